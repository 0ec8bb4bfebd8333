// imufit — the command line as the commands see it: options, flags and subcommands, without CLI11
// in the header. CLI11 is header-only (Debian 12 ships 2.1.2, without the precompiled mode of 2.3)
// and costs seconds of compilation in every translation unit that includes <CLI/CLI.hpp>: only
// cli.cc does. A CliCommand is a subcommand; a CliOption one of its options, a handle
// (copyable, null until added) through which its constraints are set and, after parsing, whether it
// was given is read. CliProgram is the program: the commands' table (main.cc) adds them, and it
// parses.
#ifndef IMUFIT_APP_CLI_H_
#define IMUFIT_APP_CLI_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
class Option;
}  // namespace CLI

#include "exit_status.h"

namespace imufit {

class CliOption {
 public:
  CliOption() = default;
  explicit CliOption(CLI::Option* option) : option_(option) {}

  // Each returns the option, for chaining.
  CliOption& Required();
  // The values of one occurrence split at `separator` ("--columns a,b").
  CliOption& Delimiter(char separator);
  // Exactly `count` values; from `min` to `max` values.
  CliOption& Expected(int count);
  CliOption& Expected(int min, int max);
  // The default the help shows: `text`, or the bound variable's value when the option was added.
  CliOption& DefaultText(const std::string& text);
  CliOption& ShowDefault();
  // Refused together with `other`; refused without `other`.
  CliOption& Excludes(const CliOption& other);
  CliOption& Needs(const CliOption& other);
  // Only these values are accepted (a parse error names them).
  CliOption& OneOf(const std::vector<std::string>& values);
  // Given several times: the values joined, a line each.
  CliOption& JoinRepeated();

  // After parsing: whether the option was given on the command line.
  bool Given() const;
  bool IsNull() const { return option_ == nullptr; }

 private:
  CLI::Option* option_ = nullptr;
};

class CliCommand {
 public:
  explicit CliCommand(CLI::App* app) : app_(app) {}

  // An option that takes a value: `names` as CLI11 spells them ("--samples,-s", or "name" for a
  // positional argument); `value` receives what is given and must outlive the parse.
  CliOption Option(const std::string& names, std::string* value, const std::string& help);
  CliOption Option(const std::string& names, double* value, const std::string& help);
  CliOption Option(const std::string& names, int* value, const std::string& help);
  CliOption Option(const std::string& names, long long* value, const std::string& help);
  CliOption Option(const std::string& names, std::uint64_t* value, const std::string& help);
  CliOption Option(const std::string& names, std::vector<std::string>* value, const std::string& help);
  CliOption Option(const std::string& names, std::vector<double>* value, const std::string& help);
  // A flag: `value` becomes true when given.
  CliOption Flag(const std::string& names, bool* value, const std::string& help);

  // A subcommand of this one (`imufit plan check`).
  CliCommand Subcommand(const std::string& name, const std::string& description);
  // Exactly one of the subcommands must be given.
  void RequireSubcommand();
  // After parsing: whether this command was given.
  bool Parsed() const;

 private:
  CLI::App* app_;
};

// What a command does once the command line has been parsed: returns the exit status
// (exit_status.h).
using CommandRunner = std::function<int()>;

// The program: its commands, and the parse of its command line.
class CliProgram {
 public:
  CliProgram(const std::string& description, const std::string& version);
  ~CliProgram();

  CliCommand Add(const std::string& name, const std::string& description);
  // nullopt when a command is to run; else the exit status: 0 after printing the help or the
  // version, 2 after printing what is wrong on one line, "imufit: COMMAND: WHAT".
  std::optional<int> Parse(int argc, char** argv);

 private:
  struct Parser;
  std::unique_ptr<Parser> parser_;
};

}  // namespace imufit

#endif  // IMUFIT_APP_CLI_H_

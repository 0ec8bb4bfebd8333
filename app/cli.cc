// The command line on CLI11: the one translation unit of imufit that includes <CLI/CLI.hpp>
// (cli.h says why).
#include "cli.h"

#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

#include "imufit/model/check.h"

namespace imufit {

CliOption& CliOption::Required() {
  option_->required();
  return *this;
}
CliOption& CliOption::Delimiter(char separator) {
  option_->delimiter(separator);
  return *this;
}
CliOption& CliOption::Expected(int count) {
  option_->expected(count);
  return *this;
}
CliOption& CliOption::Expected(int min, int max) {
  option_->expected(min, max);
  return *this;
}
CliOption& CliOption::DefaultText(const std::string& text) {
  option_->default_str(text);
  return *this;
}
CliOption& CliOption::ShowDefault() {
  option_->capture_default_str();
  return *this;
}
CliOption& CliOption::Excludes(const CliOption& other) {
  IMUFIT_CHECK(other.option_ != nullptr, "a constraint names an option that was added");
  option_->excludes(other.option_);
  return *this;
}
CliOption& CliOption::Needs(const CliOption& other) {
  IMUFIT_CHECK(other.option_ != nullptr, "a constraint names an option that was added");
  option_->needs(other.option_);
  return *this;
}
CliOption& CliOption::OneOf(const std::vector<std::string>& values) {
  option_->check(CLI::IsMember(values));
  return *this;
}
CliOption& CliOption::JoinRepeated() {
  option_->multi_option_policy(CLI::MultiOptionPolicy::Join);
  return *this;
}
bool CliOption::Given() const { return option_ != nullptr && option_->count() > 0; }

CliOption CliCommand::Option(const std::string& names, std::string* value, const std::string& help) {
  return CliOption(app_->add_option(names, *value, help));
}
CliOption CliCommand::Option(const std::string& names, double* value, const std::string& help) {
  return CliOption(app_->add_option(names, *value, help));
}
CliOption CliCommand::Option(const std::string& names, int* value, const std::string& help) {
  return CliOption(app_->add_option(names, *value, help));
}
CliOption CliCommand::Option(const std::string& names, long long* value, const std::string& help) {
  return CliOption(app_->add_option(names, *value, help));
}
CliOption CliCommand::Option(const std::string& names, std::uint64_t* value, const std::string& help) {
  return CliOption(app_->add_option(names, *value, help));
}
CliOption CliCommand::Option(const std::string& names, std::vector<std::string>* value,
                             const std::string& help) {
  return CliOption(app_->add_option(names, *value, help));
}
CliOption CliCommand::Option(const std::string& names, std::vector<double>* value, const std::string& help) {
  return CliOption(app_->add_option(names, *value, help));
}
CliOption CliCommand::Flag(const std::string& names, bool* value, const std::string& help) {
  return CliOption(app_->add_flag(names, *value, help));
}

CliCommand CliCommand::Subcommand(const std::string& name, const std::string& description) {
  return CliCommand(app_->add_subcommand(name, description));
}
void CliCommand::RequireSubcommand() { app_->require_subcommand(1); }
bool CliCommand::Parsed() const { return app_->parsed(); }

namespace {

// "plan check": the subcommands given, outermost first ("" when none).
std::string GivenCommand(const CLI::App& app) {
  std::string names;
  for (const CLI::App* command = &app;;) {
    const auto given = command->get_subcommands();
    if (given.empty()) return names;
    command = given.front();
    names += (names.empty() ? "" : " ") + command->get_name();
  }
}

// The message on one line: CLI11 words some over several.
std::string OneLine(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

}  // namespace

struct CliProgram::Parser {
  CLI::App app;
};

CliProgram::CliProgram(const std::string& description, const std::string& version)
    : parser_(std::make_unique<Parser>()) {
  parser_->app.description(description);
  parser_->app.name("imufit");
  parser_->app.set_version_flag("--version", version);
  parser_->app.require_subcommand(1);
}

CliProgram::~CliProgram() = default;

CliCommand CliProgram::Add(const std::string& name, const std::string& description) {
  return CliCommand(parser_->app.add_subcommand(name, description));
}

std::optional<int> CliProgram::Parse(int argc, char** argv) {
  try {
    parser_->app.parse(argc, argv);
    return std::nullopt;
  } catch (const CLI::CallForHelp& e) {
    return parser_->app.exit(e);  // the help on stdout, status 0
  } catch (const CLI::CallForAllHelp& e) {
    return parser_->app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return parser_->app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, as every other error (docs/spec.md section 4), naming the command it is about.
    const std::string command = GivenCommand(parser_->app);
    std::fprintf(stderr, "imufit: %s%s\n", command.empty() ? "" : (command + ": ").c_str(),
                 OneLine(e.what()).c_str());
    return kExitBadInput;
  }
}

}  // namespace imufit

#include "imufit/report/pdf.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

#include "imufit/io/path.h"
#include "imufit/io/sha256.h"
#include "temp_folder.h"

extern char** environ;

namespace imufit {
namespace {

namespace fs = std::filesystem;

bool IsExecutable(const fs::path& path) {
  std::error_code error;
  return fs::is_regular_file(path, error) && ::access(path.c_str(), X_OK) == 0;
}

// `html` with an @page rule for `paper` at the end of its head (after the page's own rules).
std::string WithPaper(const std::string& html, Paper paper) {
  const std::string rule = std::string("<style>@page { size: ") + NameOf(kPaperNames, paper) + "; }</style>";
  std::string text = html;
  const size_t head = text.find("</head>");
  text.insert(head == std::string::npos ? 0 : head, rule);
  return text;
}

// Runs `argv` with no input, its output and errors into `log`; kills it after kPdfTimeoutS. Returns
// "" when it exited with status 0, else what happened.
std::string RunWithDeadline(std::vector<std::string> argv, const std::string& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  std::vector<char*> args;
  for (std::string& a : argv) args.push_back(a.data());
  args.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) return "cannot run " + argv[0];
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(kPdfTimeoutS);
  int status = 0;
  while (::waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      return argv[0] + " did not finish within " + std::to_string(kPdfTimeoutS) + " s";
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return "";
  std::ifstream in(log);
  std::stringstream text;
  text << in.rdbuf();
  return argv[0] + " failed: " + text.str().substr(0, 400);
}

}  // namespace

std::string FindChromium() {
  if (const char* named = std::getenv("IMUFIT_CHROMIUM"); named != nullptr && *named != '\0')
    return IsExecutable(named) ? named : "";
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path != nullptr ? path : "/usr/bin:/bin");
  std::vector<std::string> folders;
  for (std::string dir; std::getline(dirs, dir, ':');) folders.push_back(dir.empty() ? "." : dir);
  for (const char* name : {"chromium", "chromium-browser", "google-chrome"}) {
    for (const std::string& dir : folders) {
      if (IsExecutable(fs::path(dir) / name)) return (fs::path(dir) / name).string();
    }
  }
  return "";
}

std::string PdfProblem() {
  if (!FindChromium().empty()) return "";
  return "printing to PDF needs Chromium (chromium on PATH, or IMUFIT_CHROMIUM naming it; Debian: apt-get "
         "install chromium)";
}

std::string PdfPathFor(const std::string& html_path) {
  if (HasSuffix(html_path, ".html")) return html_path.substr(0, html_path.size() - 5) + ".pdf";
  if (HasSuffix(html_path, ".htm")) return html_path.substr(0, html_path.size() - 4) + ".pdf";
  return html_path + ".pdf";
}

std::string WritePdf(const std::string& html, const std::string& pdf_path, Paper paper,
                     OutputTransaction* transaction) {
  const std::string chromium = FindChromium();
  if (chromium.empty()) throw std::runtime_error(pdf_path + ": " + PdfProblem());
  internal::TempFolder folder("imufit-pdf");
  const std::string page = folder.path + "/page.html";
  std::ofstream(page, std::ios::binary) << WithPaper(html, paper);
  OutputFile out(pdf_path, transaction);
  const std::string failure =
      RunWithDeadline({chromium, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
                       "--disable-background-networking", "--disable-component-update", "--disable-sync",
                       "--user-data-dir=" + folder.path + "/profile", "--no-pdf-header-footer",
                       "--print-to-pdf=" + out.temp_path(), "file://" + page},
                      folder.path + "/chromium.log");
  if (!failure.empty()) throw std::runtime_error("cannot print " + pdf_path + ": " + failure);
  std::ifstream written(out.temp_path(), std::ios::binary);
  char magic[5] = {};
  written.read(magic, 4);
  if (std::string(magic) != "%PDF")
    throw std::runtime_error("cannot print " + pdf_path + ": Chromium wrote no PDF");
  std::string sha256 = Sha256OfFile(out.temp_path());
  out.Commit();
  return sha256;
}

}  // namespace imufit

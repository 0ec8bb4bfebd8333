#include "test_util.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

extern char** environ;

namespace imufit::testing {

namespace fs = std::filesystem;

namespace {

// The program and its arguments as execv wants them; `storage` keeps the strings.
std::vector<char*> Argv(const std::string& program, const std::vector<std::string>& args,
                        std::vector<std::string>* storage) {
  *storage = {program};
  storage->insert(storage->end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& arg : *storage) argv.push_back(arg.data());
  argv.push_back(nullptr);
  return argv;
}

// Waits for `pid` and reads what it printed.
RunResult Finish(pid_t pid, const std::string& out_path, const std::string& err_path) {
  RunResult result;
  int status = 0;
  if (::waitpid(pid, &status, 0) != pid) {
    ADD_FAILURE() << "cannot wait for process " << pid;
    return result;
  }
  result.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  result.out = ReadBytes(out_path);
  result.err = ReadBytes(err_path);
  return result;
}

}  // namespace

std::string Fixture(const std::string& name) { return std::string(IMUFIT_FIXTURES_DIR) + "/" + name; }

std::string ReadBytes(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  std::stringstream text;
  text << stream.rdbuf();
  return text.str();
}

std::string ReadFile(const std::string& path) {
  gzFile file = gzopen(path.c_str(), "rb");
  if (file == nullptr) return "<cannot open " + path + ">";
  std::string text;
  char block[1 << 16];
  int n = 0;
  while ((n = gzread(file, block, sizeof block)) > 0) text.append(block, n);
  gzclose(file);
  return text;
}

::testing::AssertionResult SameText(const std::string& got, const std::string& expected) {
  if (got == expected) return ::testing::AssertionSuccess();
  const size_t at = static_cast<size_t>(
      std::mismatch(got.begin(), got.end(), expected.begin(), expected.end()).first - got.begin());
  const size_t line_start = got.rfind('\n', at == 0 ? 0 : at - 1);
  const size_t begin = line_start == std::string::npos || at == 0 ? 0 : line_start + 1;
  const auto line_of = [begin](const std::string& text) {
    return text.substr(begin, text.find('\n', begin) - begin);
  };
  return ::testing::AssertionFailure()
         << "the texts differ from line " << 1 + std::count(got.begin(), got.begin() + begin, '\n')
         << ": got \"" << line_of(got) << "\", expected \"" << line_of(expected) << "\" (" << got.size()
         << " against " << expected.size() << " bytes)";
}

RunResult RunProgram(const std::string& program, const std::vector<std::string>& args,
                     const std::string& out_path, const std::string& err_path) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, 2, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::vector<std::string> storage;
  std::vector<char*> argv = Argv(program, args, &storage);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) {
    ADD_FAILURE() << "cannot run " << program << ": " << std::strerror(spawned);
    return RunResult();
  }
  return Finish(pid, out_path, err_path);
}

RunResult RunProgramWithFileSizeLimit(const std::string& program, const std::vector<std::string>& args,
                                      const std::string& out_path, const std::string& err_path,
                                      rlim_t max_file_bytes) {
  std::vector<std::string> storage;
  std::vector<char*> argv = Argv(program, args, &storage);
  const pid_t pid = ::fork();
  if (pid == 0) {  // only async-signal-safe calls until exec
    const int out_fd = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err_fd = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int null_fd = ::open("/dev/null", O_RDONLY);
    if (out_fd < 0 || err_fd < 0 || null_fd < 0) ::_exit(126);
    ::dup2(null_fd, 0);
    ::dup2(out_fd, 1);
    ::dup2(err_fd, 2);
    const struct rlimit limit = {max_file_bytes, max_file_bytes};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    ::signal(SIGXFSZ, SIG_IGN);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  if (pid < 0) {
    ADD_FAILURE() << "cannot run " << program << ": " << std::strerror(errno);
    return RunResult();
  }
  return Finish(pid, out_path, err_path);
}

void TempDirTest::SetUp() {
  const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
  // A parameterised test's name holds '/': one folder name all the same.
  std::string name = std::string(test->test_suite_name()) + "." + test->name();
  std::replace(name.begin(), name.end(), '/', '_');
  root_ = fs::temp_directory_path() / ("imufit_test_" + std::to_string(::getpid()) + "_" + name);
  dir_ = root_ / "files";
  fs::remove_all(root_);
  fs::create_directories(dir_);
}

void TempDirTest::TearDown() {
  if (!HasFailure()) fs::remove_all(root_);
}

std::string TempDirTest::Path(const std::string& name) const { return (dir_ / name).string(); }

std::string TempDirTest::Write(const std::string& name, const std::string& text) const {
  const std::string path = Path(name);
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

std::set<std::string> TempDirTest::Listing() const {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir_)) names.insert(entry.path().filename().string());
  return names;
}

RunResult TempDirTest::RunProgram(const std::string& program, const std::vector<std::string>& args) const {
  return testing::RunProgram(program, args, (root_ / "stdout.txt").string(), (root_ / "stderr.txt").string());
}

RunResult TempDirTest::RunProgramWithFileSizeLimit(const std::string& program,
                                                   const std::vector<std::string>& args,
                                                   rlim_t max_file_bytes) const {
  return testing::RunProgramWithFileSizeLimit(program, args, (root_ / "stdout.txt").string(),
                                              (root_ / "stderr.txt").string(), max_file_bytes);
}

}  // namespace imufit::testing

#pragma once
// `psq` as a child process for the runner's crash tests: started with extra environment
// variables and an optional file-size limit, stdout and stderr captured to files, signalled,
// stopped and killed at will. Killed and reaped on destruction if still running.

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace psq::test {

struct ChildOptions {
  std::map<std::string, std::string> environment;  ///< set in the child
  std::optional<rlim_t> file_size_limit;           ///< RLIMIT_FSIZE in bytes
};

class PsqChild {
 public:
  /// Starts `executable arguments...`, its output in `log_dir`/child.{out,err}.
  PsqChild(const std::string& executable, const std::vector<std::string>& arguments,
           const std::filesystem::path& log_dir, const ChildOptions& options = {})
      : out_(log_dir / "child.out"), err_(log_dir / "child.err") {
    pid_ = ::fork();
    if (pid_ < 0) throw std::runtime_error("fork failed");
    if (pid_ > 0) return;
    for (const auto& [name, value] : options.environment) ::setenv(name.c_str(), value.c_str(), 1);
    if (options.file_size_limit) {
      const rlimit limit{*options.file_size_limit, *options.file_size_limit};
      ::setrlimit(RLIMIT_FSIZE, &limit);
      ::signal(SIGXFSZ, SIG_IGN);  // a write beyond the limit fails with EFBIG instead
    }
    const int out = ::open(out_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = ::open(err_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(out, STDOUT_FILENO);
    ::dup2(err, STDERR_FILENO);
    std::vector<char*> argv{const_cast<char*>(executable.c_str())};
    for (const std::string& a : arguments) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(executable.c_str(), argv.data());
    ::_exit(127);
  }
  PsqChild(const PsqChild&) = delete;
  PsqChild& operator=(const PsqChild&) = delete;
  ~PsqChild() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      wait();
    }
  }

  pid_t pid() const { return pid_; }
  /// Signals the child while it runs; nothing once it has exited (kill(-1) would signal every
  /// process the user may signal).
  void signal(int signal) const {
    if (pid_ > 0) ::kill(pid_, signal);
  }

  /// Waits for the exit; returns the exit code, or 128 + signal when killed.
  int wait() {
    if (pid_ > 0) {
      int status = 0;
      while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
      }
      exited(status);
    }
    return exit_code_;
  }
  /// Waits until the child stops (SIGSTOP) or exits: true if it stopped. After an exit,
  /// wait() returns its code.
  bool wait_until_stopped() {
    int status = 0;
    while (::waitpid(pid_, &status, WUNTRACED) < 0 && errno == EINTR) {
    }
    if (WIFSTOPPED(status)) return true;
    exited(status);
    return false;
  }

  std::string output() const { return read(out_); }
  std::string errors() const { return read(err_); }

 private:
  static std::string read(const std::filesystem::path& file) {
    std::ifstream in(file);
    return {std::istreambuf_iterator<char>(in), {}};
  }

  void exited(int status) {
    pid_ = -1;
    exit_code_ = WIFSIGNALED(status) ? 128 + WTERMSIG(status) : WEXITSTATUS(status);
  }

  std::filesystem::path out_, err_;
  pid_t pid_ = -1;
  int exit_code_ = -1;  ///< once exited
};

}  // namespace psq::test

#include "support/run_process.hpp"

#include <fstream>
#include <stdexcept>
#include <sys/wait.h>
#include <unistd.h>

#include "support/test_paths.hpp"

namespace psq::test {
namespace {

}  // namespace

ProcessResult run_process(const std::string& program, const std::vector<std::string>& arguments) {
  // Output goes to files rather than pipes so a chatty child can never block on a full pipe.
  const auto dir = fresh_temp_dir("process");
  const auto out_path = dir / "stdout", err_path = dir / "stderr";
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    if (!std::freopen(out_path.c_str(), "w", stdout) || !std::freopen(err_path.c_str(), "w", stderr))
      ::_exit(127);
    std::vector<char*> argv;
    argv.push_back(const_cast<char*>(program.c_str()));
    for (const auto& a : arguments) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(program.c_str(), argv.data());
    ::_exit(127);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  ProcessResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  result.output = read_file(out_path);
  result.errors = read_file(err_path);
  return result;
}

ProcessResult run_psq([[maybe_unused]] const std::vector<std::string>& arguments) {
#ifdef PSQ_EXECUTABLE
  return run_process(PSQ_EXECUTABLE, arguments);
#else
  throw std::logic_error("run_psq needs PSQ_EXECUTABLE (tests/runner only)");
#endif
}

}  // namespace psq::test

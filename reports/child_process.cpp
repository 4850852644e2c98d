#include "reports/child_process.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "engine/core/error.hpp"

extern char** environ;

namespace psq::reports {
namespace {

/// posix_spawn file actions, released on scope exit.
class FileActions {
 public:
  FileActions() { posix_spawn_file_actions_init(&actions_); }
  ~FileActions() { posix_spawn_file_actions_destroy(&actions_); }
  FileActions(const FileActions&) = delete;
  FileActions& operator=(const FileActions&) = delete;
  void open(int descriptor, const std::filesystem::path& file, int flags) {
    posix_spawn_file_actions_addopen(&actions_, descriptor, file.c_str(), flags, 0644);
  }
  const posix_spawn_file_actions_t* get() const { return &actions_; }

 private:
  posix_spawn_file_actions_t actions_;
};

}  // namespace

ChildExit run_child(const std::string& program, const std::vector<std::string>& arguments,
                    const std::filesystem::path& error_file,
                    const std::filesystem::path& output_file) {
  FileActions actions;
  actions.open(STDIN_FILENO, "/dev/null", O_RDONLY);
  if (output_file.empty())
    actions.open(STDOUT_FILENO, "/dev/null", O_WRONLY);
  else
    actions.open(STDOUT_FILENO, output_file, O_WRONLY | O_CREAT | O_TRUNC);
  actions.open(STDERR_FILENO, error_file, O_WRONLY | O_CREAT | O_TRUNC);
  std::vector<char*> argv{const_cast<char*>(program.c_str())};
  for (const std::string& argument : arguments) argv.push_back(const_cast<char*>(argument.c_str()));
  argv.push_back(nullptr);

  pid_t child = 0;
  const int spawn_error =
      program.find('/') == std::string::npos
          ? posix_spawnp(&child, program.c_str(), actions.get(), nullptr, argv.data(), environ)
          : posix_spawn(&child, program.c_str(), actions.get(), nullptr, argv.data(), environ);
  if (spawn_error != 0)
    throw InputError(fmt::format("cannot run '{}': {}", program, std::strerror(spawn_error)));
  int status = 0;
  while (::waitpid(child, &status, 0) < 0)
    if (errno != EINTR)
      throw InputError(fmt::format("cannot wait for '{}': {}", program, std::strerror(errno)));
  ChildExit exit;
  exit.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  exit.errors = read_child_output(error_file);
  return exit;
}

std::string read_child_output(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace psq::reports

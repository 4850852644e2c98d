#include "jobs/worker_pool.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

namespace psq::jobs {
namespace {

struct Worker {
  pid_t pid = -1;
  int output = -1;      ///< read end of its stderr pipe; -1 once closed
  std::string pending;  ///< an unfinished line
  int exit_code = -1;
};

[[noreturn]] void exec_worker(const std::string& program, const std::vector<std::string>& args,
                              pid_t supervisor, int pipe_write) {
  ::setpgid(0, 0);
  ::prctl(PR_SET_PDEATHSIG, SIGTERM);
  if (::getppid() != supervisor) ::_exit(143);  // the supervisor died before prctl
  ::dup2(pipe_write, STDERR_FILENO);
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(program.c_str()));
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  ::execv(program.c_str(), argv.data());
  ::_exit(127);
}

Worker start(const std::string& program, const std::vector<std::string>& args) {
  int ends[2];
  if (::pipe2(ends, O_CLOEXEC) != 0)
    throw std::system_error(errno, std::generic_category(), "pipe for a worker");
  const pid_t supervisor = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) throw std::system_error(errno, std::generic_category(), "fork of a worker");
  if (pid == 0) exec_worker(program, args, supervisor, ends[1]);
  ::close(ends[1]);
  return {pid, ends[0], {}, -1};
}

void show_line(int number, const std::string& line, ProgressDisplay& display) {
  if (!line.empty() && line.front() == kProgressMarker)
    display.status(number, line.substr(1));
  else
    display.log(fmt::format("[{}] {}", number, line));
}

/// Reads what worker `number` wrote; closes its pipe at the end of its output.
void drain(Worker& worker, int number, ProgressDisplay& display) {
  char buffer[4096];
  const ssize_t got = ::read(worker.output, buffer, sizeof buffer);
  if (got < 0 && errno == EINTR) return;
  if (got <= 0) {
    if (!worker.pending.empty()) show_line(number, worker.pending, display);
    ::close(worker.output);
    worker.output = -1;
    return;
  }
  worker.pending.append(buffer, static_cast<std::size_t>(got));
  for (std::size_t end; (end = worker.pending.find('\n')) != std::string::npos;) {
    show_line(number, worker.pending.substr(0, end), display);
    worker.pending.erase(0, end + 1);
  }
}

int exit_code(int status) {
  return WIFSIGNALED(status) ? 128 + WTERMSIG(status) : WEXITSTATUS(status);
}

}  // namespace

std::vector<int> run_worker_processes(const std::string& program,
                                      const std::vector<std::vector<std::string>>& arguments,
                                      ProgressDisplay& display, const std::atomic<int>& signals,
                                      const std::atomic<int>& last_signal) {
  std::vector<Worker> workers;
  for (const auto& args : arguments) workers.push_back(start(program, args));
  int forwarded = 0;
  for (;;) {
    for (; forwarded < signals.load(); ++forwarded)
      for (const Worker& w : workers) ::kill(w.pid, last_signal.load());
    std::vector<pollfd> open;
    std::vector<std::size_t> which;
    for (std::size_t i = 0; i < workers.size(); ++i)
      if (workers[i].output >= 0) {
        open.push_back({workers[i].output, POLLIN, 0});
        which.push_back(i);
      }
    if (open.empty()) break;
    if (::poll(open.data(), open.size(), 200) <= 0) continue;  // timeout or a signal
    for (std::size_t k = 0; k < open.size(); ++k)
      if (open[k].revents != 0) drain(workers[which[k]], static_cast<int>(which[k]) + 1, display);
  }
  std::vector<int> codes;
  for (Worker& w : workers) {
    int status = 0;
    while (::waitpid(w.pid, &status, 0) < 0 && errno == EINTR) {
    }
    codes.push_back(exit_code(status));
  }
  return codes;
}

}  // namespace psq::jobs

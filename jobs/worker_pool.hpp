#pragma once
// Worker processes of `psq work --workers N`: each a fresh exec of psq itself (fork + exec, not
// a bare fork: the solver's thread pools (TBB, OpenBLAS) and SQLite connections must not be
// inherited by a forked copy), with its stderr on a pipe so the supervisor can draw one status
// line for all of them and keep their log lines whole.

#include <atomic>
#include <string>
#include <vector>

#include "jobs/progress_display.hpp"

namespace psq::jobs {

/// Starts one process per argument list (`program` with those arguments), shows their
/// progress lines (kProgressMarker) on `display` and prints their other stderr lines as log
/// lines prefixed with the worker's number. While they run, each new signal counted by
/// `signals` (its number in `last_signal`) is forwarded to every worker. The workers run in
/// their own process group (a terminal's Ctrl-C reaches them once, through the supervisor)
/// and receive SIGTERM if the supervisor dies. Returns each worker's exit code, 128 + signal
/// when it was killed. Throws std::system_error if a process cannot be started.
std::vector<int> run_worker_processes(const std::string& program,
                                      const std::vector<std::vector<std::string>>& arguments,
                                      ProgressDisplay& display, const std::atomic<int>& signals,
                                      const std::atomic<int>& last_signal);

}  // namespace psq::jobs

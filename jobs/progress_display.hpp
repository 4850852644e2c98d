#pragma once
// What `psq work` shows: on a terminal, one status line rewritten in place (job, level, frame,
// iteration, residual, ETA of every worker) with log lines scrolling above it; elsewhere, plain
// log lines only.

#include <cstdio>
#include <map>
#include <optional>
#include <string>

#include "jobs/job_executor.hpp"

namespace psq::jobs {

/// "3f2a9c01 L1/2 frame 4/10 it 3 ‖g‖ 1.2e-03 ETA 0:42": one worker's progress, short.
std::string describe_progress(const JobProgress& progress);

/// Worker processes send their progress to the supervisor as lines of their stderr that start
/// with this marker (a byte that never begins a log line), followed by describe_progress text.
inline constexpr char kProgressMarker = '\x1e';

class ProgressDisplay {
 public:
  /// Writes to `out`; `live` selects the updating status line (a terminal).
  ProgressDisplay(std::FILE* out, bool live) : out_(out), live_(live) {}
  ProgressDisplay(const ProgressDisplay&) = delete;
  ProgressDisplay& operator=(const ProgressDisplay&) = delete;

  bool live() const { return live_; }
  /// Sets worker `worker`'s part of the status line (nothing when not live).
  void status(int worker, const std::string& text);
  /// Prints one log line (above the status line when live).
  void log(const std::string& line);
  /// Erases the status line (before exit).
  void clear();

 private:
  void redraw();

  std::FILE* out_;
  bool live_;
  std::map<int, std::string> statuses_;
  bool drawn_ = false;
};

}  // namespace psq::jobs

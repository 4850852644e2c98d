#include "jobs/progress_display.hpp"

#include <fmt/format.h>
#include <sys/ioctl.h>
#include <unistd.h>

namespace psq::jobs {
namespace {

std::string clock_text(double seconds) {
  const long s = static_cast<long>(seconds + 0.5);
  return s >= 3600 ? fmt::format("{}:{:02d}:{:02d}", s / 3600, s / 60 % 60, s % 60)
                   : fmt::format("{}:{:02d}", s / 60, s % 60);
}

/// Columns of the terminal on `out`, or 100 when unknown.
std::size_t terminal_width(std::FILE* out) {
  winsize size{};
  if (::ioctl(::fileno(out), TIOCGWINSZ, &size) == 0 && size.ws_col > 0) return size.ws_col;
  return 100;
}

}  // namespace

std::string describe_progress(const JobProgress& p) {
  std::string text =
      fmt::format("{:.8} L{}/{} frame {}/{} it {} ‖g‖ {:.2e} ‖Δx‖/Δt {:.2e}", p.job_id, p.level,
                  p.level_count, p.frame, p.frame_count, p.iteration, p.gradient_norm, p.step_norm);
  if (p.eta_seconds) text += " ETA " + clock_text(*p.eta_seconds);
  return text;
}

void ProgressDisplay::status(int worker, const std::string& text) {
  if (!live_) return;
  statuses_[worker] = text;
  redraw();
}

void ProgressDisplay::log(const std::string& line) {
  if (live_ && drawn_) std::fputs("\r\x1b[K", out_);
  std::fputs(line.c_str(), out_);
  std::fputc('\n', out_);
  drawn_ = false;
  if (live_ && !statuses_.empty()) redraw();
  std::fflush(out_);
}

void ProgressDisplay::clear() {
  if (live_ && drawn_) std::fputs("\r\x1b[K", out_);
  drawn_ = false;
  statuses_.clear();
  std::fflush(out_);
}

void ProgressDisplay::redraw() {
  std::string line;
  for (const auto& [worker, text] : statuses_)
    line += fmt::format("{}{}", line.empty() ? "" : " | ",
                        statuses_.size() > 1 ? fmt::format("[{}] {}", worker, text) : text);
  // Cut to the terminal's width: a wrapped line could not be rewritten in place. Count code
  // points, not bytes (‖ and Δ take several bytes).
  const std::size_t width = terminal_width(out_) - 1;
  std::size_t columns = 0, cut = 0;
  for (; cut < line.size() && columns < width; ++cut)
    if ((static_cast<unsigned char>(line[cut]) & 0xC0) != 0x80) ++columns;
  while (cut < line.size() && (static_cast<unsigned char>(line[cut]) & 0xC0) == 0x80) ++cut;
  std::fputs(("\r\x1b[K" + line.substr(0, cut)).c_str(), out_);
  std::fflush(out_);
  drawn_ = true;
}

}  // namespace psq::jobs

#include "runner/slurm_scheduler.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <stdlib.h>
#include <unistd.h>

#include <array>
#include <cstdlib>
#include <sstream>

#include "engine/core/error.hpp"
#include "reports/child_process.hpp"

namespace psq::runner::slurm {
namespace fs = std::filesystem;
namespace {

std::string trimmed(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return {};
  return text.substr(first, text.find_last_not_of(" \t\r\n") - first + 1);
}

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> fields;
  std::stringstream in(text);
  for (std::string field; std::getline(in, field, separator);) fields.push_back(field);
  return fields;
}

/// Throws InputError naming `program` unless PATH has an executable of that name: without it
/// there is no cluster to talk to, and spawn's "No such file" would not say so.
void require_on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  for (const std::string& dir : split(path ? path : "", ':'))
    if (!dir.empty() && ::access((fs::path(dir) / program).c_str(), X_OK) == 0) return;
  throw InputError(fmt::format(
      "{} is not on PATH ({}): psq slurm needs SLURM's client commands; install them (Debian: "
      "apt-get install slurm-client) or load your cluster's module, then try again",
      program, path ? path : ""));
}

/// What to do about an sbatch refusal, from the words SLURM uses for it.
std::string submission_hint(const std::string& errors) {
  if (errors.find("nvalid partition") != std::string::npos)
    return "choose a partition that `sinfo --summarize` lists (--partition)";
  if (errors.find("Unable to contact slurm controller") != std::string::npos)
    return "the cluster's controller (slurmctld) does not answer: check `scontrol ping`, and that "
           "SLURM_CONF (or /etc/slurm/slurm.conf) names your cluster";
  if (errors.find("time limit") != std::string::npos)
    return "choose a --time within the partition's limit (`sinfo --summarize`)";
  if (errors.find("emory") != std::string::npos)
    return "choose a --mem the partition's nodes have (`sinfo --Node --long`)";
  return "fix the option sbatch names and submit again";
}

}  // namespace

bool is_live(const std::string& state) {
  static constexpr std::array kLive{"PENDING",      "RUNNING",   "REQUEUED",  "REQUEUE_FED",
                                    "REQUEUE_HOLD", "RESIZING",  "SUSPENDED", "CONFIGURING",
                                    "COMPLETING",   "SIGNALING", "STAGE_OUT", "RESV_DEL_HOLD",
                                    "STOPPED"};
  for (const char* live : kLive)
    if (state == live) return true;
  return false;
}

std::string task_name(const std::string& array_id, int index) {
  return fmt::format("{}_{}", array_id, index);
}

Scheduler::Scheduler() {
  std::string pattern = (fs::temp_directory_path() / "psq-slurm-XXXXXX").string();
  if (!::mkdtemp(pattern.data()))
    throw InputError(fmt::format("cannot create a temporary directory in {}; set TMPDIR",
                                 fs::temp_directory_path().string()));
  scratch_ = pattern;
}

Scheduler::~Scheduler() {
  std::error_code ignored;
  fs::remove_all(scratch_, ignored);
}

Scheduler::Output Scheduler::run(const std::string& program,
                                 const std::vector<std::string>& arguments) {
  require_on_path(program);
  const reports::ChildExit exit =
      reports::run_child(program, arguments, scratch_ / "errors", scratch_ / "output");
  return {exit.status, reports::read_child_output(scratch_ / "output"), trimmed(exit.errors)};
}

std::string Scheduler::submit(const fs::path& script) {
  const Output result = run("sbatch", {"--parsable", script.string()});
  if (result.status != 0)
    throw InputError(fmt::format("sbatch refused the sweep's array job: {}; {}", result.errors,
                                 submission_hint(result.errors)));
  // --parsable prints "<id>" or "<id>;<cluster>".
  const std::string id = trimmed(split(trimmed(result.out), ';').front());
  if (id.empty() || id.find_first_not_of("0123456789") != std::string::npos)
    throw InputError(
        fmt::format("sbatch answered '{}' instead of a job id; check that it is SLURM's sbatch",
                    trimmed(result.out)));
  return id;
}

std::map<std::string, TaskState> Scheduler::states(const std::vector<std::string>& array_ids) {
  std::map<std::string, TaskState> states;
  if (array_ids.empty()) return states;
  const std::string jobs = fmt::format("{}", fmt::join(array_ids, ","));
  // Ended arrays whose every task left the controller's memory make squeue fail with "Invalid
  // job id"; sacct then answers for them.
  const Output queue = run(
      "squeue", {"--noheader", "--array", "--states=all", "--jobs=" + jobs, "--format=%i|%T|%r"});
  if (queue.status != 0 && queue.errors.find("Invalid job id") == std::string::npos)
    throw InputError(fmt::format(
        "squeue cannot tell the state of the array jobs {}: {}; check `scontrol ping` and "
        "SLURM_CONF, then run psq slurm sync again",
        jobs, queue.errors));
  for (const std::string& line : split(queue.out, '\n')) {
    const std::vector<std::string> fields = split(trimmed(line), '|');
    if (fields.size() >= 3) states[fields[0]] = {fields[1], fields[2] == "None" ? "" : fields[2]};
  }
  const Output accounting = run("sacct", {"--noheader", "--parsable2", "--allocations",
                                          "--jobs=" + jobs, "--format=JobID,State,ExitCode"});
  if (accounting.status != 0) return states;  // no accounting on this cluster: squeue's word
  for (const std::string& line : split(accounting.out, '\n')) {
    const std::vector<std::string> fields = split(trimmed(line), '|');
    if (fields.size() < 3 || states.contains(fields[0])) continue;
    // sacct writes "CANCELLED by <uid>"; the state is the first word.
    states[fields[0]] = {split(fields[1], ' ').front(), "exit code " + fields[2]};
  }
  return states;
}

void Scheduler::cancel(const std::string& task) {
  const Output result = run("scancel", {task});
  if (result.status != 0)
    throw InputError(fmt::format("scancel {} failed: {}", task, result.errors));
}

void Scheduler::requeue(const std::string& task) {
  const Output result = run("scontrol", {"requeue", task});
  if (result.status != 0)
    throw InputError(fmt::format("scontrol requeue {} failed: {}", task, result.errors));
}

}  // namespace psq::runner::slurm

// Benchmark (prints, never fails on a slow machine): per contact scene of jobs/scenes, the time
// per Newton iteration (the run's wall time over its Newton iterations) split into contact
// (broad phase and barrier), friction (lagging and evaluation), CCD, factorization with the
// solves, and the rest ("elastic+": elastic assembly, line search and everything else); then the
// speed-up from the skips ([contact] skip_when_apart on and off, each twice) on drape_sphere,
// whose cloth falls freely for three frames before it meets the ball, and on twist_wrap at a
// coarse size, whose layers meet only in the last third of its frames. (drape_sphere with the
// cloth 20 cm higher shows no more: each free-fall frame takes about one Newton iteration.)
//
// Usage: bench_contact [--scale S] [--scenes a,b] [--frames N] [--skips on|off]
//   S multiplies every mesh edge length (default 1: the sizes below, chosen to run in about a
//   minute); --scenes picks scenes of the table, --frames overrides their frame counts (large
//   sizes: the first frames of contact), --skips off leaves out the skip comparison.

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include "bench/bench_options.hpp"
#include "bench/generated_mesh.hpp"
#include "engine/scene/scene_reader.hpp"
#include "engine/sim/quasistatic.hpp"

namespace {

using namespace psq;

/// A scene of the library at a benchmark size.
struct Case {
  std::string scene;
  double shell_edge;
  double collider_edge;  ///< generated colliders only; the bunny is a file
  int frames;
};

const std::vector<Case> kCases = {
    {"drape_sphere", 0.05, 0.05, 8},
    {"twist_wrap", 0.05, 0.0, 16},
    {"cylinder_crush", 0.01, 0.04, 4},
    {"bunny_press", 0.025, 0.0, 8},
};

void set_edge_length(MeshSource& mesh, double edge) {
  if (edge > 0) psq::bench::set_generated_edge_length(mesh, edge);
}

/// The cases named on the command line (all by default), each with its frame count or `frames`.
std::vector<Case> chosen_cases(const psq::bench::BenchOptions& options) {
  std::vector<Case> chosen;
  const std::vector<std::string> names =
      options.given("scenes") ? options.texts("scenes") : std::vector<std::string>{};
  for (const Case& c : kCases)
    if (names.empty() || std::find(names.begin(), names.end(), c.scene) != names.end())
      chosen.push_back(c);
  std::vector<std::string> known;
  for (const Case& c : kCases) known.push_back(c.scene);
  for (const std::string& name : names)
    if (std::find(known.begin(), known.end(), name) == known.end())
      psq::bench::reject_value("scenes", name, fmt::format("one of {}", fmt::join(known, ", ")));
  if (options.given("frames"))
    for (Case& c : chosen) c.frames = options.integer("frames");
  return chosen;
}

Scene load(const Case& c, double scale, bool skip) {
  Scene scene = read_scene(std::string(PSQ_SOURCE_DIR "/jobs/scenes/") + c.scene + ".toml");
  for (Shell& shell : scene.shells) set_edge_length(shell.mesh, scale * c.shell_edge);
  for (Collider& collider : scene.colliders)
    set_edge_length(collider.mesh, scale * c.collider_edge);
  scene.time.frames = c.frames;
  scene.contact.skip_when_apart = skip;
  return scene;
}

/// Totals over every frame of a run.
struct Totals {
  int vertices = 0;
  int iterations = 0;
  bool converged = true;
  PhaseTimes newton;
  ContactStats contact;
  double friction = 0;
  double wall = 0;
};

Totals run(const Scene& scene) {
  const auto start = std::chrono::steady_clock::now();
  QuasistaticSimulation sim(scene);
  Totals totals;
  totals.vertices = sim.system().rest_mesh().vertex_count();
  while (sim.frame() < sim.frame_count()) {
    const FrameRecord record = sim.step();
    totals.iterations += record.newton.iterations;
    totals.converged = totals.converged && record.newton.converged;
    totals.newton += record.newton.times;
    totals.contact += record.contact;
    totals.friction += record.friction_seconds;
  }
  totals.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return totals;
}

void print_split(const std::string& name, const Totals& t) {
  const double per = 1e3 / std::max(1, t.iterations);
  const double contact = t.contact.broad_phase_seconds + t.contact.barrier_seconds;
  const double ccd = t.contact.ccd_seconds;
  const double factorization = t.newton.factorization + t.newton.solve;
  // Contact and CCD also run outside Newton's phases (κ at the frame start, the scripted
  // vertices' safe moves), so the elastic share is what the run's wall time leaves.
  const double elastic = t.wall - contact - t.friction - ccd - factorization;
  fmt::print(
      "{:<16} {:>8} {:>6} {:>10.3f} {:>10.3f} {:>10.3f} {:>10.3f} {:>10.3f} {:>10.3f} {:>9}\n",
      name, t.vertices, t.iterations, per * elastic, per * contact, per * t.friction, per * ccd,
      per * factorization, per * t.wall, t.converged ? "yes" : "NO");
}

double contact_seconds(const Totals& t) {
  return t.contact.broad_phase_seconds + t.contact.barrier_seconds + t.contact.ccd_seconds;
}

void print_skip_row(const std::string& label, const Totals& t) {
  const ContactStats& c = t.contact;
  fmt::print(
      "{:<14} {:>8.3f} {:>6} {:>11.3f} {:>6}/{:<6} {:>6}/{:<6} {:>6}/{:<6} {:>6}/{:<6} {:>8}\n",
      label, t.wall, t.iterations, contact_seconds(t), c.barrier_skips, c.barrier_evaluations,
      c.barrier_certified, c.barrier_evaluations, c.ccd_skips, c.ccd_evaluations, c.ccd_certified,
      c.ccd_evaluations, c.certificate_renewals);
}

/// The same scene with [contact] skip_when_apart on and off, twice each (wall times vary from
/// run to run): wall time, contact work (broad phase, barrier and CCD), skipped and
/// certified states and steps, certificate renewals.
void print_skip_speedup(const Case& c, double scale, const std::string& when) {
  constexpr int kRepeats = 2;
  fmt::print("\nskips on {} ({} frames, {})\n", c.scene, c.frames, when);
  fmt::print("{:<14} {:>8} {:>6} {:>11} {:>13} {:>13} {:>13} {:>13} {:>8}\n", "", "wall [s]",
             "iters", "contact [s]", "state skips", "certified", "step skips", "certified",
             "renewals");
  for (int repeat = 0; repeat < kRepeats; ++repeat) {
    const Totals with = run(load(c, scale, true));
    const Totals without = run(load(c, scale, false));
    print_skip_row("skips on", with);
    print_skip_row("skips off", without);
    fmt::print("speed-up from the skips: {:.2f}x on the whole run, {:.2f}x on contact work\n",
               without.wall / with.wall,
               contact_seconds(without) / std::max(contact_seconds(with), 1e-12));
  }
}

/// Prints the phase split and the skips' speed-ups; the command line is read by run_benchmark.
int bench_contact(const psq::bench::BenchOptions& options) {
  const double scale = options.number("scale");
  // Both options are checked before the first run, which may take minutes.
  const std::vector<Case> cases = chosen_cases(options);
  const std::string skips = options.text("skips");
  if (skips != "on" && skips != "off") psq::bench::reject_value("skips", skips, "on or off");
  fmt::print("time per Newton iteration [ms]\n");
  fmt::print("{:<16} {:>8} {:>6} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>9}\n", "scene",
             "vertices", "iters", "elastic+", "contact", "friction", "CCD", "factor", "wall",
             "converged");
  for (const Case& c : cases) print_split(c.scene, run(load(c, scale, true)));
  if (skips == "off") return 0;

  // Scenes where contact happens in some frames only: the cloth's free fall onto the ball (cheap
  // frames), and the twisted sheet whose layers meet around frame 9 of 14 (costly frames).
  const std::vector<std::pair<Case, std::string>> skip_cases = {
      {kCases.front(), "contact from frame 4"},
      {{"twist_wrap", 0.1, 0.0, 14}, "self-contact from about frame 9"}};
  for (const auto& [c, when] : skip_cases) print_skip_speedup(c, scale, when);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  using psq::bench::OptionType;
  psq::bench::BenchOptions options(
      "bench_contact",
      {{"scale", OptionType::positive_number, "1",
        "factor on every mesh edge length; 1: the sizes for about a minute"},
       {"scenes", OptionType::text_list, "",
        "scenes of the table to run (drape_sphere,twist_wrap,cylinder_crush,bunny_press)"},
       {"frames", OptionType::count, "", "frames of each scene (default: the table's)"},
       {"skips", OptionType::text, "on", "on: also compare the skips on and off; off: do not"}});
  return psq::bench::run_benchmark(options, argc, argv, bench_contact);
}

// `psq sim SCENE --out DIR [--levels L] [--cache DIR]`: a simulation of a scene, direct at its full
// resolution (levels = 1) or progressive over a hierarchy of L levels (docs/progressive.md).

#include <fmt/format.h>
#include <unistd.h>

#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "engine/contact/intersection_check.hpp"
#include "engine/core/atomic_file.hpp"
#include "engine/core/error.hpp"
#include "engine/mesh/mesh_io.hpp"
#include "engine/progressive/progressive_simulation.hpp"
#include "engine/scene/scene_reader.hpp"
#include "engine/sim/quasistatic.hpp"
#include "runner/commands.hpp"
#include "runner/output_dir.hpp"
#include "runner/shell_parts.hpp"
#include "runner/stats_json.hpp"

namespace psq::runner {
namespace {

struct SimOptions {
  std::string scene;
  std::string out;
  std::optional<int> levels;
  std::string cache;  ///< hierarchy cache directory; empty: build without a cache
};

void write_positions(const std::filesystem::path& path, const TriMesh& rest,
                     const Eigen::VectorXd& x) {
  write_mesh(path, TriMesh{as_positions(x), rest.triangles});
}

std::filesystem::path frame_path(const std::filesystem::path& dir, int frame) {
  return dir / fmt::format("frame_{:04d}.obj", frame);
}

nlohmann::json step_json(const ProgressiveStep& step) {
  nlohmann::json out = frame_json(step.frame);
  out["level"] = step.level;
  out["settling"] = step.settling;
  out["change"] = step.change;
  return out;
}

/// Totals of one level's steps, with the steps themselves.
struct LevelRecord {
  int level = 0;
  int vertices = 0, triangles = 0;
  int iterations = 0;
  double seconds = 0.0;
  bool converged = true;
  std::string settling_failure;  ///< why a settling of the level stopped without an equilibrium
  nlohmann::json steps = nlohmann::json::array();

  [[nodiscard]] nlohmann::json json() const {
    nlohmann::json out{{"level", level},         {"vertices", vertices},
                       {"triangles", triangles}, {"iterations", iterations},
                       {"seconds", seconds},     {"converged", converged},
                       {"steps", steps}};
    if (!settling_failure.empty()) out["settling_failure"] = settling_failure;
    return out;
  }
};

/// Refuses an initial state with intersections, prepares the output directory, prints `header`
/// and writes frame 0 (the rest state); returns the output directory.
std::filesystem::path start_run(const Scene& scene, const ShellSystem& system,
                                const SimOptions& options, const std::string& header) {
  const TriMesh& rest = system.rest_mesh();
  require_intersection_free(rest, fmt::format("{}: initial state", scene.source.string()),
                            shell_parts(system));
  const std::filesystem::path out = prepare_output_dir(options.out);
  std::cerr << header;
  write_positions(frame_path(out, 0), rest, flat(rest.vertices));
  return out;
}

/// Redraws the progress line of a Newton iteration in place ("  <where>  iteration k  …").
void show_iteration(const std::string& where, const NewtonIteration& it) {
  std::cerr << fmt::format("\r  {}  iteration {}  ‖Δx‖∞/Δt {:.3e}  ‖g‖ {:.3e}   ", where,
                           it.iteration, it.step_norm, it.gradient_norm)
            << std::flush;
}

/// "converged", or why not.
std::string verdict(const NewtonResult& newton) {
  if (newton.converged) return "converged";
  if (newton.stagnated)
    return "NOT converged: stagnated at round-off (the tolerance is finer than double precision "
           "resolves here; raise [solver] tolerance above the ‖Δx‖∞/Δt reached)";
  return "NOT converged";
}

/// A direct frame's settling, for its progress line: the static residual only where the settling
/// reached an equilibrium (NaN otherwise, which would read like a numerical failure).
std::string settling_text(const FrameRecord& record) {
  if (record.settle_steps == 0) return "";
  if (std::isnan(record.static_residual))
    return fmt::format(", {} settling steps, no equilibrium reached", record.settle_steps);
  return fmt::format(", {} settling steps, static residual {:.3e}", record.settle_steps,
                     record.static_residual);
}

/// The summary fields of every run; the progressive one adds its levels.
nlohmann::json run_summary(const Scene& scene, const TriMesh& rest, double tolerance,
                           int level_count, bool all_converged, const nlohmann::json& frames) {
  return {{"scene", scene.name},
          {"scene_file", scene.source.string()},
          {"vertices", rest.vertex_count()},
          {"triangles", rest.triangle_count()},
          {"time_step", scene.time.step},
          {"tolerance", tolerance},
          {"frame_solution", scene.solver.frame_solution == FrameSolution::equilibrium
                                 ? "equilibrium"
                                 : "fixed_step"},
          {"level_count", level_count},
          {"all_converged", all_converged},
          {"frames", frames}};
}

/// Writes summary.json, prints its path, and returns the exit code.
int finish(const std::filesystem::path& out, const nlohmann::json& summary, bool all_converged) {
  write_file_atomically(out / "summary.json",
                        [&](std::ostream& o) { o << summary.dump(2) << '\n'; });
  std::cout << (out / "summary.json").string() << '\n';
  if (!all_converged) {
    std::cerr << "psq sim: some frames or levels did not converge (see summary.json)\n";
    return kExitNotConverged;
  }
  return 0;
}

ProgressiveSettings settings_for(const Scene& scene, const SimOptions& options) {
  ProgressiveSettings settings = ProgressiveSettings::from_scene(scene);
  if (options.levels) {
    if (*options.levels < 1)
      throw InputError(fmt::format("--levels must be at least 1 (got {})", *options.levels));
    settings.schedule.levels = *options.levels;
  }
  settings.cache_dir = options.cache;
  return settings;
}

/// levels = 1: the direct simulation, with contact when the scene has it.
int run_direct(const Scene& scene, const SimOptions& sim_options) {
  QuasistaticSimulation sim(scene);
  const TriMesh& rest = sim.system().rest_mesh();
  const std::filesystem::path out = start_run(
      scene, sim.system(), sim_options,
      fmt::format("psq sim: '{}': {} vertices, {} triangles, {} frames, tolerance {:.3g} m/s\n",
                  scene.name, rest.vertex_count(), rest.triangle_count(), sim.frame_count(),
                  sim.newton_settings().tolerance));
  const bool terminal = ::isatty(STDERR_FILENO);

  nlohmann::json frames = nlohmann::json::array();
  bool all_converged = true;
  while (sim.frame() < sim.frame_count()) {
    const FrameRecord record = sim.step([&](int frame, const NewtonIteration& it) {
      if (terminal) show_iteration(fmt::format("frame {}/{}", frame, sim.frame_count()), it);
    });
    write_positions(frame_path(out, record.frame), rest, sim.positions());
    all_converged = all_converged && record.newton.converged;
    frames.push_back(frame_json(record));
    std::cerr << fmt::format(
        "{}  frame {}/{}: {} iterations, {}, ‖Δx‖∞/Δt {:.3e}{}, {:.3f} s\n", terminal ? "\r" : "",
        record.frame, sim.frame_count(), record.newton.iterations,
        verdict(record.newton), record.newton.step_norm,
        settling_text(record),
        record.newton.wall_seconds);
  }
  return finish(out,
                run_summary(scene, rest, sim.newton_settings().tolerance, 1, all_converged, frames),
                all_converged);
}

/// levels > 1: the progressive simulation (docs/progressive.md).
int run_progressive(const Scene& scene, const SimOptions& sim_options,
                    const ProgressiveSettings& settings) {
  ProgressiveSimulation sim(scene, settings);
  const TriMesh& rest = sim.finest_system().rest_mesh();
  const std::filesystem::path out =
      start_run(scene, sim.finest_system(), sim_options,
                fmt::format("psq sim: '{}': {} vertices, {} triangles, {} frames, {} level(s), "
                            "tolerance {:.3g} m/s\n",
                            scene.name, rest.vertex_count(), rest.triangle_count(),
                            sim.frame_count(), sim.level_count(), sim.finest_tolerance()));
  const bool terminal = ::isatty(STDERR_FILENO);

  nlohmann::json frames = nlohmann::json::array();
  nlohmann::json levels = nlohmann::json::array();
  bool all_converged = true;
  for (;;) {
    const bool finest = sim.finest_level();
    LevelRecord level;
    level.level = sim.level();
    level.vertices = sim.level_rest_mesh().vertex_count();
    level.triangles = sim.level_rest_mesh().triangle_count();
    while (!sim.level_done()) {
      const ProgressiveStep step = sim.step([&](int l, int frame, const NewtonIteration& it) {
        if (terminal)
          show_iteration(fmt::format("level {}/{}  frame {}/{}", l, sim.level_count() - 1, frame,
                                     sim.frame_count()),
                         it);
      });
      // Every frame file holds the finest mesh: previews are prolonged to it.
      write_positions(frame_path(out, step.frame.frame), rest, sim.finest_positions());
      level.iterations += step.frame.newton.iterations;
      level.seconds += step.frame.newton.wall_seconds;
      level.steps.push_back(step_json(step));
      if (finest) {
        frames.push_back(step_json(step));
        if (step.judged) level.converged = level.converged && step.converged;
      }
      std::cerr << fmt::format(
          "{}  level {}/{} frame {}/{}{}: {} iterations, {}, change {:.3e} m/s, {:.3f} s\n",
          terminal ? "\r" : "", step.level, sim.level_count() - 1, step.frame.frame,
          sim.frame_count(), step.settling ? " (settling)" : "", step.frame.newton.iterations,
          verdict(step.frame.newton), step.change,
          step.frame.newton.wall_seconds);
      if (!step.settling_failure.empty()) {
        level.settling_failure = step.settling_failure;
        std::cerr << "  " << step.settling_failure << "\n";
      }
    }
    if (sim.level_count() > 1) level.converged = level.converged && sim.level_converged();
    all_converged = all_converged && level.converged;
    write_positions(out / fmt::format("level_{}.obj", sim.level()), sim.level_rest_mesh(),
                    sim.positions());
    levels.push_back(level.json());
    if (!sim.refinement_statistics().empty())
      levels.back()["refinement"] = sim.refinement_statistics();
    if (sim.finished()) break;
    const int next = sim.level() + 1;
    sim.refine([&](const std::string& phase) {
      std::cerr << fmt::format("  refining to level {}/{}: {}\n", next, sim.level_count() - 1,
                               phase);
    });
  }
  nlohmann::json summary =
      run_summary(scene, rest, sim.finest_tolerance(), sim.level_count(), all_converged, frames);
  summary["refine_frame"] = sim.refine_frame();
  if (!settings.cache_dir.empty())
    summary["hierarchy_cache"] = std::filesystem::absolute(settings.cache_dir).string();
  summary["levels"] = levels;
  return finish(out, summary, all_converged);
}

int run_sim(const SimOptions& sim_options) {
  const Scene scene = read_scene(sim_options.scene);
  const ProgressiveSettings settings = settings_for(scene, sim_options);
  return settings.schedule.levels == 1 ? run_direct(scene, sim_options)
                                       : run_progressive(scene, sim_options, settings);
}

}  // namespace

void register_sim_command(CLI::App& app, std::vector<Command>& commands) {
  auto options = std::make_shared<SimOptions>();
  CLI::App* command = app.add_subcommand(
      "sim", "Simulate a scene, directly at its full resolution or progressively over levels");
  command->add_option("scene", options->scene, "Scene file (TOML, see docs/scene-format.md)")
      ->required();
  command
      ->add_option("--out", options->out,
                   "Output directory for frame meshes, level meshes and summary.json")
      ->required();
  command->add_option("--levels", options->levels,
                      "Hierarchy levels (overrides [hierarchy] levels; 1 = direct)");
  command->add_option("--cache", options->cache,
                      "Directory of built hierarchies, reused by later runs of the same mesh, "
                      "depth and decimation settings (created if missing; default: no cache)");
  commands.push_back({command, [options] { return run_sim(*options); }});
}

}  // namespace psq::runner

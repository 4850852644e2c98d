// `psq sim SCENE --out DIR`: a direct simulation at the scene's full resolution.

#include <fmt/format.h>
#include <iostream>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "engine/core/atomic_file.hpp"
#include "engine/contact/intersection_check.hpp"
#include "engine/core/error.hpp"
#include "engine/mesh/mesh_io.hpp"
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
};

void write_frame(const std::filesystem::path& dir, int frame, const TriMesh& rest, const Eigen::VectorXd& x) {
  TriMesh mesh{as_positions(x), rest.triangles};
  write_mesh(dir / fmt::format("frame_{:04d}.obj", frame), mesh);
}

int run_sim(const SimOptions& sim_options) {
  const Scene scene = read_scene(sim_options.scene);
  QuasistaticSimulation sim(scene);
  const TriMesh& rest = sim.system().rest_mesh();
  require_intersection_free(rest, fmt::format("{}: initial state", scene.source.string()),
                            shell_parts(sim.system()));
  const std::filesystem::path out = prepare_output_dir(sim_options.out);
  const bool terminal = ::isatty(STDERR_FILENO);
  std::cerr << fmt::format("psq sim: '{}': {} vertices, {} triangles, {} frames, tolerance {:.3g} m/s\n",
                           scene.name, rest.vertex_count(), rest.triangle_count(), sim.frame_count(),
                           sim.newton_settings().tolerance);
  write_frame(out, 0, rest, sim.positions());

  nlohmann::json frames = nlohmann::json::array();
  bool all_converged = true;
  while (sim.frame() < sim.frame_count()) {
    const FrameRecord record = sim.step([&](int frame, const NewtonIteration& it) {
      if (terminal)
        std::cerr << fmt::format("\r  frame {}/{}  iteration {}  ‖Δx‖∞/Δt {:.3e}  ‖g‖ {:.3e}   ", frame,
                                 sim.frame_count(), it.iteration, it.step_norm, it.gradient_norm)
                  << std::flush;
    });
    write_frame(out, record.frame, rest, sim.positions());
    all_converged = all_converged && record.newton.converged;
    frames.push_back(frame_json(record));
    std::cerr << fmt::format("{}  frame {}/{}: {} iterations, {}, ‖Δx‖∞/Δt {:.3e}, {:.3f} s\n",
                             terminal ? "\r" : "", record.frame, sim.frame_count(),
                             record.newton.iterations, record.newton.converged ? "converged" : "NOT converged",
                             record.newton.step_norm, record.newton.wall_seconds);
  }
  const nlohmann::json summary = {
      {"scene", scene.name},
      {"scene_file", scene.source.string()},
      {"vertices", rest.vertex_count()},
      {"triangles", rest.triangle_count()},
      {"time_step", scene.time.step},
      {"tolerance", sim.newton_settings().tolerance},
      {"all_converged", all_converged},
      {"frames", frames},
  };
  write_file_atomically(out / "summary.json", [&](std::ostream& o) { o << summary.dump(2) << '\n'; });
  std::cout << (out / "summary.json").string() << '\n';
  if (!all_converged) {
    std::cerr << "psq sim: some frames did not converge within solver.max_iterations (see summary.json)\n";
    return kExitNotConverged;
  }
  return 0;
}

}  // namespace

void register_sim_command(CLI::App& app, std::vector<Command>& commands) {
  auto options = std::make_shared<SimOptions>();
  CLI::App* command = app.add_subcommand("sim", "Simulate a scene at its full resolution");
  command->add_option("scene", options->scene, "Scene file (TOML, see docs/scene-format.md)")
      ->required();
  command->add_option("--out", options->out, "Output directory for frame meshes and summary.json")
      ->required();
  commands.push_back({command, [options] { return run_sim(*options); }});
}

}  // namespace psq::runner

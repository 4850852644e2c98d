// `psq check SCENE`: the exact intersection check of a scene's initial state, every shell
// concatenated as the simulator sees it. Exit 0 when it is free of intersections; otherwise
// the offending triangle pairs are listed (shell and local triangle index) and the exit code
// is that of bad input, since the scene must be fixed before it can be simulated.

#include <fmt/format.h>

#include <iostream>
#include <memory>

#include "engine/contact/intersection_check.hpp"
#include "engine/scene/scene_reader.hpp"
#include "engine/sim/shell_system.hpp"
#include "runner/commands.hpp"
#include "runner/shell_parts.hpp"

namespace psq::runner {
namespace {

struct CheckOptions {
  std::string scene;
};

int run_check(const CheckOptions& options) {
  const Scene scene = read_scene(options.scene);
  const ShellSystem system(scene);
  const TriMesh& mesh = system.rest_mesh();
  const IntersectionReport report = find_intersections(mesh.vertices, mesh.triangles);
  if (report.clean()) {
    std::cout << fmt::format("no intersections ({} triangles)\n", report.triangle_count);
    return 0;
  }
  std::cout << list_intersections(report, shell_parts(system));
  std::cerr << fmt::format(
      "psq check: {}: the initial state is not free of intersections; move the shells apart "
      "or fix their meshes\n",
      options.scene);
  return kExitInputError;
}

}  // namespace

void register_check_command(CLI::App& app, std::vector<Command>& commands) {
  auto options = std::make_shared<CheckOptions>();
  CLI::App* command = app.add_subcommand(
      "check", "Check with exact predicates that a scene's initial state has no intersections");
  command->add_option("scene", options->scene, "Scene file (TOML, see docs/scene-format.md)")
      ->required();
  commands.push_back({command, [options] { return run_check(*options); }});
}

}  // namespace psq::runner

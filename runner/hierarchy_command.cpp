// `psq hierarchy MESH --levels L [--ratio r] --out DIR`: builds the simulation hierarchy of a
// mesh (docs/hierarchy.md) and writes level_<l>.obj for every level and hierarchy.json with
// per-level counts, shape quality and the rest-shape error of the direct prolongation.

#include <fmt/format.h>

#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "engine/core/atomic_file.hpp"
#include "engine/core/error.hpp"
#include "engine/hierarchy/mesh_hierarchy.hpp"
#include "engine/hierarchy/shell_prolongation.hpp"
#include "engine/hierarchy/triangle_quality.hpp"
#include "engine/mesh/mesh_io.hpp"
#include "runner/commands.hpp"
#include "runner/output_dir.hpp"

namespace psq::runner {
namespace {

struct HierarchyOptions {
  std::string mesh;
  std::string out;
  int levels = 3;
  double ratio = HierarchySettings{}.vertex_ratio;
};

HierarchySettings checked_settings(const HierarchyOptions& options) {
  if (options.levels < 1) {
    throw InputError(fmt::format("--levels must be at least 1 (got {})", options.levels));
  }
  if (!(options.ratio > 0 && options.ratio < 1)) {
    throw InputError(
        fmt::format("--ratio must lie strictly between 0 and 1 (got {})", options.ratio));
  }
  return {.levels = options.levels, .vertex_ratio = options.ratio};
}

/// max_i |finest rest_i − P^l(level rest)_i| / bounding-box diagonal of the finest mesh.
double rest_error(const MeshHierarchy& hierarchy, int level) {
  const Positions& finest = hierarchy.finest().rest.vertices;
  const Positions prolonged = direct_prolongation(hierarchy, level).apply(
      hierarchy.levels[level].rest.vertices);
  return (prolonged - finest).rowwise().norm().maxCoeff() / bounding_box_diagonal(finest);
}

nlohmann::json level_json(const MeshHierarchy& hierarchy, int level) {
  const TriMesh& rest = hierarchy.levels[level].rest;
  const MeshQuality quality = mesh_quality(rest);
  return {{"level", level},
          {"vertices", rest.vertex_count()},
          {"triangles", rest.triangle_count()},
          {"min_angle_degrees", quality.min_angle_degrees},
          {"max_aspect_ratio", quality.max_aspect_ratio},
          {"rest_error", rest_error(hierarchy, level)}};
}

int run_hierarchy(const HierarchyOptions& options) {
  const HierarchySettings settings = checked_settings(options);
  const TriMesh mesh = read_mesh(options.mesh);
  const std::filesystem::path out = prepare_output_dir(options.out);
  const MeshHierarchy hierarchy = build_hierarchy(mesh, {}, settings);

  nlohmann::json levels = nlohmann::json::array();
  for (int l = 0; l < hierarchy.level_count(); ++l) {
    write_mesh(out / fmt::format("level_{}.obj", l), hierarchy.levels[l].rest);
    levels.push_back(level_json(hierarchy, l));
    std::cout << fmt::format("level {}: {} vertices, {} triangles, rest error {:.2e}\n", l,
                             levels.back()["vertices"].get<int>(),
                             levels.back()["triangles"].get<int>(),
                             levels.back()["rest_error"].get<double>());
  }
  const nlohmann::json summary = {{"mesh", options.mesh},
                                  {"requested_levels", settings.levels},
                                  {"vertex_ratio", settings.vertex_ratio},
                                  {"levels", levels}};
  write_file_atomically(out / "hierarchy.json",
                        [&](std::ostream& stream) { stream << summary.dump(2) << '\n'; });
  return 0;
}

}  // namespace

void register_hierarchy_command(CLI::App& app, std::vector<Command>& commands) {
  auto options = std::make_shared<HierarchyOptions>();
  CLI::App* command = app.add_subcommand(
      "hierarchy", "Build a mesh's simulation hierarchy and write every level with statistics");
  command->add_option("mesh", options->mesh, "Finest mesh (OBJ, PLY or OFF)")->required();
  command->add_option("--levels", options->levels, "Levels including the finest (default 3)");
  command->add_option("--ratio", options->ratio,
                      "Vertex fraction kept from one level to the next coarser (default 0.25)");
  command->add_option("--out", options->out, "Output directory for level_<l>.obj and "
                                             "hierarchy.json")
      ->required();
  commands.push_back({command, [options] { return run_hierarchy(*options); }});
}

}  // namespace psq::runner

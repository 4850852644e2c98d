// Benchmark (prints, never fails on a slow machine): progressive vs direct simulation of the
// drape, twist and cylinder scenes at ~20k–50k fine vertices. Per scene: the time of the direct
// fine solve, of each progressive level and in total, and the errors (max and rms vertex
// distance / bounding-box diagonal) to the settled direct fine answer of: the progressive finest
// answer, the level-0 preview prolonged to the finest mesh, a direct simulation of the level-0
// mesh (its own elastics) prolonged the same way, and the direct fine answer itself sampled at
// the level-0 vertices and prolonged (about the best the level-0 space can hold); and, without
// the prolongation, the preview's and the direct coarse answer's distances at the level-0
// vertices to that sample. Targets (issue 4): level-0 preview ≥ 50× faster than the direct fine
// solve; progressive total faster than the direct fine solve. The contact scenes (drape_sphere,
// twist_wrap, cylinder_crush; their generated colliders refined with the shell) also print each
// refinement's safe initialization by phase; targets (issue 13): safe initialization below 10 %
// of its level's solve, progressive total ≥ 3× faster than the direct fine solve on the
// twisting and crushing scenes.
//
// Usage: bench_progressive [--vertices N] [--levels L] [--frames F] [--gradient exact|held]
//                          [--preview-tolerance T] [--preview-iterations K]
//                          [--scenes drape,twist,cylinder_compress,drape_sphere,...]
//                          [--preview-only 1]   (level 0 only, no direct solves)
//                          [--direct 0]         (all levels, no direct solves or errors)

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <iostream>

#include "bench/bench_options.hpp"
#include "bench/generated_mesh.hpp"
#include "engine/contact/point_triangle_distance.hpp"
#include "engine/progressive/progressive_simulation.hpp"
#include "engine/scene/scene_reader.hpp"
#include "progressive/reference_runs.hpp"

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// The library scene with its shell's edge length set for about `vertices` vertices
/// (near-equilateral triangles: 2/(√3 e²) vertices per unit area), and generated colliders
/// refined by the same factor, so that contact resolves the shell's folds as at the scene's
/// own size.
psq::Scene sized_scene(const std::string& name, int vertices, int frames) {
  psq::Scene scene = psq::read_scene(PSQ_SOURCE_DIR "/jobs/scenes/" + name + ".toml");
  psq::MeshSource& mesh = scene.shells.at(0).mesh;
  const double area = mesh.kind == psq::MeshSource::Kind::Cylinder
                          ? 2 * M_PI * mesh.cylinder.radius * mesh.cylinder.height
                          : mesh.sheet.width * mesh.sheet.height;
  const double edge = std::sqrt(area * 2 / (std::sqrt(3.0) * vertices));
  const double refinement = edge / psq::bench::generated_edge_length(mesh);
  psq::bench::set_generated_edge_length(mesh, edge);
  for (psq::Collider& collider : scene.colliders)
    if (collider.mesh.kind != psq::MeshSource::Kind::File)
      psq::bench::set_generated_edge_length(
          collider.mesh, refinement * psq::bench::generated_edge_length(collider.mesh));
  scene.time.step *= double(scene.time.frames) / frames;
  scene.time.frames = frames;
  return scene;
}

/// `deformed` (positions of `rest`'s vertices) at the points of `rest` closest to each of
/// `points` (barycentric interpolation in the closest triangle), and how far the farthest of
/// `points` lies from `rest`.
struct Sample {
  psq::Positions values;
  double largest_distance = 0.0;
};
Sample sample_at(const psq::TriMesh& rest, const psq::Positions& deformed,
                 const psq::Positions& points) {
  using Kernel = CGAL::Simple_cartesian<double>;
  using Triangles = std::vector<Kernel::Triangle_3>;
  using Primitive = CGAL::AABB_triangle_primitive<Kernel, Triangles::const_iterator>;
  const auto point = [](const auto& row) { return Kernel::Point_3(row(0), row(1), row(2)); };
  Triangles triangles;
  for (int t = 0; t < rest.triangle_count(); ++t)
    triangles.emplace_back(point(rest.vertices.row(rest.triangles(t, 0))),
                           point(rest.vertices.row(rest.triangles(t, 1))),
                           point(rest.vertices.row(rest.triangles(t, 2))));
  const CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>> tree(triangles.begin(),
                                                                    triangles.end());
  Sample result{psq::Positions(points.rows(), 3)};
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const auto [closest, triangle] = tree.closest_point_and_primitive(point(points.row(i)));
    result.largest_distance = std::max(
        result.largest_distance, std::sqrt(CGAL::squared_distance(closest, point(points.row(i)))));
    const auto corners = rest.triangles.row(triangle - triangles.begin());
    const auto vertex = [&](int k) -> Eigen::Vector3d {
      return rest.vertices.row(corners(k)).transpose();
    };
    // The closest point lies on the triangle, so it is its own foot on the triangle's plane,
    // whose barycentric coordinates are minus the weights of t0, t1, t2.
    const Eigen::Vector3d barycentric =
        -psq::point_plane_closest_pair(Eigen::Vector3d(closest.x(), closest.y(), closest.z()),
                                       vertex(0), vertex(1), vertex(2))
             .weights.tail<3>();
    result.values.row(i) = barycentric(0) * deformed.row(corners(0)) +
                           barycentric(1) * deformed.row(corners(1)) +
                           barycentric(2) * deformed.row(corners(2));
  }
  return result;
}

/// The first shell's part of a system's flat positions (shells come first, then colliders):
/// the errors compare the shell alone.
Eigen::VectorXd shell_part(const Eigen::VectorXd& x, const psq::TriMesh& shell) {
  return x.head(3 * shell.vertex_count());
}

void run_scene(const psq::Scene& scene, const psq::ProgressiveSettings& settings,
               bool preview_only, bool direct_solves) {
  auto start = Clock::now();
  psq::ProgressiveSimulation sim(scene, settings);
  const double hierarchy_seconds = seconds_since(start);
  std::cout << fmt::format("{}: {} fine vertices, {} levels (hierarchy {:.2f} s):", scene.name,
                           sim.finest_system().rest_mesh().vertex_count(), sim.level_count(),
                           hierarchy_seconds);
  for (const psq::MeshHierarchy& h : sim.hierarchies())
    for (const psq::HierarchyLevel& level : h.levels) std::cout << " " << level.rest.vertex_count();
  std::cout << "\n";

  Eigen::VectorXd preview, preview_level0;
  double preview_seconds = 0.0, total_seconds = 0.0;
  while (true) {
    start = Clock::now();
    int steps = 0, iterations = 0, shifted = 0, reanalyzed = 0;
    psq::PhaseTimes phases;
    while (!sim.level_done()) {
      const psq::ProgressiveStep step = sim.step();
      iterations += step.frame.newton.iterations;
      phases += step.frame.newton.times;
      for (const psq::NewtonIteration& it : step.frame.newton.history) {
        shifted += it.direction != psq::DirectionKind::newton;
        reanalyzed += it.pattern_changed;
      }
      ++steps;
    }
    const double level_seconds = seconds_since(start);
    total_seconds += level_seconds;
    std::cout << fmt::format(
        "  level {} ({} vertices): {} steps, {} iterations, {:.2f} s{} [assembly {:.2f}, "
        "factorization {:.2f}, solve {:.2f}, line search {:.2f} s; {} shifted, {} re-analyzed]\n",
        sim.level(), sim.level_rest_mesh().vertex_count(), steps, iterations, level_seconds,
        sim.level_converged() ? "" : " (NOT converged)", phases.assembly, phases.factorization,
        phases.solve, phases.line_search, shifted, reanalyzed);
    if (sim.level() == 0) {
      preview = shell_part(sim.finest_positions(), sim.hierarchies().at(0).levels.back().rest);
      preview_level0 = shell_part(sim.positions(), sim.hierarchies().at(0).levels[0].rest);
      preview_seconds = level_seconds;
    }
    if (sim.finished() || preview_only) break;
    start = Clock::now();
    sim.refine();
    const double refine_seconds = seconds_since(start);
    total_seconds += refine_seconds;
    std::cout << fmt::format("  refinement into level {}: {:.2f} s", sim.level(), refine_seconds);
    if (!sim.refinements().empty() && sim.refinements().back().level == sim.level()) {
      const psq::RefinementStats& r = sim.refinements().back();
      std::cout << fmt::format(
          " [safe initialization {:.2f} s: gap {:.2f}, perturbation {:.2f}, CCD advance {:.2f} "
          "({} rounds, {} redone for a fold), relaxation {:.2f}, exact check {:.2f} s; {} batches]",
          r.seconds, r.gap_seconds, r.perturb_seconds, r.ccd_seconds, r.ccd_rounds,
          r.folded_advances, r.relax_seconds, r.check_seconds, r.batches);
    }
    std::cout << "\n";
  }

  if (preview_only || !direct_solves) {
    std::cout << fmt::format("  progressive: preview {:.2f} s, total {:.2f} s\n", preview_seconds,
                             preview_only ? preview_seconds : total_seconds);
    return;
  }
  const psq::ShellSystem& fine = sim.finest_system();
  start = Clock::now();
  const psq::test::DirectRun direct = psq::test::settled_direct_run(fine, sim.finest_tolerance());
  const double direct_seconds = seconds_since(start);

  const psq::MeshHierarchy& h = sim.hierarchies().at(0);
  const psq::ShellSystem coarse(scene,
                                {{h.levels[0].rest, h.levels[0].pin_group, fine.shared_pins(0)}});
  start = Clock::now();
  const psq::test::DirectRun direct_coarse =
      psq::test::settled_direct_run(coarse, sim.finest_tolerance());
  const double coarse_seconds = seconds_since(start);
  const psq::TriMesh& fine_shell = h.levels.back().rest;
  const psq::ShellProlongation to_finest(h.levels[0].rest, h.levels[0].finest, fine_shell.vertices);
  const Eigen::VectorXd direct_coarse_shell = shell_part(direct_coarse.positions, h.levels[0].rest);
  const Eigen::VectorXd direct_shell = shell_part(direct.positions, fine_shell);
  const Eigen::VectorXd coarse_prolonged =
      psq::flat(to_finest.apply(psq::as_positions(direct_coarse_shell)));

  // What the level-0 space can hold at best, roughly: the direct fine answer sampled at the
  // level-0 rest vertices (each at its closest point on the fine rest mesh), prolonged by P^0.
  const Sample sample =
      sample_at(fine_shell, psq::as_positions(direct_shell), h.levels[0].rest.vertices);
  const Eigen::VectorXd sampled = psq::flat(sample.values);
  const Eigen::VectorXd sampled_prolonged = psq::flat(to_finest.apply(sample.values));

  const double diagonal = psq::bounding_box_diagonal(fine_shell.vertices);
  const auto errors = [&](const Eigen::VectorXd& x, const Eigen::VectorXd& reference) {
    return fmt::format("{:.2e} ({:.2e})",
                       psq::test::max_vertex_distance(x, reference) / diagonal,
                       psq::test::rms_vertex_distance(x, reference) / diagonal);
  };
  std::cout << fmt::format(
      "  direct fine: {} iterations, {:.2f} s{}; direct coarse: {:.2f} s\n"
      "  progressive: preview {:.2f} s ({:.1f}× faster than direct fine), total {:.2f} s "
      "({:.2f}× the direct fine time)\n"
      "  error / bbox diagonal, max (rms): progressive finest {}, level-0 preview {}, "
      "direct coarse {}, fine answer sampled at level 0 {}\n"
      "  at the level-0 vertices, max (rms): level-0 preview {}, direct coarse {} (the level-0 "
      "rest vertices lie up to {:.1e} off the fine rest mesh: the samples are exact only at 0)\n",
      direct.newton_iterations, direct_seconds, direct.settled ? "" : " (NOT settled)",
      coarse_seconds, preview_seconds, direct_seconds / preview_seconds, total_seconds,
      total_seconds / direct_seconds, errors(shell_part(sim.positions(), fine_shell), direct_shell),
      errors(preview, direct_shell), errors(coarse_prolonged, direct_shell),
      errors(sampled_prolonged, direct_shell),
      // Without the prolongation's interpolation error: at the level-0 vertices, to the sample.
      errors(preview_level0, sampled), errors(direct_coarse_shell, sampled),
      sample.largest_distance / diagonal);
}

/// Runs every scene progressively and directly; the command line is read by run_benchmark.
int bench_progressive(const psq::bench::BenchOptions& options) {
  const int vertices = options.integer("vertices"), levels = options.integer("levels"),
            frames = options.integer("frames");
  const std::string gradient = options.text("gradient");
  if (gradient != "exact" && gradient != "held")
    psq::bench::reject_value("gradient", gradient, "exact or held");
  const std::vector<std::string> scenes = options.texts("scenes");
  const int preview_only = options.integer("preview-only"), direct = options.integer("direct");
  if (preview_only != 0 && preview_only != 1)
    psq::bench::reject_value("preview-only", std::to_string(preview_only), "0 or 1");
  if (direct != 0 && direct != 1) psq::bench::reject_value("direct", std::to_string(direct), "0 or 1");
  std::cout << fmt::format(
      "bench_progressive: ~{} fine vertices, {} levels, {} frames, {} gradient\n", vertices, levels,
      frames, gradient);
  for (const std::string& name : scenes) {
    const psq::Scene scene = sized_scene(name, vertices, frames);
    psq::ProgressiveSettings settings = psq::ProgressiveSettings::from_scene(scene);
    settings.schedule.levels = levels;
    if (options.given("preview-tolerance"))
      settings.schedule.preview_tolerance = options.number("preview-tolerance");
    if (options.given("preview-iterations"))
      settings.schedule.preview_iterations = options.integer("preview-iterations");
    settings.gradient =
        gradient == "exact" ? psq::ProxyGradient::exact : psq::ProxyGradient::held_offsets;
    run_scene(scene, settings, preview_only == 1, direct == 1);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  using psq::bench::OptionType;
  psq::bench::BenchOptions options(
      "bench_progressive",
      {{"vertices", OptionType::count, "20000", "about this many fine vertices per scene"},
       {"levels", OptionType::count, "3", "hierarchy levels"},
       {"frames", OptionType::count, "10", "frames per scene"},
       // The solver's default (ProgressiveSettings).
       {"gradient", OptionType::text, "exact", "proxy gradient: exact or held"},
       {"preview-tolerance", OptionType::positive_number, "",
        "level-0 tolerance (default: the scene's, 10 x its tolerance)"},
       {"preview-iterations", OptionType::count, "",
        "Newton-type iterations per preview step at most (default: the scene's, 2)"},
       {"scenes", OptionType::text_list, "drape,twist,cylinder_compress", "library scenes"},
       {"preview-only", OptionType::integer, "0", "1: level 0 only, no direct solves"},
       {"direct", OptionType::integer, "1",
        "0: no direct solves and no errors, only the progressive run"}});
  return psq::bench::run_benchmark(options, argc, argv, bench_progressive);
}

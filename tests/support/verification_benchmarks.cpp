#include "support/verification_benchmarks.hpp"

#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "bench/generated_mesh.hpp"
#include "engine/scene/scene_reader.hpp"
#include "support/test_paths.hpp"

namespace psq::test {
namespace {

/// The mean, over the vertices `chosen` by their rest position, of their displacement along
/// `direction`.
template <class Chosen>
double mean_displacement(const QuasistaticSimulation& sim, Chosen&& chosen,
                         const Eigen::Vector3d& direction) {
  const TriMesh& rest = sim.system().rest_mesh();
  double sum = 0.0;
  int count = 0;
  for (int v = 0; v < rest.vertex_count(); ++v) {
    const Eigen::Vector3d p = rest.vertices.row(v).transpose();
    if (!chosen(p)) continue;
    sum += (sim.positions().segment<3>(3 * v) - p).dot(direction);
    ++count;
  }
  if (count == 0) throw std::logic_error("verification: the probe selects no vertex");
  return sum / count;
}

/// The mean displacement of the point-loaded vertices along their loads.
double displacement_under_loads(const QuasistaticSimulation& sim, const FrameRecord&) {
  const Eigen::VectorXd& force = sim.system().external_force();
  const TriMesh& rest = sim.system().rest_mesh();
  double sum = 0.0;
  int count = 0;
  for (int v = 0; v < rest.vertex_count(); ++v) {
    const Eigen::Vector3d f = force.segment<3>(3 * v);
    if (f.isZero(0.0)) continue;
    sum += (sim.positions().segment<3>(3 * v) - rest.vertices.row(v).transpose()).dot(
        f.normalized());
    ++count;
  }
  if (count == 0) throw std::logic_error("verification: the scene loads no vertex");
  return sum / count;
}

/// The roll-up's elastic energy: ½ EI (2π)²/L for EI = E b h³/12 = 0.1 N·m², L = 1 m.
constexpr double kRollUpEnergy = 0.5 * 0.1 * (2 * std::numbers::pi) * (2 * std::numbers::pi);

/// The load factor of the roof and the hemisphere. At its published load the roof deflects
/// about its thickness, and PSQ's geometrically exact equilibrium is 12 % stiffer than the
/// linear reference (docs/verification.md); at 1 % of it the nonlinear part is 100 times
/// smaller. The hemisphere turned out linear at its load (to 0.01 %) and is scaled alike. The
/// pinched cylinder's scene is loaded 5000 times the published load (its comment says why) and
/// extrapolated to zero load from it and twice it.
constexpr double kLinearScale = 0.01;

/// Scordelis–Lo's free edges at y = ±25 sin 40°, midside at x = 0 (the scene's placement).
double scordelis_lo_midside_sag(const QuasistaticSimulation& sim, const FrameRecord&) {
  const double edge = 25 * std::sin(40 * std::numbers::pi / 180);
  return mean_displacement(
      sim,
      [&](const Eigen::Vector3d& p) {
        return std::abs(p.x()) < 1e-9 && std::abs(std::abs(p.y()) - edge) < 1e-6;
      },
      -Eigen::Vector3d::UnitZ());
}

std::vector<VerificationBenchmark> make_benchmarks() {
  return {
      {"roll_up", "elastic energy [J] at a full circle", kRollUpEnergy,
       "Euler elastica: W = ½ EI (2π)²/L", 1, false, {0.05, 0.025, 0.0125, 0.00625},
       [](const QuasistaticSimulation&, const FrameRecord& last) { return last.elastic_energy; }},
      {"scordelis_lo", "vertical sag at the free edge's midside", 0.3024,
       "MacNeal & Harder 1985 (0.3006 by deep-shell theory)", kLinearScale, false, {5, 2.5, 1.25, 0.625},
       scordelis_lo_midside_sag},
      {"pinched_cylinder", "radial displacement under a load P = 5000", 5000 * 1.8248e-5,
       "MacNeal & Harder 1985: 1.8248e-5 per unit load", 1, true, {50, 25, 12.5, 6.25},
       displacement_under_loads},
      {"pinched_hemisphere", "displacement under a load along it", 0.094,
       "MacNeal & Harder 1985 (0.093 also quoted)", kLinearScale, false, {1, 0.5, 0.25, 0.125},
       displacement_under_loads},
  };
}

}  // namespace

const std::vector<VerificationBenchmark>& verification_benchmarks() {
  static const std::vector<VerificationBenchmark> benchmarks = make_benchmarks();
  return benchmarks;
}

const VerificationBenchmark& verification_benchmark(const std::string& name) {
  for (const VerificationBenchmark& b : verification_benchmarks())
    if (b.name == name) return b;
  throw std::invalid_argument("no verification benchmark '" + name + "'");
}

Scene verification_scene(const VerificationBenchmark& benchmark, BendingModel bending,
                         double edge_length) {
  Scene scene =
      read_scene(source_dir() / "jobs" / "scenes" / "verification" / (benchmark.name + ".toml"));
  scene.shells.at(0).bending = bending;
  bench::set_generated_edge_length(scene.shells[0].mesh, edge_length);
  // The weight through the density, not gravity: the inertia-like term of the first steps then
  // shrinks with the load instead of holding a hundredfold load back (and stalling Newton).
  scene.shells[0].material.density *= benchmark.load_scale;
  for (Load& load : scene.shells[0].loads) load.total_force *= benchmark.load_scale;
  if (scene.solver.tolerance) *scene.solver.tolerance *= benchmark.load_scale;
  return scene;
}

namespace {

/// One simulation of the benchmark's scene with its loads scaled by `load_scale` (and the
/// tolerance with them); the value per unit of load_scale.
VerificationRun run_at(const VerificationBenchmark& benchmark, BendingModel bending,
                       double edge_length, double load_scale) {
  VerificationBenchmark scaled = benchmark;
  scaled.load_scale = load_scale;
  const auto start = std::chrono::steady_clock::now();
  QuasistaticSimulation sim(verification_scene(scaled, bending, edge_length));
  VerificationRun run;
  run.vertices = sim.system().rest_mesh().vertex_count();
  run.converged = true;
  FrameRecord last;
  while (sim.frame() < sim.frame_count()) {
    last = sim.step();
    run.converged = run.converged && last.newton.converged;
  }
  run.value = benchmark.measure(sim, last) / load_scale;
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

}  // namespace

VerificationRun run_verification(const VerificationBenchmark& benchmark, BendingModel bending,
                                 double edge_length) {
  VerificationRun run = run_at(benchmark, bending, edge_length, benchmark.load_scale);
  if (!benchmark.extrapolate_in_load) return run;
  const VerificationRun doubled = run_at(benchmark, bending, edge_length, 2 * benchmark.load_scale);
  run.value = 2 * run.value - doubled.value;
  run.converged = run.converged && doubled.converged;
  run.seconds += doubled.seconds;
  return run;
}

}  // namespace psq::test

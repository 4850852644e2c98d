#pragma once
// The solvers a job can run, behind LevelSolver. Header-only on purpose: psq_jobs links the
// scene, store and checkpoint modules but not the simulation (psq_sim), so the code that builds
// a simulation lives in the translation units of the programs that link the engine (psq, its
// tests and benchmarks), which include this header.

#include <fmt/format.h>

#include <memory>

#include "engine/core/error.hpp"
#include "engine/progressive/progressive_simulation.hpp"
#include "engine/sim/quasistatic.hpp"
#include "engine/sim/shell_system.hpp"
#include "jobs/level_solver.hpp"

namespace psq::jobs {

/// The shells, then the colliders, of `system`, as they lie in its concatenated arrays.
inline std::vector<PartRange> system_parts(const ShellSystem& system) {
  std::vector<PartRange> parts;
  const auto add = [&](const MeshBlock& block, PartKind kind) {
    parts.push_back({block.name, kind, block.first_vertex, block.vertex_count, block.first_triangle,
                     block.triangle_count});
  };
  for (const ShellBlock& shell : system.shells()) add(shell, PartKind::shell);
  for (const ColliderBlock& collider : system.colliders()) add(collider, PartKind::collider);
  return parts;
}

/// A solved frame's load scale and probe readings, for the store.
inline db::FrameReadings frame_readings(const FrameRecord& record) {
  db::FrameReadings readings{.frame = record.frame, .load_scale = record.load_scale, .probes = {}};
  for (const ProbeReading& probe : record.probes)
    readings.probes.push_back(
        {.probe = probe.name,
         .kind = probe.kind == ProbeKind::displacement ? "displacement" : "reaction",
         .value = {probe.value.x(), probe.value.y(), probe.value.z()}});
  return readings;
}

/// A direct solve as a hierarchy of one level: QuasistaticSimulation over the scene's frames.
class DirectLevelSolver final : public LevelSolver {
 public:
  explicit DirectLevelSolver(const Scene& scene) : simulation_(scene) {}

  int level_count() const override { return 1; }
  int level() const override { return 0; }
  int frame() const override { return simulation_.frame(); }
  int frame_count() const override { return simulation_.frame_count(); }
  bool level_done() const override { return simulation_.frame() == simulation_.frame_count(); }
  bool finished() const override { return level_done(); }

  LevelFrame step(const Progress& progress) override {
    const FrameRecord record = simulation_.step(progress);
    return {.level = 0,
            .frame = record.frame,
            .converged = record.newton.converged,
            .stagnated = record.newton.stagnated,
            .iterations = record.newton.iterations,
            .step_norm = record.newton.step_norm,
            .gradient_norm = record.newton.gradient_norm,
            .elastic_energy = record.elastic_energy,
            // The record says only that the step or its settling ran out of iterations.
            .failure = {},
            .times = record.newton.times,
            .readings = frame_readings(record)};
  }

  void refine(const RefinementPhase&) override {
    throw std::logic_error("DirectLevelSolver::refine: a direct solve has one level");
  }

  const Eigen::VectorXd& positions() const override { return simulation_.positions(); }
  const Eigen::VectorXd& previous() const override { return simulation_.previous(); }
  const TriMesh& level_rest_mesh() const override { return simulation_.system().rest_mesh(); }
  std::vector<PartRange> level_parts() const override { return system_parts(simulation_.system()); }
  Positions finest_positions() const override { return as_positions(simulation_.positions()); }

  bool settles_frame(int) const override {
    return simulation_.system().scene().solver.frame_solution == FrameSolution::equilibrium;
  }
  std::map<std::string, double> state() const override { return simulation_.adaptive_state(); }
  void restore(int level, int frame, const Eigen::VectorXd& positions,
               const Eigen::VectorXd& previous, int iterations_in_frame,
               const std::map<std::string, double>& state) override {
    if (level != 0)
      throw std::invalid_argument(fmt::format("restore: level {} of a direct solve", level));
    simulation_.restore(frame, positions, previous, iterations_in_frame, state);
  }

 private:
  QuasistaticSimulation simulation_;
};

/// A progressive solve (engine/progressive) over `depth` levels. Settling steps at the refine
/// frame are steps like any other: they may repeat a frame number.
class ProgressiveLevelSolver final : public LevelSolver {
 public:
  ProgressiveLevelSolver(const Scene& scene, int depth, const std::filesystem::path& cache_dir)
      : simulation_(scene, settings(scene, depth, cache_dir)) {}
  int level_count() const override { return simulation_.level_count(); }
  int level() const override { return simulation_.level(); }
  int frame() const override { return simulation_.frame(); }
  int frame_count() const override { return simulation_.frame_count(); }
  bool level_done() const override { return simulation_.level_done(); }
  bool finished() const override { return simulation_.finished(); }
  LevelFrame step(const Progress& progress) override {
    const ProgressiveStep step = simulation_.step(
        [&](int, int frame, const NewtonIteration& iteration) { progress(frame, iteration); });
    const NewtonResult& newton = step.frame.newton;
    return {.level = step.level,
            .frame = step.frame.frame,
            .converged = step.converged,
            .stagnated = newton.stagnated,
            .must_converge = step.judged,
            .iterations = newton.iterations,
            .step_norm = newton.step_norm,
            .gradient_norm = newton.gradient_norm,
            .elastic_energy = step.frame.elastic_energy,
            .failure = step.settling_failure,
            .times = newton.times,
            .readings = frame_readings(step.frame)};
  }
  void refine(const RefinementPhase& phase) override { simulation_.refine(phase); }
  std::map<std::string, double> refinement_statistics() const override {
    return simulation_.refinement_statistics();
  }
  std::vector<db::HierarchyCacheUse> hierarchy_cache_uses() const override {
    std::vector<db::HierarchyCacheUse> uses;
    for (const HierarchyCacheUse& use : simulation_.hierarchy_cache_uses())
      uses.push_back({.key = fmt::format("{:016x}", use.key),
                      .hit = use.outcome == HierarchyCacheOutcome::kHit,
                      .seconds = use.seconds});
    return uses;
  }
  const Eigen::VectorXd& positions() const override { return simulation_.positions(); }
  const Eigen::VectorXd& previous() const override { return simulation_.previous(); }
  const TriMesh& level_rest_mesh() const override { return simulation_.level_rest_mesh(); }
  std::vector<PartRange> level_parts() const override {
    return system_parts(simulation_.level_system());
  }
  Positions finest_positions() const override {
    return as_positions(simulation_.finest_positions());
  }
  bool settles_frame(int frame) const override { return simulation_.frame_settles(frame); }
  std::map<std::string, double> state() const override { return simulation_.schedule_state(); }
  void restore(int level, int frame, const Eigen::VectorXd& positions,
               const Eigen::VectorXd& previous, int iterations_in_frame,
               const std::map<std::string, double>& state) override {
    simulation_.restore(level, frame, positions, previous, iterations_in_frame, state);
  }

 private:
  static ProgressiveSettings settings(const Scene& scene, int depth,
                                      const std::filesystem::path& cache_dir) {
    ProgressiveSettings result = ProgressiveSettings::from_scene(scene);
    result.schedule.levels = depth;
    result.cache_dir = cache_dir;
    return result;
  }
  ProgressiveSimulation simulation_;
};

/// The solver of a job with `depth` hierarchy levels on `scene`; hierarchies are cached in
/// `cache_dir` (empty: built every time).
inline std::unique_ptr<LevelSolver> make_level_solver(const Scene& scene, int depth,
                                                      const std::filesystem::path& cache_dir = {}) {
  if (depth == 1) return std::make_unique<DirectLevelSolver>(scene);
  return std::make_unique<ProgressiveLevelSolver>(scene, depth, cache_dir);
}

}  // namespace psq::jobs

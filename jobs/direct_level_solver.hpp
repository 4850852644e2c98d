#pragma once
// The solvers a job can run, behind LevelSolver. Header-only on purpose: psq_jobs links the
// scene, store and checkpoint modules but not the simulation (psq_sim), so the code that builds
// a simulation lives in the translation units of the programs that link the engine (psq, its
// tests and benchmarks), which include this header.

#include <fmt/format.h>

#include <memory>
#include <optional>

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

/// The hierarchy cache uses of a simulation as the store takes them.
inline std::vector<db::HierarchyCacheUse> store_cache_uses(
    const std::vector<HierarchyCacheUse>& uses) {
  std::vector<db::HierarchyCacheUse> stored;
  for (const HierarchyCacheUse& use : uses)
    stored.push_back({.key = fmt::format("{:016x}", use.key),
                      .hit = use.outcome == HierarchyCacheOutcome::kHit,
                      .seconds = use.seconds});
  return stored;
}

/// The progressive settings of a job: the scene's, with the job's depth and hierarchy cache.
inline ProgressiveSettings job_progressive_settings(const Scene& scene, int depth,
                                                   const std::filesystem::path& cache_dir) {
  ProgressiveSettings result = ProgressiveSettings::from_scene(scene);
  result.schedule.levels = depth;
  result.cache_dir = cache_dir;
  return result;
}

/// A direct solve as a hierarchy of one level: QuasistaticSimulation over the scene's frames,
/// on the finest mesh or (coarse_prolonged) on a coarse level of a hierarchy as a problem of
/// its own, whose answer is then prolonged to the finest mesh.
class DirectLevelSolver final : public LevelSolver {
 public:
  /// With `first_settled_frame`, frames before it are not settled
  /// (QuasistaticSimulation::settle_from_frame).
  explicit DirectLevelSolver(const Scene& scene, int first_settled_frame = 1)
      : simulation_(scene) {
    simulation_.settle_from_frame(first_settled_frame);
  }
  /// The direct solve of `coarse`; `uses`: how its hierarchies were obtained.
  DirectLevelSolver(const Scene& scene, const CoarseProblem& coarse,
                    std::vector<db::HierarchyCacheUse> uses)
      : to_finest_(coarse.to_finest),
        finest_rest_(coarse.finest_rest),
        cache_uses_(std::move(uses)),
        simulation_(scene, coarse.shells, coarse.colliders, coarse.loads) {}

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
  Positions finest_positions() const override {
    return as_positions(to_finest_ ? to_finest_->apply(simulation_.positions())
                                   : simulation_.positions());
  }
  const Positions& finest_rest_positions() const override {
    return to_finest_ ? finest_rest_ : simulation_.system().rest_mesh().vertices;
  }
  std::vector<db::HierarchyCacheUse> hierarchy_cache_uses() const override { return cache_uses_; }

  bool settles_frame(int frame) const override { return simulation_.frame_settles(frame); }
  std::map<std::string, double> state() const override { return simulation_.adaptive_state(); }
  void restore(int level, int frame, const Eigen::VectorXd& positions,
               const Eigen::VectorXd& previous, int iterations_in_frame,
               const std::map<std::string, double>& state) override {
    if (level != 0)
      throw std::invalid_argument(fmt::format("restore: level {} of a direct solve", level));
    simulation_.restore(frame, positions, previous, iterations_in_frame, state);
  }

 private:
  /// P^l of a coarse solve; none on the finest mesh.
  std::optional<SystemProlongation> to_finest_;
  Positions finest_rest_;  ///< of a coarse solve; empty on the finest mesh
  std::vector<db::HierarchyCacheUse> cache_uses_;
  QuasistaticSimulation simulation_;
};

/// A progressive solve (engine/progressive) over `depth` levels. Settling steps at the refine
/// frame are steps like any other: they may repeat a frame number.
class ProgressiveLevelSolver final : public LevelSolver {
 public:
  ProgressiveLevelSolver(const Scene& scene, int depth, const std::filesystem::path& cache_dir)
      : simulation_(scene, job_progressive_settings(scene, depth, cache_dir)) {}
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
    return store_cache_uses(simulation_.hierarchy_cache_uses());
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
  const Positions& finest_rest_positions() const override {
    return simulation_.finest_system().rest_mesh().vertices;
  }
  bool settles_frame(int frame) const override { return simulation_.frame_settles(frame); }
  std::map<std::string, double> state() const override { return simulation_.schedule_state(); }
  void restore(int level, int frame, const Eigen::VectorXd& positions,
               const Eigen::VectorXd& previous, int iterations_in_frame,
               const std::map<std::string, double>& state) override {
    simulation_.restore(level, frame, positions, previous, iterations_in_frame, state);
  }

 private:
  ProgressiveSimulation simulation_;
};

/// The direct solve of the coarsest level of `scene`'s hierarchy of `depth` levels (built or
/// read through `cache_dir`), prolonged to the finest mesh.
inline std::unique_ptr<LevelSolver> make_coarse_prolonged_solver(
    const Scene& scene, int depth, const std::filesystem::path& cache_dir) {
  // The progressive simulation builds the hierarchies and the level's meshes and prolongation;
  // it is dropped once it has handed them over.
  const ProgressiveSimulation hierarchy(scene, job_progressive_settings(scene, depth, cache_dir));
  return std::make_unique<DirectLevelSolver>(scene, hierarchy.coarse_problem(0),
                                             store_cache_uses(hierarchy.hierarchy_cache_uses()));
}

/// The solver of a job of `method` with a hierarchy of `depth` levels (1 for a direct job) on
/// `scene`; hierarchies are cached in `cache_dir` (empty: built every time).
inline std::unique_ptr<LevelSolver> make_level_solver(const Scene& scene, db::Method method,
                                                      int depth,
                                                      const std::filesystem::path& cache_dir = {}) {
  switch (method) {
    case db::Method::direct:
      return std::make_unique<DirectLevelSolver>(scene);
    case db::Method::direct_final:
      // Where a progressive solve of the scene reaches its finest level.
      return std::make_unique<DirectLevelSolver>(
          scene, scene.hierarchy.refine_frame.value_or(scene.time.frames));
    case db::Method::progressive:
      return std::make_unique<ProgressiveLevelSolver>(scene, depth, cache_dir);
    case db::Method::coarse_prolonged:
      return make_coarse_prolonged_solver(scene, depth, cache_dir);
  }
  throw std::logic_error("make_level_solver: not a method");
}

}  // namespace psq::jobs

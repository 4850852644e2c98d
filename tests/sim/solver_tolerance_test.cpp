// The scene checks the stress suite added (docs/stress.md): a pseudo time step so large that
// the tolerance accepts steps of a visible fraction of the scene is refused naming time.step
// and solver.tolerance, and a shell with slivers is refused naming the shell.

#include "engine/sim/solver_tolerance.hpp"

#include <gtest/gtest.h>

#include "engine/core/error.hpp"
#include "engine/mesh/tri_mesh.hpp"
#include "engine/sim/shell_system.hpp"
#include "support/library_scene.hpp"

namespace psq {
namespace {

/// The message of the InputError building the scene's shell system throws ("" if none).
std::string refusal(const Scene& scene) {
  try {
    const ShellSystem system(scene);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SolverTolerance, DefaultsToATenThousandthOfTheSizePerSecond) {
  Scene scene = test::library_scene("drape");
  scene.solver.tolerance.reset();
  EXPECT_DOUBLE_EQ(solver_tolerance(scene, 2.0), 2e-4);
  scene.solver.tolerance = 3e-5;
  EXPECT_DOUBLE_EQ(solver_tolerance(scene, 2.0), 3e-5);
}

TEST(SolverTolerance, AStepWhoseToleranceAcceptsAVisibleMoveIsRefused) {
  Scene scene = test::library_scene("drape");  // a 1 m sheet, diagonal √2 m
  scene.solver.tolerance.reset();
  // The default tolerance 1e-4·√2 m/s allows Δt up to 10 s (a move of 1e-3 of the size).
  scene.time.step = 9.0;
  EXPECT_EQ(refusal(scene), "");
  scene.time.step = 1000.0;
  const std::string message = refusal(scene);
  EXPECT_NE(message.find("drape.toml: time.step = 1000 s"), std::string::npos) << message;
  EXPECT_NE(message.find("(its default"), std::string::npos) << message;
  EXPECT_NE(message.find("lower time.step to at most 10 s or solver.tolerance to at most "
                         "1.41e-06 m/s"),
            std::string::npos)
      << message;
  // A tolerance fine enough for that step passes (tests/sim/cantilever_test solves statically
  // that way).
  scene.solver.tolerance = 1e-6;
  EXPECT_EQ(refusal(scene), "");
}

TEST(SolverTolerance, AShellWithSliversIsRefusedNamingIt) {
  const Scene scene = read_scene(test::source_dir() / "jobs/scenes/stress/sliver_sheet.toml");
  const std::string message = refusal(scene);
  EXPECT_NE(message.find("sliver_sheet.toml: shell 'sheet': triangle"), std::string::npos)
      << message;
  EXPECT_NE(message.find("is a sliver"), std::string::npos) << message;
  // The same sheet with its needles 100 times wider is solved (jobs/scenes/stress/shaped_sheets).
  EXPECT_EQ(refusal(read_scene(test::source_dir() / "jobs/scenes/stress/shaped_sheets.toml")), "");
}

}  // namespace
}  // namespace psq

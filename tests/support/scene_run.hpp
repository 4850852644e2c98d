#pragma once
// Simulating a scene frame by frame with QuasistaticSimulation, checking every stored frame with
// the exact intersection check (for the contact scene tests).

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include "engine/contact/intersection_check.hpp"
#include "engine/sim/quasistatic.hpp"

namespace psq::test {

/// The outcome of simulating a scene frame by frame.
struct SceneRun {
  std::vector<FrameRecord> frames;
  std::vector<std::string> intersecting_frames;  ///< "frame k: <listing>"
};

/// Simulates every frame of `scene`; `after_frame` (optional) sees the simulation after each.
inline SceneRun simulate(
    const Scene& scene, const std::function<void(const QuasistaticSimulation&)>& after_frame = {}) {
  QuasistaticSimulation sim(scene);
  const Triangles& triangles = sim.system().rest_mesh().triangles;
  SceneRun run;
  while (sim.frame() < sim.frame_count()) {
    run.frames.push_back(sim.step());
    const IntersectionReport report = find_intersections(as_positions(sim.positions()), triangles);
    if (!report.clean())
      run.intersecting_frames.push_back(
          fmt::format("frame {}: {}", sim.frame(), list_intersections(report, {})));
    if (after_frame) after_frame(sim);
  }
  return run;
}

/// Every stored frame passed the intersection check and every frame's Newton solve converged.
inline void expect_intersection_free_and_converged(const SceneRun& run) {
  EXPECT_TRUE(run.intersecting_frames.empty())
      << fmt::format("{}", fmt::join(run.intersecting_frames, "\n"));
  for (const FrameRecord& f : run.frames) EXPECT_TRUE(f.newton.converged) << "frame " << f.frame;
}

}  // namespace psq::test

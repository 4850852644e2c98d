// `psq sim` end to end, as a user runs it: outputs, exit codes and messages.

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "support/run_process.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

/// A small, fast scene: a 0.2 m sheet pinned along one edge, sagging under gravity.
std::string small_scene(int frames) {
  return "name = \"sag\"\ngravity = [0, 0, -9.81]\n[time]\nstep = 0.05\nframes = " +
         std::to_string(frames) +
         "\n[[shell]]\nname = \"sheet\"\n"
         "mesh = { generator = \"sheet\", width = 0.2, height = 0.2, edge_length = 0.04 }\n"
         "material = { youngs_modulus = 1e5, poisson_ratio = 0.3, density = 200, thickness = 1e-3 "
         "}\n"
         "[[shell.pin]]\nname = \"edge\"\nbox = { min = [-0.11, -0.11, -0.01], max = [-0.09, 0.11, "
         "0.01] }\n";
}

TEST(SimCommand, WritesEveryFrameAndASummary) {
  const auto dir = test::fresh_temp_dir("sim");
  const auto scene = test::write_file(dir / "sag.toml", small_scene(3));
  const auto result = test::run_psq({"sim", scene.string(), "--out", (dir / "out").string()});
  ASSERT_EQ(result.exit_code, 0) << result.errors;
  for (int f = 0; f <= 3; ++f)
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / ("frame_000" + std::to_string(f) + ".obj")))
        << f;
  EXPECT_NE(result.output.find("summary.json"), std::string::npos);
  std::ifstream in(dir / "out" / "summary.json");
  const auto summary = nlohmann::json::parse(in);
  EXPECT_TRUE(summary["all_converged"].get<bool>());
  EXPECT_EQ(summary["frame_solution"], "equilibrium");
  ASSERT_EQ(summary["frames"].size(), 3u);
  for (const auto& frame : summary["frames"]) {
    EXPECT_TRUE(frame["converged"].get<bool>());
    EXPECT_LT(frame["step_norm"].get<double>(), summary["tolerance"].get<double>());
    // Frames are equilibria: the frame's solve and its settling steps each end on a judged
    // final record, and the last one's step norm is the static residual.
    EXPECT_GE(frame["settle_steps"].get<int>(), 1);
    EXPECT_EQ(frame["step_norm_history"].size(), frame["iterations"].get<std::size_t>() + 1 +
                                                     frame["settle_steps"].get<std::size_t>());
    EXPECT_EQ(frame["static_residual"].get<double>(), frame["step_norm"].get<double>());
  }
  // Gravity pulls the sheet down: the elastic energy grows from zero.
  EXPECT_GT(summary["frames"][2]["elastic_energy"].get<double>(), 0.0);
  // One body without self-contact: no contact work at all.
  EXPECT_EQ(summary["frames"][2]["contact"]["max_active_pairs"].get<long>(), 0);
  EXPECT_EQ(summary["frames"][2]["contact"]["barrier_stiffness"].get<double>(), 0.0);
}

TEST(SimCommand, SummaryHasEachFramesLoadScaleAndProbes) {
  const auto dir = test::fresh_temp_dir("sim_probes");
  // The sag scene with a 1 mN downward load on its free edge, ramped over 3 frames of 0.05 s,
  // and probes: the loaded edge's mean displacement and what the pinned edge carries.
  const auto scene = test::write_file(
      dir / "sag.toml",
      small_scene(3) +
          "[[shell.load]]\nbox = { min = [0.09, -0.11, -0.01], max = [0.11, 0.11, 0.01] }\n"
          "force = [0, 0, -1e-3]\n"
          "[[shell.probe]]\nname = \"free_edge\"\n"
          "box = { min = [0.09, -0.11, -0.01], max = [0.11, 0.11, 0.01] }\n"
          "[[shell.probe]]\nname = \"held\"\npin = \"edge\"\n"
          "[load_scale]\nend = 0.15\n");
  const auto result = test::run_psq({"sim", scene.string(), "--out", (dir / "out").string()});
  ASSERT_EQ(result.exit_code, 0) << result.errors;
  std::ifstream in(dir / "out" / "summary.json");
  const auto summary = nlohmann::json::parse(in);
  ASSERT_EQ(summary["frames"].size(), 3u);
  const double weight = 200 * 1e-3 * 0.2 * 0.2 * 9.81;  // ρ h A g [N]
  for (int k = 0; k < 3; ++k) {
    const auto& frame = summary["frames"][k];
    SCOPED_TRACE(k + 1);
    const double scale = (k + 1) / 3.0;
    EXPECT_NEAR(frame["load_scale"].get<double>(), scale, 1e-12);
    ASSERT_EQ(frame["probes"].size(), 2u);
    EXPECT_EQ(frame["probes"][0]["name"], "free_edge");
    EXPECT_EQ(frame["probes"][0]["kind"], "displacement");
    EXPECT_LT(frame["probes"][0]["value"][2].get<double>(), 0.0);  // the edge sags
    const auto& held = frame["probes"][1];
    EXPECT_EQ(held["kind"], "reaction");
    // The pinned edge carries the weight and the ramped load, both along −z.
    const double carried = weight + scale * 1e-3;
    EXPECT_NEAR(held["value"][2].get<double>(), -carried, 1e-3 * carried);
    EXPECT_NEAR(held["magnitude"].get<double>(), carried, 1e-3 * carried);
  }
}

TEST(SimCommand, ContactScenesReportTheirContactAndFrictionPerFrame) {
  const auto dir = test::fresh_temp_dir("sim_contact");
  const auto result =
      test::run_psq({"sim", (test::source_dir() / "jobs/scenes/tilted_plane.toml").string(),
                     "--out", (dir / "out").string()});
  ASSERT_EQ(result.exit_code, 0) << result.errors;
  std::ifstream in(dir / "out" / "summary.json");
  const auto summary = nlohmann::json::parse(in);
  ASSERT_FALSE(summary["frames"].empty());
  for (const auto& frame : summary["frames"]) {
    // The patch rests on the slope in every frame, held there by friction.
    EXPECT_GT(frame["contact"]["max_active_pairs"].get<long>(), 0);
    EXPECT_GT(frame["contact"]["barrier_stiffness"].get<double>(), 0.0);
    EXPECT_GT(frame["contact"]["barrier_evaluations"].get<long>(), 0);
    // In contact throughout: nothing is ever certified clear.
    EXPECT_EQ(frame["contact"]["barrier_certified"].get<long>(), 0);
    EXPECT_EQ(frame["contact"]["ccd_certified"].get<long>(), 0);
    EXPECT_GE(frame["friction_iterations"].get<int>(), 2);
  }
}

TEST(SimCommand, LevelsRunsProgressivelyAndWritesEveryLevel) {
  const auto dir = test::fresh_temp_dir("sim_levels");
  std::string text = small_scene(2);  // finer, so that a coarser level has room
  text.replace(text.find("edge_length = 0.04"), 18, "edge_length = 0.02");
  const auto scene = test::write_file(dir / "sag.toml", text);
  const auto result =
      test::run_psq({"sim", scene.string(), "--out", (dir / "out").string(), "--levels", "2"});
  ASSERT_EQ(result.exit_code, 0) << result.errors;
  EXPECT_NE(result.errors.find("level 0/1 frame 1/2"), std::string::npos) << result.errors;
  EXPECT_NE(result.errors.find("level 1/1 frame 2/2 (settling)"), std::string::npos)
      << result.errors;
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "level_0.obj"));
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "level_1.obj"));
  std::ifstream in(dir / "out" / "summary.json");
  const auto summary = nlohmann::json::parse(in);
  EXPECT_TRUE(summary["all_converged"].get<bool>());
  EXPECT_EQ(summary["level_count"].get<int>(), 2);
  ASSERT_EQ(summary["levels"].size(), 2u);
  const auto& coarse = summary["levels"][0];
  const auto& fine = summary["levels"][1];
  EXPECT_LT(coarse["vertices"].get<int>(), fine["vertices"].get<int>());
  EXPECT_EQ(fine["vertices"].get<int>(), summary["vertices"].get<int>());
  for (const auto& level : summary["levels"]) {
    EXPECT_TRUE(level["converged"].get<bool>());
    EXPECT_GT(level["steps"].size(), 0u);
    EXPECT_GE(level["seconds"].get<double>(), 0.0);
    int iterations = 0;
    for (const auto& step : level["steps"]) iterations += step["iterations"].get<int>();
    EXPECT_EQ(level["iterations"].get<int>(), iterations);
  }
  // The coarse level previews frames 1 and 2 before settling; the finest level only settles.
  EXPECT_FALSE(coarse["steps"][0]["settling"].get<bool>());
  EXPECT_TRUE(fine["steps"][0]["settling"].get<bool>());
  EXPECT_EQ(summary["frames"].size(), fine["steps"].size());
}

TEST(SimCommand, CacheKeepsTheHierarchyForTheNextRunWhichEndsTheSame) {
  const auto dir = test::fresh_temp_dir("sim_cache");
  std::string text = small_scene(2);
  text.replace(text.find("edge_length = 0.04"), 18, "edge_length = 0.02");
  const auto scene = test::write_file(dir / "sag.toml", text);
  const auto cache = dir / "cache";
  const auto run = [&](const std::string& out) {
    return test::run_psq({"sim", scene.string(), "--out", (dir / out).string(), "--levels", "2",
                          "--cache", cache.string()});
  };
  const auto first = run("first");
  ASSERT_EQ(first.exit_code, 0) << first.errors;
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(cache))
    files.push_back(entry.path());
  ASSERT_EQ(files.size(), 1u);  // one shell, one hierarchy
  const auto written = std::filesystem::last_write_time(files[0]);
  const std::string stored = test::read_file(files[0]);

  const auto second = run("second");
  ASSERT_EQ(second.exit_code, 0) << second.errors;
  // Read, not rebuilt: the file is untouched, and the run is the first one again.
  EXPECT_EQ(std::filesystem::last_write_time(files[0]), written);
  EXPECT_EQ(test::read_file(files[0]), stored);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(cache),
                          std::filesystem::directory_iterator{}),
            1);
  EXPECT_EQ(test::read_file(dir / "second" / "frame_0002.obj"),
            test::read_file(dir / "first" / "frame_0002.obj"));
  std::ifstream in(dir / "second" / "summary.json");
  EXPECT_EQ(nlohmann::json::parse(in)["hierarchy_cache"].get<std::string>(),
            std::filesystem::absolute(cache).string());
}

TEST(SimCommand, LevelsBelowOneIsAnInputError) {
  const auto dir = test::fresh_temp_dir("sim_levels");
  const auto scene = test::write_file(dir / "sag.toml", small_scene(1));
  const auto result =
      test::run_psq({"sim", scene.string(), "--out", (dir / "out").string(), "--levels", "0"});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.errors.find("--levels must be at least 1"), std::string::npos) << result.errors;
}

TEST(SimCommand, BadSceneNamesFileLineAndKeyAndWritesNothing) {
  const auto dir = test::fresh_temp_dir("sim");
  std::string text = small_scene(2);
  text.replace(text.find("thickness"), 9, "thicknes");
  const auto scene = test::write_file(dir / "typo.toml", text);
  const auto result = test::run_psq({"sim", scene.string(), "--out", (dir / "out").string()});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.errors.find("typo.toml:"), std::string::npos) << result.errors;
  EXPECT_NE(result.errors.find("thickness"), std::string::npos) << result.errors;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(SimCommand, UnwritableOutputDirectoryIsAnInputError) {
  if (::geteuid() == 0) {
    // Root ignores permissions: use a path below a regular file instead.
    const auto dir = test::fresh_temp_dir("sim");
    const auto scene = test::write_file(dir / "sag.toml", small_scene(1));
    test::write_file(dir / "file", "x");
    const auto result =
        test::run_psq({"sim", scene.string(), "--out", (dir / "file" / "out").string()});
    EXPECT_EQ(result.exit_code, 1);
    EXPECT_NE(result.errors.find("output directory"), std::string::npos) << result.errors;
    return;
  }
  const auto dir = test::fresh_temp_dir("sim");
  const auto scene = test::write_file(dir / "sag.toml", small_scene(1));
  std::filesystem::create_directory(dir / "locked");
  ::chmod((dir / "locked").c_str(), 0500);
  const auto result = test::run_psq({"sim", scene.string(), "--out", (dir / "locked").string()});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.errors.find("not writable"), std::string::npos) << result.errors;
}

TEST(SimCommand, MissingSceneAndMissingArgumentsFail) {
  const auto missing = test::run_psq({"sim", "/nonexistent/scene.toml", "--out", "/tmp/x"});
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.errors.find("/nonexistent/scene.toml"), std::string::npos) << missing.errors;
  EXPECT_NE(test::run_psq({"sim"}).exit_code, 0);
}

TEST(SimCommand, TooFewIterationsIsReportedWithExitCodeThree) {
  const auto dir = test::fresh_temp_dir("sim");
  const auto scene =
      test::write_file(dir / "sag.toml", small_scene(1) + "[solver]\nmax_iterations = 1\n");
  const auto result = test::run_psq({"sim", scene.string(), "--out", (dir / "out").string()});
  EXPECT_EQ(result.exit_code, 3) << result.errors;
  std::ifstream in(dir / "out" / "summary.json");
  EXPECT_FALSE(nlohmann::json::parse(in)["all_converged"].get<bool>());
}

}  // namespace
}  // namespace psq

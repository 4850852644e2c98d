// `psq sim` end to end, as a user runs it: outputs, exit codes and messages.

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sys/stat.h>

#include "support/run_process.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

/// A small, fast scene: a 0.2 m sheet pinned along one edge, sagging under gravity.
std::string small_scene(int frames) {
  return "name = \"sag\"\ngravity = [0, 0, -9.81]\n[time]\nstep = 0.05\nframes = " + std::to_string(frames) +
         "\n[[shell]]\nname = \"sheet\"\n"
         "mesh = { generator = \"sheet\", width = 0.2, height = 0.2, edge_length = 0.04 }\n"
         "material = { youngs_modulus = 1e5, poisson_ratio = 0.3, density = 200, thickness = 1e-3 }\n"
         "[[shell.pin]]\nname = \"edge\"\nbox = { min = [-0.11, -0.11, -0.01], max = [-0.09, 0.11, 0.01] }\n";
}

TEST(SimCommand, WritesEveryFrameAndASummary) {
  const auto dir = test::fresh_temp_dir("sim");
  const auto scene = test::write_file(dir / "sag.toml", small_scene(3));
  const auto result = test::run_psq({"sim", scene.string(), "--out", (dir / "out").string()});
  ASSERT_EQ(result.exit_code, 0) << result.errors;
  for (int f = 0; f <= 3; ++f)
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / ("frame_000" + std::to_string(f) + ".obj"))) << f;
  EXPECT_NE(result.output.find("summary.json"), std::string::npos);
  std::ifstream in(dir / "out" / "summary.json");
  const auto summary = nlohmann::json::parse(in);
  EXPECT_TRUE(summary["all_converged"].get<bool>());
  ASSERT_EQ(summary["frames"].size(), 3u);
  for (const auto& frame : summary["frames"]) {
    EXPECT_TRUE(frame["converged"].get<bool>());
    EXPECT_LT(frame["step_norm"].get<double>(), summary["tolerance"].get<double>());
    EXPECT_EQ(frame["step_norm_history"].size(), frame["iterations"].get<std::size_t>() + 1);
  }
  // Gravity pulls the sheet down: the elastic energy grows from zero.
  EXPECT_GT(summary["frames"][2]["elastic_energy"].get<double>(), 0.0);
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
    const auto result = test::run_psq({"sim", scene.string(), "--out", (dir / "file" / "out").string()});
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
  const auto scene = test::write_file(dir / "sag.toml", small_scene(1) + "[solver]\nmax_iterations = 1\n");
  const auto result = test::run_psq({"sim", scene.string(), "--out", (dir / "out").string()});
  EXPECT_EQ(result.exit_code, 3) << result.errors;
  std::ifstream in(dir / "out" / "summary.json");
  EXPECT_FALSE(nlohmann::json::parse(in)["all_converged"].get<bool>());
}

}  // namespace
}  // namespace psq

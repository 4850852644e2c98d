// The [load_scale] table and [[shell.probe]]: s(t) of ramps and keyframes, what the reader takes
// from a scene, and the errors it gives for bad input.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <tuple>

#include "engine/core/error.hpp"
#include "engine/scene/load_scale.hpp"
#include "engine/scene/scene_reader.hpp"
#include "support/scene_error.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

namespace fs = std::filesystem;

TEST(LoadScale, TheDefaultIsOneAtEveryTime) {
  const LoadScale scale;
  for (double t : {-1.0, 0.0, 0.3, 100.0}) EXPECT_EQ(load_scale_at(scale, t), 1.0) << t;
}

TEST(LoadScale, KeyframesInterpolateLinearlyAndHoldBeyondTheEnds) {
  const LoadScale scale{{{1.0, 0.0}, {2.0, 4.0}, {4.0, -2.0}}};
  EXPECT_EQ(load_scale_at(scale, 0.0), 0.0);  // before the first: its value
  EXPECT_EQ(load_scale_at(scale, 1.0), 0.0);
  EXPECT_DOUBLE_EQ(load_scale_at(scale, 1.25), 1.0);  // a quarter of the way from 0 to 4
  EXPECT_EQ(load_scale_at(scale, 2.0), 4.0);
  EXPECT_DOUBLE_EQ(load_scale_at(scale, 3.5), 4.0 + 0.75 * (-6.0));
  EXPECT_EQ(load_scale_at(scale, 4.0), -2.0);
  EXPECT_EQ(load_scale_at(scale, 9.0), -2.0);  // after the last: its value
}

TEST(LoadScale, TwoKeyframesAtOneTimeJumpThere) {
  const LoadScale scale{{{0.0, 0.0}, {1.0, 0.5}, {1.0, 2.0}, {2.0, 2.0}}};
  EXPECT_DOUBLE_EQ(load_scale_at(scale, 0.5), 0.25);
  EXPECT_NEAR(load_scale_at(scale, 1.0 - 1e-12), 0.5, 1e-9);
  EXPECT_EQ(load_scale_at(scale, 1.0), 2.0);  // the later keyframe's from the jump's time on
  EXPECT_EQ(load_scale_at(scale, 1.5), 2.0);
}

constexpr const char* kShellLines = R"([[shell]]
name = "strip"
mesh = { generator = "sheet", width = 1, height = 0.2, edge_length = 0.05, structured = true }
material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 200, thickness = 1e-3 }
[[shell.pin]]
name = "clamp"
box = { min = [-0.6, -1, -1], max = [-0.45, 1, 1] }
)";  // lines 1..7

Scene scene_from(const std::string& name, const std::string& text) {
  const fs::path dir = test::fresh_temp_dir("load_scale_" + name);
  return read_scene(test::write_file(dir / "scene.toml", text));
}

TEST(ReadLoadScale, ARampIsTheKeyframesFromZeroAtStartToOneAtEnd) {
  const Scene scene = scene_from("ramp", "[load_scale]\nstart = 0.5\nend = 2\n" +
                                             std::string(kShellLines));
  const std::vector<std::pair<double, double>> expected{{0.5, 0.0}, {2.0, 1.0}};
  EXPECT_EQ(scene.load_scale.keyframes, expected);
  EXPECT_DOUBLE_EQ(load_scale_at(scene.load_scale, 1.25), 0.5);
}

TEST(ReadLoadScale, ARampDefaultsToThePinMotionTimes) {
  const Scene scene = scene_from("ramp_defaults", "[load_scale]\n" + std::string(kShellLines));
  const std::vector<std::pair<double, double>> expected{{0.0, 0.0}, {1.0, 1.0}};
  EXPECT_EQ(scene.load_scale.keyframes, expected);
}

TEST(ReadLoadScale, ReadsKeyframesAsWritten) {
  const Scene scene = scene_from(
      "keyframes", "[load_scale]\nkeyframes = [[0, 0], [1, 2.5], [1, 3], [2, -1]]\n" +
                       std::string(kShellLines));
  const std::vector<std::pair<double, double>> expected{
      {0.0, 0.0}, {1.0, 2.5}, {1.0, 3.0}, {2.0, -1.0}};
  EXPECT_EQ(scene.load_scale.keyframes, expected);
}

TEST(ReadLoadScale, WithoutTheTableEveryLoadHasItsFullForce) {
  const Scene scene = scene_from("none", kShellLines);
  EXPECT_EQ(load_scale_at(scene.load_scale, 0.0), 1.0);
}

TEST(ReadProbes, ReadsDisplacementAndReactionProbes) {
  const Scene scene = scene_from("probes", std::string(kShellLines) + R"(
[[shell.probe]]
name = "tip"
box = { min = [0.45, -1, -1], max = [0.6, 1, 1] }
[[shell.probe]]
name = "clamp_force"
pin = "clamp"
)");
  const std::vector<Probe>& probes = scene.shells.at(0).probes;
  ASSERT_EQ(probes.size(), 2u);
  EXPECT_EQ(probes[0].name, "tip");
  EXPECT_EQ(probes[0].kind, ProbeKind::displacement);
  EXPECT_EQ(probes[0].selector.kind, VertexSelector::Kind::Box);
  EXPECT_EQ(probes[0].selector.source_line, 11);  // the box, after a blank line 8
  EXPECT_EQ(probes[1].name, "clamp_force");
  EXPECT_EQ(probes[1].kind, ProbeKind::reaction);
  EXPECT_EQ(probes[1].pin, "clamp");
}

TEST(ReadLoadScaleAndProbes, BadEntriesNameTheirFileLineAndKey) {
  const fs::path dir = test::fresh_temp_dir("bad_load_scale");
  // Texts starting with [load_scale] go before the shell (their first line is line 1); the
  // others after it (line 8).
  const std::vector<std::tuple<std::string, int, std::string>> cases = {
      {"[load_scale]\nstart = 1\nend = 0.5", 3, "'end' in [load_scale] must be at least start"},
      {"[load_scale]\nkeyframes = [[0, 0], [1]]", 2,
       "expected an array of 2 numbers for 'keyframes' in [load_scale]"},
      {"[load_scale]\nkeyframes = [[0, 0], [1, \"a\"]]", 2,
       "expected an array of 2 numbers for 'keyframes'"},
      {"[load_scale]\nkeyframes = 3", 2, "expected an array of [a, b] pairs of numbers"},
      {"[load_scale]\nkeyframes = []", 2, "'keyframes' in [load_scale] must be a non-empty"},
      {"[load_scale]\nkeyframes = [[1, 0], [0.5, 1]]", 2,
       "'keyframes' in [load_scale] must be in time order (0.5 follows 1)"},
      {"[load_scale]\nkeyframes = [[0, 0], [1, 1]]\nend = 2", 3,
       "'end' and 'keyframes' in [load_scale] exclude each other"},
      {"[load_scale]\nramp = 1", 2, "unknown key 'ramp' in [load_scale]"},
      {"[[shell.probe]]\nname = \"tip\"", 8, "missing a vertex selector in [shell.probe]"},
      {"[[shell.probe]]\nvertices = [0]", 8, "missing required key 'name' in [shell.probe]"},
      {"[[shell.probe]]\nname = \"f\"\npin = \"clmp\"", 10,
       "unknown pin 'clmp' in [shell.probe]; did you mean 'clamp'?"},
      {"[[shell.probe]]\nname = \"f\"\npin = \"clamp\"\nvertices = [0]", 11,
       "'vertices' and 'pin' in [shell.probe] exclude each other"},
      {"[[shell.probe]]\nname = \"a\"\nvertices = [0]\n[[shell.probe]]\nname = \"a\"\npin = "
       "\"clamp\"",
       12, "probe name 'a' is used twice"},
      {"[[shell.probe]]\nname = \"a\"\nvertices = [0]\nscale = 2", 11,
       "unknown key 'scale' in [shell.probe]"},
  };
  int index = 0;
  for (const auto& [text, line, fragment] : cases) {
    const bool before = text.starts_with("[load_scale]");
    test::expect_scene_error(dir / fmt::format("case{}.toml", index++),
                             before ? text + "\n" + kShellLines : kShellLines + text + "\n", line,
                             fragment);
  }
}

}  // namespace
}  // namespace psq

// Sweep files: expansion of grids and zipped lists, canonical job ids, and every kind of bad
// input reported at its line.

#include <algorithm>
#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <set>

#include "engine/core/error.hpp"
#include "engine/scene/scene_reader.hpp"
#include "jobs/scene_overrides.hpp"
#include "jobs/sweep_file.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

using jobs::read_sweep;

/// A directory holding a copy of the cantilever scene as scene.toml, for sweep files to use.
std::filesystem::path sweep_dir() {
  const auto dir = test::fresh_temp_dir("sweep_file");
  std::filesystem::copy_file(test::source_dir() / "jobs/scenes/cantilever.toml",
                             dir / "scene.toml");
  return dir;
}

std::filesystem::path write_sweep(const std::filesystem::path& dir, const std::string& body,
                                  const std::string& name = "sweep.toml") {
  return test::write_file(dir / name, "name = \"s\"\nscene = \"scene.toml\"\n" + body);
}

/// The message of the InputError that reading `file` throws (empty if none).
std::string error_of(const std::filesystem::path& file) {
  try {
    read_sweep(file);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

const std::string kE = "shell.strip.material.youngs_modulus";
const std::string kH = "shell.strip.material.thickness";
const std::string kNu = "shell.strip.material.poisson_ratio";

TEST(SweepFile, GridIsTheCartesianProductLastAxisFastest) {
  const auto dir = sweep_dir();
  const auto sweep = read_sweep(write_sweep(dir, "[grid]\n\"" + kE + "\" = [1e6, 2e6]\n\"" + kH +
                                                     "\" = [1e-3, 2e-3, 3e-3]\n\"time.frames\" = [4, 5]\n"));
  ASSERT_EQ(sweep.jobs.size(), 12u);  // 2 × 3 × 2
  EXPECT_EQ(sweep.scene, dir / "scene.toml");
  // Axes sorted by path: thickness, E, time.frames; time.frames varies fastest.
  EXPECT_EQ(sweep.jobs[0].overrides.at(kH), 1e-3);
  EXPECT_EQ(sweep.jobs[0].overrides.at(kE), 1e6);
  EXPECT_EQ(sweep.jobs[0].overrides.at("time.frames"), 4);
  EXPECT_EQ(sweep.jobs[1].overrides.at("time.frames"), 5);
  EXPECT_EQ(sweep.jobs[2].overrides.at(kE), 2e6);
  EXPECT_EQ(sweep.jobs[4].overrides.at(kH), 2e-3);
  EXPECT_EQ(sweep.jobs[11].overrides.at(kH), 3e-3);
  EXPECT_EQ(sweep.jobs[11].overrides.at(kE), 2e6);
  EXPECT_EQ(sweep.jobs[11].overrides.at("time.frames"), 5);
  std::set<std::string> ids;
  for (const auto& job : sweep.jobs) {
    ids.insert(job.id);
    EXPECT_EQ(job.depth, 1);
    EXPECT_EQ(job.id.size(), 16u);
  }
  EXPECT_EQ(ids.size(), 12u);
}

TEST(SweepFile, ZipVariesListsTogetherAndCombinesWithTheGrid) {
  const auto dir = sweep_dir();
  const auto sweep = read_sweep(write_sweep(
      dir, "depth = 2\n[grid]\n\"" + kH + "\" = [1e-3, 2e-3]\n[[zip]]\n\"" + kE +
               "\" = [1e6, 2e6, 3e6]\n\"" + kNu + "\" = [0.1, 0.2, 0.3]\n[[zip]]\n"
               "\"solver.tolerance\" = [1e-5]\n\"solver.max_iterations\" = [50]\n"));
  ASSERT_EQ(sweep.jobs.size(), 6u);  // 2 thicknesses × 3 zipped materials × 1
  for (const auto& job : sweep.jobs) {
    // Zipped: E = ν·1e7 in every job, never a cross combination.
    EXPECT_DOUBLE_EQ(job.overrides.at(kE).get<double>(), job.overrides.at(kNu).get<double>() * 1e7);
    EXPECT_EQ(job.overrides.at("solver.max_iterations"), 50);
    EXPECT_EQ(job.depth, 2);
    EXPECT_EQ(job.parameters.at("depth"), 2);
  }
  // Axes: the grid's thickness, then the two zip groups.
  EXPECT_EQ(sweep.jobs[0].overrides.at(kE), 1e6);
  EXPECT_EQ(sweep.jobs[1].overrides.at(kE), 2e6);
  EXPECT_EQ(sweep.jobs[3].overrides.at(kH), 2e-3);
}

TEST(SweepFile, NoVariationIsOneJobOfTheBaseScene) {
  const auto sweep = read_sweep(write_sweep(sweep_dir(), ""));
  ASSERT_EQ(sweep.jobs.size(), 1u);
  EXPECT_TRUE(sweep.jobs[0].overrides.empty());
}

TEST(SweepFile, DepthCanBeVaried) {
  const auto sweep = read_sweep(write_sweep(sweep_dir(), "[grid]\ndepth = [1, 2, 3]\n"));
  ASSERT_EQ(sweep.jobs.size(), 3u);
  EXPECT_EQ(sweep.jobs[2].depth, 3);
  EXPECT_TRUE(sweep.jobs[2].overrides.empty());
}

TEST(SweepFile, IdsAreStableUnderKeyOrderSyntaxAndNumberFormatting) {
  const auto dir = sweep_dir();
  const auto quoted = read_sweep(write_sweep(
      dir, "[grid]\n\"time.frames\" = [4]\n\"" + kE + "\" = [500000, 1e6]\n", "a.toml"));
  // Dotted (nested) keys, other order, other spelling of the same numbers, comments.
  const auto dotted = read_sweep(write_sweep(
      dir, "# comment\n[grid]\nshell.strip.material.youngs_modulus = [5e5, 1_000_000.0]\n"
           "time.frames = [ 4 ]   # frames\n",
      "b.toml"));
  ASSERT_EQ(quoted.jobs.size(), 2u);
  ASSERT_EQ(dotted.jobs.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(quoted.jobs[i].id, dotted.jobs[i].id);
    EXPECT_EQ(quoted.jobs[i].parameters.dump(), dotted.jobs[i].parameters.dump());
  }
  // The canonical text, written out by hand: keys sorted, reals as doubles.
  EXPECT_EQ(quoted.jobs[0].parameters.dump(),
            "{\"depth\":1,\"overrides\":{\"" + kE + "\":500000.0,\"time.frames\":4},\"scene\":\"" +
                quoted.scene_hash + "\"}");
  // The id does not depend on the sweep's name or the scene's path, only its content.
  EXPECT_EQ(quoted.jobs[0].id, jobs::job_id(quoted.jobs[0].parameters));
}

TEST(SweepFile, JobIdIsFnv1aOfTheCanonicalText) {
  // The canonical text of the JSON number 1 is "1"; FNV-1a 64 of "1" is the published
  // test vector 0xaf63ac4c86019afc.
  EXPECT_EQ(jobs::job_id(nlohmann::json::parse("1")), "af63ac4c86019afc");  // fnv1a64("1")
}

TEST(SweepFile, EditingTheSceneChangesEveryId) {
  const auto dir = sweep_dir();
  const auto file = write_sweep(dir, "[grid]\n\"time.frames\" = [4, 5]\n");
  const auto before = read_sweep(file);
  std::ofstream(dir / "scene.toml", std::ios::app) << "# edited\n";
  const auto after = read_sweep(file);
  EXPECT_NE(before.scene_hash, after.scene_hash);
  EXPECT_NE(before.jobs[0].id, after.jobs[0].id);
}

TEST(SceneOverrides, ApplyingSetsTheScenesValues) {
  const Scene base = read_scene(test::source_dir() / "jobs/scenes/cantilever.toml");
  const Scene scene = jobs::apply_overrides(
      base, {{kH, 2e-3}, {kNu, 0.4}, {"time.frames", 7}, {"solver.tolerance", 1e-6},
             {"time.step", 0.5}, {"solver.max_iterations", 9}, {kE, 3e9},
             {"shell.strip.material.density", 10}, {"contact.friction", 0.4}});
  EXPECT_EQ(scene.shells[0].material.thickness, 2e-3);
  EXPECT_EQ(scene.contact.friction, 0.4);
  EXPECT_EQ(scene.shells[0].material.poisson_ratio, 0.4);
  EXPECT_EQ(scene.shells[0].material.youngs_modulus, 3e9);
  EXPECT_EQ(scene.shells[0].material.density, 10.0);
  EXPECT_EQ(scene.time.frames, 7);
  EXPECT_EQ(scene.time.step, 0.5);
  EXPECT_EQ(scene.solver.tolerance, 1e-6);
  EXPECT_EQ(scene.solver.max_iterations, 9);
  EXPECT_EQ(base.shells[0].material.thickness, 1e-3);  // the base is a copy
}

TEST(SceneOverrides, ImpossibleValuesAndUnknownPathsThrowNamingThePath) {
  const Scene base = read_scene(test::source_dir() / "jobs/scenes/cantilever.toml");
  auto error = [&](const std::string& path, const nlohmann::json& value) -> std::string {
    try {
      jobs::apply_overrides(base, {{path, value}});
    } catch (const jobs::OverrideError& e) {
      EXPECT_EQ(e.path(), path);
      return e.what();
    }
    return "";
  };
  EXPECT_NE(error(kH, -1e-3).find("must be positive (got -0.001)"), std::string::npos);
  EXPECT_NE(error(kNu, 0.5).find("in (-1, 0.5)"), std::string::npos);
  EXPECT_NE(error("contact.friction", -0.1).find("must be at least 0 (got -0.1)"),
            std::string::npos);
  EXPECT_NE(error("time.frames", 2.5).find("an integer"), std::string::npos);
  EXPECT_NE(error("time.frames", 0).find("at least 1"), std::string::npos);
  EXPECT_NE(error(kE, "stiff").find("a number"), std::string::npos);
  EXPECT_NE(error(kE, std::numeric_limits<double>::infinity()).find("finite"), std::string::npos);
  EXPECT_NE(error("shell.strip.material.thicknes", 1).find("did you mean '" + kH + "'"),
            std::string::npos);
  EXPECT_NE(error("shell.cloth.material.thickness", 1).find("unknown parameter"), std::string::npos);
}

struct BadSweep {
  std::string body;
  std::string expected;  ///< a part of the message, after "sweep.toml:<line>: "
  long line;
};

class BadSweepFile : public ::testing::TestWithParam<BadSweep> {};

TEST_P(BadSweepFile, IsRefusedAtItsLine) {
  const auto file = write_sweep(sweep_dir(), GetParam().body);
  const std::string message = error_of(file);
  const long line = GetParam().line;  // 0: the whole file
  const std::string location = file.string() + (line ? ":" + std::to_string(line) : "") + ": ";
  EXPECT_EQ(message.rfind(location, 0), 0u) << message;
  EXPECT_NE(message.find(GetParam().expected), std::string::npos) << message;
}

// Lines: 1 name, 2 scene, 3 onwards the body.
INSTANTIATE_TEST_SUITE_P(
    Cases, BadSweepFile,
    ::testing::Values(
        BadSweep{"[grid]\n\"" + kH + "\" = [1e-3, -1e-3]\n",
                 "job depth=1 " + kH + "=-0.001: parameter '" + kH + "' must be positive", 4},
        BadSweep{"[grid]\n\"" + kNu + "\" = [\n  0.3,\n  0.5,\n]\n", "in (-1, 0.5) (got 0.5)", 6},
        BadSweep{"[grid]\ndepth = [1, 0]\n", "job depth=0: 'depth' must be an integer", 4},
        BadSweep{"depth = 0\n", "'depth' must be an integer in [1, 64] (got 0)", 3},
        BadSweep{"[grid]\n\"shell.strip.material.thicknes\" = [1e-3]\n", "did you mean '" + kH, 4},
        BadSweep{"[grid]\n\"gravity.z\" = [1]\n", "valid parameters: time.step", 4},
        BadSweep{"[grid]\n\"" + kH + "\" = []\n", "must be a non-empty list", 4},
        BadSweep{"[grid]\n\"" + kH + "\" = 1e-3\n", "must be a non-empty list", 4},
        BadSweep{"[grid]\n\"" + kH + "\" = [[1e-3]]\n", "must list numbers", 4},
        BadSweep{"[[zip]]\n\"" + kH + "\" = [1e-3, 2e-3]\n\"" + kE + "\" = [1e6]\n",
                 "must have equal lengths", 3},
        BadSweep{"[grid]\n\"" + kH + "\" = [1e-3]\n[[zip]]\n\"" + kH + "\" = [2e-3]\n",
                 "varied twice", 6},
        BadSweep{"[grid]\n\"" + kE + "\" = [5e5, 500000]\n", "have the same parameters", 0},
        BadSweep{"depth = 1\n[grid]\ndepth = [2]\n", "given at the top level and varied", 3},
        BadSweep{"grids = 1\n", "did you mean 'grid'", 3},
        BadSweep{"[grid\n", "TOML syntax error", 3}));

TEST(SweepFile, MissingSceneAndMissingNameAreRefused) {
  const auto dir = sweep_dir();
  const auto no_scene = test::write_file(dir / "a.toml", "name = \"s\"\nscene = \"nope.toml\"\n");
  EXPECT_NE(error_of(no_scene).find(no_scene.string() + ":2: scene file"), std::string::npos);
  const auto no_name = test::write_file(dir / "b.toml", "scene = \"scene.toml\"\n");
  EXPECT_NE(error_of(no_name).find("missing 'name'"), std::string::npos);
  EXPECT_NE(error_of(dir / "absent.toml").find("no such sweep file"), std::string::npos);
}

TEST(SweepFile, SceneFileNameTooLongIsAnInputErrorAtItsLine) {
  const auto dir = sweep_dir();
  const auto file = test::write_file(
      dir / "long.toml", "name = \"s\"\nscene = \"" + std::string(300, 'a') + ".toml\"\n");
  EXPECT_NE(error_of(file).find(file.string() + ":2: scene file"), std::string::npos)
      << error_of(file);
  EXPECT_NE(error_of(file).find("too long"), std::string::npos) << error_of(file);
}

TEST(SweepFile, MoreThanTenThousandJobsAreRefusedBeforeExpansion) {
  const auto dir = sweep_dir();
  auto list = [](int count) {
    std::string text = "[1";
    for (int i = 2; i <= count; ++i) text += ", " + std::to_string(i);
    return text + "]";
  };
  // 400 × 300 × 64 = 7 680 000 jobs: refused at once, not after expanding them.
  const auto file = write_sweep(dir, "[grid]\n\"time.frames\" = " + list(400) +
                                         "\n\"solver.max_iterations\" = " + list(300) +
                                         "\ndepth = " + list(64) + "\n");
  EXPECT_NE(error_of(file).find("expands to 7680000 jobs, more than the 10000"),
            std::string::npos)
      << error_of(file);
  EXPECT_EQ(read_sweep(write_sweep(dir, "[grid]\n\"time.frames\" = " + list(100) +
                                            "\n\"solver.max_iterations\" = " + list(100) + "\n"))
                .jobs.size(),
            10'000u);
}

TEST(SweepFile, AnInvalidSceneIsReportedInTheSceneFile) {
  const auto dir = sweep_dir();
  test::write_file(dir / "scene.toml", "name = \"x\"\n[time]\nstep = -1\n[[shell]]\n");
  const auto file = write_sweep(dir, "");
  EXPECT_NE(error_of(file).find((dir / "scene.toml").string() + ":"), std::string::npos)
      << error_of(file);
}

TEST(SweepFile, TheDemoSweepExpandsToEightValidJobsAtTwoDepths) {
  const auto sweep = read_sweep(test::source_dir() / "jobs/sweeps/demo.toml");
  EXPECT_EQ(sweep.name, "demo");
  ASSERT_EQ(sweep.jobs.size(), 8u);
  EXPECT_EQ(std::count_if(sweep.jobs.begin(), sweep.jobs.end(),
                          [](const auto& job) { return job.depth == 2; }),
            4);
  EXPECT_EQ(jobs::new_jobs(sweep).front().scene,
            (test::source_dir() / "jobs/scenes/demo_strip.toml").lexically_normal().string());
}

TEST(SweepFile, TextIsReadAsIfItWereTheNamedFile) {
  const auto dir = sweep_dir();
  const std::string body = "[grid]\n\"" + kH + "\" = [1e-3, 2e-3]\n";
  const auto from_file = read_sweep(write_sweep(dir, body));
  const auto from_text = jobs::read_sweep_text(
      "name = \"s\"\nscene = \"scene.toml\"\n" + body, dir / "unwritten.toml");
  EXPECT_EQ(from_text.file, dir / "unwritten.toml");
  EXPECT_EQ(from_text.scene, from_file.scene);
  ASSERT_EQ(from_text.jobs.size(), 2u);
  EXPECT_EQ(from_text.jobs[1].id, from_file.jobs[1].id);
  try {
    jobs::read_sweep_text("name = 1\n", dir / "unwritten.toml");
    ADD_FAILURE() << "a bad name was accepted";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find((dir / "unwritten.toml").string() + ":1:"),
              std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace psq

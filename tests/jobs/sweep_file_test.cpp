// Sweep files: expansion of grids and zipped lists, canonical job ids, and every kind of bad
// input reported at its line.

#include "jobs/sweep_file.hpp"

#include <gtest/gtest.h>
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <limits>
#include <set>

#include "engine/core/error.hpp"
#include "engine/scene/scene_reader.hpp"
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

TEST(SweepFile, MethodsAreAnAxisWithDepthAndADirectJobIsListedOnce) {
  const auto dir = sweep_dir();
  const auto sweep = read_sweep(write_sweep(
      dir, "[grid]\ndepth = [2, 3]\nmethod = [\"direct\", \"progressive\", \"coarse_prolonged\"]\n"));
  // depth 2: direct, progressive, coarse; depth 3: (direct again, the same job), progressive,
  // coarse.
  ASSERT_EQ(sweep.jobs.size(), 5u);
  const std::vector<std::pair<db::Method, int>> expected{{db::Method::direct, 1},
                                                         {db::Method::progressive, 2},
                                                         {db::Method::coarse_prolonged, 2},
                                                         {db::Method::progressive, 3},
                                                         {db::Method::coarse_prolonged, 3}};
  for (std::size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(sweep.jobs[k].method, expected[k].first) << k;
    EXPECT_EQ(sweep.jobs[k].depth, expected[k].second) << k;
  }
  // Direct and progressive jobs keep the ids the same depths had before methods existed.
  const auto by_depth = read_sweep(write_sweep(dir, "[grid]\ndepth = [1, 2, 3]\n"));
  EXPECT_EQ(sweep.jobs[0].id, by_depth.jobs[0].id);
  EXPECT_EQ(sweep.jobs[1].id, by_depth.jobs[1].id);
  EXPECT_EQ(sweep.jobs[3].id, by_depth.jobs[2].id);
  EXPECT_FALSE(sweep.jobs[1].parameters.contains("method"));
  // A coarse-prolonged job is another job than the progressive one of its depth, and solves one
  // level.
  EXPECT_EQ(sweep.jobs[2].parameters.at("method"), "coarse_prolonged");
  EXPECT_NE(sweep.jobs[2].id, sweep.jobs[1].id);
  const std::vector<db::NewJob> stored = new_jobs(sweep);
  EXPECT_EQ(stored[2].depth, 1);
  EXPECT_EQ(stored[2].method, db::Method::coarse_prolonged);
  EXPECT_EQ(stored[3].depth, 3);
  EXPECT_EQ(describe_parameters(sweep.jobs[4]), "depth=3 method=coarse_prolonged");
}

TEST(SweepFile, TheMethodsSweepComparesFourMethodsAtTwoDepthsInSixJobs) {
  const auto sweep = read_sweep(test::source_dir() / "jobs/sweeps/methods.toml");
  std::vector<std::string> methods;  // each job's description up to its overrides
  for (const auto& job : sweep.jobs) {
    const std::string text = describe_parameters(job);
    methods.push_back(text.substr(0, text.find(" shell.")));
  }
  EXPECT_EQ(methods, (std::vector<std::string>{
                         "depth=1 method=direct", "depth=1 method=direct_final",
                         "depth=2 method=progressive", "depth=2 method=coarse_prolonged",
                         "depth=3 method=progressive", "depth=3 method=coarse_prolonged"}));
}

TEST(SweepFile, ATopLevelMethodAppliesToEveryJob) {
  const auto sweep = read_sweep(write_sweep(
      sweep_dir(), "method = \"coarse_prolonged\"\ndepth = 3\n[grid]\n\"" + kH + "\" = [1e-3, 2e-3]\n"));
  ASSERT_EQ(sweep.jobs.size(), 2u);
  for (const auto& job : sweep.jobs) {
    EXPECT_EQ(job.method, db::Method::coarse_prolonged);
    EXPECT_EQ(job.parameters.at("depth"), 3);
  }
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

/// FNV-1a 64 of `text`, written here apart from the program's (engine/core/checksum).
std::uint64_t fnv1a64(std::string_view text) {
  std::uint64_t hash = 0xcbf29ce484222325ull;
  for (const unsigned char c : text) hash = (hash ^ c) * 0x100000001b3ull;
  return hash;
}

std::string hex16(std::uint64_t value) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(value));
  return text;
}

TEST(SweepFile, JobIdsOfTheFormerParameterPathsArePinned) {
  // Stores made before any number became a path hold these ids: the overrides of the former
  // fixed paths must keep their canonical text. The scene is fixed here so that its hash is.
  const std::string scene =
      "[time]\nstep = 0.04\nframes = 10\n\n[[shell]]\nname = \"strip\"\n"
      "mesh = { generator = \"sheet\", width = 0.2, height = 0.02, edge_length = 0.005 }\n"
      "material = { youngs_modulus = 2e9, poisson_ratio = 0.3, density = 1200, thickness = 1e-3 "
      "}\n";
  const auto dir = test::fresh_temp_dir("sweep_pinned_id");
  test::write_file(dir / "scene.toml", scene);
  const auto sweep = read_sweep(
      write_sweep(dir, "[grid]\n\"" + kH + "\" = [5e-4]\n\"" + kE +
                           "\" = [500000]\n\"time.frames\" = [4]\n\"solver.tolerance\" = [1e-6]\n"
                           "\"contact.friction\" = [0]\ndepth = [2]\n"));
  ASSERT_EQ(sweep.jobs.size(), 1u);
  const std::string scene_hash = "fnv1a64:" + hex16(fnv1a64(scene));
  EXPECT_EQ(scene_hash, "fnv1a64:b489debf6fda4bbd");  // computed apart, with Python
  const std::string canonical =
      "{\"depth\":2,\"overrides\":{\"contact.friction\":0.0,\"" + kH + "\":0.0005,\"" + kE +
      "\":500000.0,\"solver.tolerance\":1e-06,\"time.frames\":4},\"scene\":\"" + scene_hash + "\"}";
  EXPECT_EQ(sweep.jobs[0].parameters.dump(), canonical);
  EXPECT_EQ(sweep.jobs[0].id, hex16(fnv1a64(canonical)));
  EXPECT_EQ(sweep.jobs[0].id, "d31cdd96247f0bc9");  // computed apart, with Python
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
                 "job depth=1 " + kH + "=-0.001: parameter '" + kH + "': ", 4},
        BadSweep{"[grid]\n\"" + kH + "\" = [1e-3, -1e-3]\n",
                 "scene.toml: 'thickness' in [shell.material] must be positive (got -0.001)", 4},
        BadSweep{"[grid]\n\"" + kNu + "\" = [\n  0.3,\n  0.5,\n]\n", "in (-1, 0.5) (got 0.5)", 6},
        BadSweep{"[grid]\ndepth = [1, 0]\n", "job depth=0: 'depth' must be an integer", 4},
        BadSweep{"depth = 0\n", "'depth' must be an integer in [1, 64] (got 0)", 3},
        BadSweep{"[grid]\n\"shell.strip.material.thicknes\" = [1e-3]\n", "did you mean '" + kH, 4},
        BadSweep{"[grid]\n\"gravity.z\" = [1]\n", "unknown parameter 'gravity.z'", 4},
        BadSweep{"[grid]\nshell.strip.mesh.edge_lenght = [1e-3]\n",
                 "did you mean 'shell.strip.mesh.edge_length'?", 4},
        BadSweep{"[grid]\n\"shell.strip.bending\" = [1]\n", "is a string in the scene", 4},
        BadSweep{"[grid]\nhierarchy.levels = [1, 2]\n", "vary 'depth' instead", 4},
        BadSweep{"[grid]\n\"" + kH + "\" = [\"thick\"]\n", "must be a number", 4},
        BadSweep{"[grid]\n\"shell.strip.mesh.edge_length\" = [0.005,\n  0.05]\n",
                 "job depth=1 shell.strip.mesh.edge_length=0.05: parameter "
                 "'shell.strip.mesh.edge_length': ",
                 5},
        BadSweep{"[[zip]]\nshell.strip.mesh.edge_length = [0.005, 0.015]\n"
                 "shell.strip.mesh.height = [0.02, 0.01]\n",
                 "parameters 'shell.strip.mesh.edge_length', 'shell.strip.mesh.height' together",
                 4},
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
        BadSweep{"[grid]\nmethod = [\"direct\",\n  \"progresive\"]\n",
                 "job depth=1 method=\"progresive\": 'method' must name a method, did you mean "
                 "\"progressive\"? (got \"progresive\"); valid methods: direct, direct_final, "
                 "progressive, coarse_prolonged",
                 5},
        BadSweep{"method = 2\n", "'method' must name a method (got 2); valid methods: direct", 3},
        BadSweep{"depth = 2\nmethod = \"Direct\"\n",
                 "'method' must name a method, did you mean \"direct\"? (got \"Direct\"); valid "
                 "methods: direct, direct_final, progressive, coarse_prolonged",
                 4},
        BadSweep{"method = \"progressive\"\n",
                 "method \"progressive\" solves a hierarchy, which needs 'depth' 2 or more (got 1)",
                 3},
        BadSweep{"[grid]\ndepth = [1]\nmethod = [\"coarse_prolonged\"]\n",
                 "method \"coarse_prolonged\" solves a hierarchy", 5},
        BadSweep{"method = \"direct\"\n[grid]\nmethod = [\"direct\"]\n",
                 "'method' is given at the top level and varied", 3},
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

TEST(SweepFile, TheDemoSweepIsACoarseFirstContactSweepOfNineJobs) {
  const auto sweep = read_sweep(test::source_dir() / "jobs/sweeps/demo.toml");
  EXPECT_EQ(sweep.name, "demo");
  ASSERT_EQ(sweep.jobs.size(), 9u);
  EXPECT_TRUE(std::all_of(sweep.jobs.begin(), sweep.jobs.end(),
                          [](const auto& job) { return job.depth == 3; }));
  EXPECT_EQ(sweep.refine.kind, db::RefineKind::top);
  EXPECT_EQ(sweep.refine.preview_levels(3), 2);
  const auto jobs = jobs::new_jobs(sweep);
  EXPECT_EQ(jobs.front().scene,
            (test::source_dir() / "jobs/scenes/drape_sphere.toml").lexically_normal().string());
  // The scene it sweeps has contact (a collider): the demo shows what the progressive solver is
  // for.
  EXPECT_FALSE(read_scene(jobs.front().scene).colliders.empty());
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

// ---- refine: coarse-first sweeps ------------------------------------------------------------

TEST(SweepFileRefine, RulesAreReadAndJobsGetTheirPreviewLevels) {
  const auto dir = sweep_dir();
  const auto top = read_sweep(write_sweep(
      dir, "depth = 3\nrefine = { rule = \"top\", by = \"max_displacement\", count = 2, "
           "order = \"smallest\" }\n[grid]\n\"" + kH + "\" = [1e-3, 2e-3]\n"));
  EXPECT_EQ(top.refine.kind, db::RefineKind::top);
  EXPECT_EQ(top.refine.by, "max_displacement");
  EXPECT_EQ(top.refine.count, 2);
  EXPECT_EQ(top.refine.preference, db::Preference::smallest);
  for (const db::NewJob& job : jobs::new_jobs(top)) EXPECT_EQ(job.preview_levels, 2);

  const auto pareto = read_sweep(write_sweep(
      dir, "depth = 4\n[refine]\nrule = \"pareto\"\npreview = 1\nminimize = "
           "[\"elastic_energy\"]\nmaximize = [\"max_displacement\"]\n"));
  ASSERT_EQ(pareto.refine.objectives.size(), 2u);
  EXPECT_EQ(pareto.refine.objectives[1].preference, db::Preference::largest);
  EXPECT_EQ(jobs::new_jobs(pareto).front().preview_levels, 1);

  const auto threshold = read_sweep(write_sweep(
      dir, "depth = 2\nrefine = { rule = \"threshold\", by = \"elastic_energy\", above = 1, "
           "below = 2.5 }\n"));
  EXPECT_EQ(threshold.refine.conditions.size(), 2u);
  const auto changed = read_sweep(write_sweep(
      dir, "depth = 3\nrefine = { rule = \"changed\", by = \"max_displacement\", above = 0.05 }\n"));
  EXPECT_EQ(changed.refine.change_above, 0.05);
  const auto none = read_sweep(write_sweep(dir, "depth = 2\nrefine = \"none\"\n"));
  EXPECT_EQ(none.refine.kind, db::RefineKind::none);
  EXPECT_EQ(jobs::new_jobs(none).front().preview_levels, 1);
}

TEST(SweepFileRefine, TheRuleIsNotPartOfAJobsIdentity) {
  const auto dir = sweep_dir();
  const std::string grid = "depth = 3\n[grid]\n\"" + kH + "\" = [1e-3, 2e-3]\n";
  const auto all = read_sweep(write_sweep(dir, "refine = \"all\"\n" + grid, "a.toml"));
  const auto plain = read_sweep(write_sweep(dir, grid, "p.toml"));
  const auto coarse = read_sweep(write_sweep(
      dir, "refine = { rule = \"top\", by = \"seconds\", count = 1 }\n" + grid, "c.toml"));
  for (std::size_t i = 0; i < plain.jobs.size(); ++i) {
    EXPECT_EQ(all.jobs[i].id, plain.jobs[i].id);
    EXPECT_EQ(coarse.jobs[i].id, plain.jobs[i].id);
  }
  EXPECT_FALSE(jobs::new_jobs(all).front().preview_levels);
}

class BadRefine : public ::testing::TestWithParam<BadSweep> {};

TEST_P(BadRefine, IsRefusedAtItsLineNamingTheKeyAndTheChoices) {
  const auto dir = sweep_dir();
  const auto file = write_sweep(dir, GetParam().body);
  const std::string message = error_of(file);
  EXPECT_NE(message.find(GetParam().expected), std::string::npos) << message;
  EXPECT_EQ(message.rfind(fmt::format("{}:{}: ", file.string(), GetParam().line), 0), 0u)
      << message;
}

// Lines: 1 name, 2 scene, 3 onwards the body.
INSTANTIATE_TEST_SUITE_P(
    Cases, BadRefine,
    ::testing::Values(
        BadSweep{"depth = 3\nrefine = \"some\"\n", "use \"all\", \"none\" or a table", 4},
        BadSweep{"depth = 3\nrefine = 2\n", "'refine' must be \"all\", \"none\" or a table", 4},
        BadSweep{"depth = 3\nrefine = { rule = \"topk\" }\n",
                 "unknown rule 'topk' in 'refine' (did you mean 'top'?); valid rules: changed, "
                 "none, pareto, threshold, top",
                 4},
        BadSweep{"depth = 3\nrefine = { by = \"seconds\" }\n", "'rule' in 'refine' must name", 4},
        BadSweep{"depth = 3\n[refine]\nrule = \"top\"\nby = \"max_displacment\"\ncount = 1\n",
                 "(did you mean 'max_displacement'?); valid outputs: max_displacement, "
                 "elastic_energy",
                 6},
        BadSweep{"depth = 3\n[refine]\nrule = \"top\"\nby = \"seconds\"\n",
                 "'refine' with this rule needs 'count'", 4},
        BadSweep{"depth = 3\n[refine]\nrule = \"top\"\nby = \"seconds\"\ncount = 0\n",
                 "'count' in 'refine' must be a positive integer", 7},
        BadSweep{"depth = 3\n[refine]\nrule = \"top\"\nby = \"seconds\"\ncount = 1\nabove = 2\n",
                 "unknown key 'above' in 'refine' with rule = \"top\"", 8},
        BadSweep{"depth = 3\n[refine]\nrule = \"top\"\nby = \"seconds\"\ncount = 1\norder = "
                 "\"big\"\n",
                 "must be \"largest\" or \"smallest\"", 8},
        BadSweep{"depth = 3\nrefine = { rule = \"threshold\", by = \"seconds\" }\n",
                 "needs 'above', 'below' or both", 4},
        BadSweep{"depth = 3\nrefine = { rule = \"pareto\", minimize = [\"seconds\"] }\n",
                 "needs two different outputs", 4},
        BadSweep{"depth = 3\nrefine = { rule = \"changed\", by = \"seconds\" }\n",
                 "needs 'count' (how many points) or 'above'", 4},
        BadSweep{"refine = \"none\"\n", "solves 1 level and has 0 preview levels; give the sweep depth 2",
                 3},
        BadSweep{"depth = 3\n[refine]\nrule = \"none\"\npreview = 3\n",
                 "lower 'preview' below the depth", 6},
        BadSweep{"depth = 2\nrefine = { rule = \"changed\", by = \"seconds\", count = 1 }\n",
                 "compares the last two preview levels", 4},
        BadSweep{"depth = 3\nrefin = \"none\"\n", "did you mean 'refine'", 4}));

}  // namespace
}  // namespace psq

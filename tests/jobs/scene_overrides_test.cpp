// Overriding a scene's numbers by path: the former fixed parameters, any number of the file
// (by key, by name, by index), keys the file omits, canonical integers and reals, and the
// refusals: unknown paths with a suggestion, non-numbers, and the scene reader's rules.

#include "jobs/scene_overrides.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "engine/scene/scene_reader.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

namespace fs = std::filesystem;
using jobs::OverrideError;
using jobs::SceneDocument;

const fs::path kCantilever = test::source_dir() / "jobs/scenes/cantilever.toml";
const std::string kH = "shell.strip.material.thickness";
const std::string kEdge = "shell.strip.mesh.edge_length";

/// The message of the OverrideError that `attempt` throws, checking the path it names.
template <class Attempt>
std::string refusal(const std::string& path, Attempt&& attempt) {
  try {
    attempt();
  } catch (const OverrideError& error) {
    EXPECT_EQ(error.path(), path);
    return error.what();
  }
  ADD_FAILURE() << "'" << path << "' was accepted";
  return "";
}

std::string canonical_refusal(const SceneDocument& scene, const std::string& path,
                              const nlohmann::json& value) {
  return refusal(path, [&] { scene.canonical_override(path, value); });
}

TEST(SceneOverrides, TheFormerTenPathsSetTheSameValuesAsWritten) {
  const SceneDocument document = SceneDocument::read(kCantilever);
  // The cantilever has no [solver] or [contact] table: those keys are added.
  const Scene scene = document.apply({{kH, 2e-3},
                                      {"shell.strip.material.poisson_ratio", 0.4},
                                      {"time.frames", 7},
                                      {"solver.tolerance", 1e-6},
                                      {"time.step", 0.5},
                                      {"solver.max_iterations", 9},
                                      {"shell.strip.material.youngs_modulus", 3e9},
                                      {"shell.strip.material.density", 10.0},
                                      {"contact.friction", 0.4}});
  EXPECT_EQ(scene.shells[0].material.thickness, 2e-3);
  EXPECT_EQ(scene.contact.friction, 0.4);
  EXPECT_EQ(scene.shells[0].material.poisson_ratio, 0.4);
  EXPECT_EQ(scene.shells[0].material.youngs_modulus, 3e9);
  EXPECT_EQ(scene.shells[0].material.density, 10.0);
  EXPECT_EQ(scene.time.frames, 7);
  EXPECT_EQ(scene.time.step, 0.5);
  EXPECT_EQ(scene.solver.tolerance, 1e-6);
  EXPECT_EQ(scene.solver.max_iterations, 9);
  // The document is not edited: a second scene without overrides is the file's.
  EXPECT_EQ(document.apply({}).shells[0].material.thickness, 1e-3);
}

TEST(SceneOverrides, AnyNumberIsAPathByKeyNameOrIndex) {
  const Scene scene = SceneDocument::read(kCantilever)
                          .apply({{kEdge, 0.0025},
                                  {"gravity.2", -9.81},
                                  {"shell.strip.load.0.force.2", -2e-3},
                                  {"shell.strip.pin.clamp.box.max.0", -0.09},
                                  {"hierarchy.vertex_ratio", 0.5},
                                  {"contact.ccd.rescaling", 0.8}});
  EXPECT_EQ(scene.shells[0].mesh.sheet.edge_length, 0.0025);
  EXPECT_EQ(scene.gravity.z(), -9.81);
  EXPECT_EQ(scene.shells[0].loads[0].total_force.z(), -2e-3);
  EXPECT_EQ(scene.shells[0].pins[0].selector.box_max.x(), -0.09);
  EXPECT_EQ(scene.hierarchy.vertex_ratio, 0.5);
  EXPECT_EQ(scene.contact.ccd_rescaling, 0.8);
  EXPECT_EQ(scene.shells[0].mesh.sheet.width, 0.2);  // untouched neighbours
}

TEST(SceneOverrides, PinMotionsAreAddressedThroughTheirPinsName) {
  const SceneDocument twist = SceneDocument::read(test::source_dir() / "jobs/scenes/twist.toml");
  const Scene scene = twist.apply({{"shell.ribbon.pin.turned_end.motion.0.angle_degrees", 90},
                                   {"shell.ribbon.pin.turned_end.motion.0.axis_point.1", 0.01}});
  EXPECT_EQ(scene.shells[0].pins[1].motions[0].angle_degrees, 90.0);
  EXPECT_EQ(scene.shells[0].pins[1].motions[0].axis_point.y(), 0.01);
  EXPECT_EQ(scene.shells[0].pins[0].motions.size(), 0u);
}

// A pin of chosen components keeps them under overrides of its motion's numbers; the list
// itself is not a number and cannot be varied.
TEST(SceneOverrides, PinsOfChosenComponentsKeepThemAndTheListIsNoPath) {
  const SceneDocument document(R"(
[[shell]]
name = "sheet"
mesh = { generator = "sheet", width = 1, height = 1, edge_length = 0.25 }
material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 100, thickness = 1e-3 }
[[shell.pin]]
name = "roller"
box = { min = [-0.5, -0.5, 0], max = [-0.5, 0.5, 0] }
components = ["z", "x"]
[[shell.pin.motion]]
translation = [0, 0, 0.1]
)",
                               "rollers.toml");
  const Scene scene = document.apply({{"shell.sheet.pin.roller.motion.0.translation.2", 0.3}});
  EXPECT_EQ(scene.shells[0].pins[0].motions[0].translation.z(), 0.3);
  EXPECT_EQ(scene.shells[0].pins[0].components, (PinComponents{true, false, true}));
  EXPECT_NE(canonical_refusal(document, "shell.sheet.pin.roller.components", 1).find("an array"),
            std::string::npos);
}

TEST(SceneOverrides, ANameWithDotsSpansSeveralKeys) {
  const auto dir = test::fresh_temp_dir("scene_overrides");
  const auto file = test::write_file(
      dir / "scene.toml",
      "[[shell]]\nname = \"left.sheet\"\n"
      "mesh = { generator = \"sheet\", width = 1, height = 1, edge_length = 0.5 }\n"
      "material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 1, thickness = 1e-3 }\n"
      "[[shell]]\nname = \"left\"\n"
      "mesh = { generator = \"sphere\", radius = 1, edge_length = 0.5 }\n"
      "material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 1, thickness = 1e-3 }\n");
  const SceneDocument document = SceneDocument::read(file);
  const Scene scene = document.apply(
      {{"shell.left.sheet.material.thickness", 2e-3}, {"shell.left.material.thickness", 3e-3}});
  EXPECT_EQ(scene.shells[0].material.thickness, 2e-3);
  EXPECT_EQ(scene.shells[1].material.thickness, 3e-3);
  const auto paths = document.numeric_paths();
  EXPECT_NE(std::find(paths.begin(), paths.end(), "shell.left.sheet.mesh.width"), paths.end());
}

TEST(SceneOverrides, IntegersStayIntegersAndRealsTakeIntegers) {
  const SceneDocument document = SceneDocument::read(kCantilever);
  const auto frames = document.canonical_override("time.frames", 4);
  EXPECT_TRUE(frames.is_number_integer());
  EXPECT_EQ(frames, 4);
  // A real written as an integer is the same value as written as a real.
  const auto modulus = document.canonical_override("shell.strip.material.youngs_modulus", 500000);
  EXPECT_TRUE(modulus.is_number_float());
  EXPECT_EQ(modulus.dump(), nlohmann::json(5e5).dump());
  // The file writes density = 1200 (an integer); it is still a real.
  EXPECT_TRUE(document.canonical_override("shell.strip.material.density", 900).is_number_float());
  // Keys the file omits: preview_iterations is an integer, contact.thickness a real.
  EXPECT_TRUE(document.canonical_override("hierarchy.preview_iterations", 3).is_number_integer());
  EXPECT_TRUE(document.canonical_override("contact.thickness", 0).is_number_float());
  EXPECT_NE(canonical_refusal(document, "time.frames", 2.5).find("expected an integer"),
            std::string::npos);
}

TEST(SceneOverrides, UnknownPathsAreRefusedWithTheNearestValidPath) {
  const SceneDocument document = SceneDocument::read(kCantilever);
  auto expect_suggests = [&](const std::string& path, const std::string& nearest) {
    const std::string message = canonical_refusal(document, path, 1);
    EXPECT_NE(message.find("unknown parameter '" + path + "'; did you mean '" + nearest + "'?"),
              std::string::npos)
        << message;
  };
  expect_suggests("shell.strip.mesh.edge_lenght", kEdge);   // a number of the file
  expect_suggests("shell.strip.material.thicknes", kH);     // the tolerance grows with length
  expect_suggests("solver.tolerence", "solver.tolerance");  // a key the file omits
  expect_suggests("hierarchy.vertex_ration", "hierarchy.vertex_ratio");
  for (const std::string path :
       {"shell.cloth.material.thickness", "gravity.3", "gravity.01", "time.step.x",
        "shell.strip.pin.0.box.min.0", "gravity.z", "contact.pair.0.friction", ""})
    EXPECT_NE(canonical_refusal(document, path, 1).find("unknown parameter '" + path + "'"),
              std::string::npos)
        << path;
}

TEST(SceneOverrides, PathsToSomethingOtherThanANumberAreRefused) {
  const SceneDocument document = SceneDocument::read(kCantilever);
  EXPECT_NE(canonical_refusal(document, "shell.strip.bending", 1).find("is a string in the scene"),
            std::string::npos);
  EXPECT_NE(canonical_refusal(document, "shell.strip.mesh.structured", 1).find("a boolean"),
            std::string::npos);
  const std::string table = canonical_refusal(document, "shell.strip.material", 1);
  EXPECT_NE(table.find("is a table in the scene, not a number; only numbers can be varied, "
                       "such as 'shell.strip.material."),
            std::string::npos)
      << table;
  EXPECT_NE(canonical_refusal(document, "gravity", 1).find("an array"), std::string::npos);
  EXPECT_NE(canonical_refusal(document, kH, "thick").find("must be a number (got \"thick\")"),
            std::string::npos);
  // A key the file omits that the format defines as text.
  EXPECT_NE(canonical_refusal(document, "solver.frame_solution", 1).find("expected a string"),
            std::string::npos);
}

TEST(SceneOverrides, ValuesAreRefusedWithTheScenesRuleNamingThePath) {
  const SceneDocument document = SceneDocument::read(kCantilever);
  auto message = [&](const std::string& path, const nlohmann::json& value) {
    const std::string text = canonical_refusal(document, path, value);
    EXPECT_EQ(text.rfind("parameter '" + path + "': ", 0), 0u) << text;
    return text;
  };
  EXPECT_NE(
      message(kH, -1e-3).find("'thickness' in [shell.material] must be positive (got -0.001)"),
      std::string::npos);
  EXPECT_NE(message("shell.strip.material.poisson_ratio", 0.5).find("in (-1, 0.5)"),
            std::string::npos);
  EXPECT_NE(message("contact.friction", -0.1).find("must be at least 0 (got -0.1)"),
            std::string::npos);
  EXPECT_NE(message("time.frames", 0).find("at least 1"), std::string::npos);
  EXPECT_NE(message(kH, std::numeric_limits<double>::infinity()).find("finite"), std::string::npos);
  EXPECT_NE(message(kEdge, 0.05).find("smaller than the sheet's width and height"),
            std::string::npos);
  // The scene file's line of the replaced value is not given: the value came from elsewhere.
  EXPECT_NE(message(kH, -1e-3).find(kCantilever.string() + ": 'thickness'"), std::string::npos);
}

TEST(SceneOverrides, ValuesPossibleAloneButNotTogetherAreRefusedNamingBoth) {
  const SceneDocument document = SceneDocument::read(kCantilever);
  const std::string height = "shell.strip.mesh.height";
  EXPECT_NO_THROW(document.canonical_override(kEdge, 0.015));
  EXPECT_NO_THROW(document.canonical_override(height, 0.01));
  const std::string message = refusal(kEdge + ", " + height, [&] {
    document.apply({{kEdge, 0.015}, {height, 0.01}});
  });
  EXPECT_NE(message.find("parameters '" + kEdge + "', '" + height + "' together: "),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("smaller than the sheet's width and height"), std::string::npos);
}

TEST(SceneOverrides, EveryNumberOfEveryLibrarySceneIsAPathThatTakesItsOwnValue) {
  for (const auto& entry : fs::recursive_directory_iterator(test::source_dir() / "jobs/scenes")) {
    if (entry.path().extension() != ".toml") continue;
    const SceneDocument document = SceneDocument::read(entry.path());
    const auto paths = document.numeric_paths();
    EXPECT_GT(paths.size(), 5u) << entry.path();
    for (const std::string& path : paths) EXPECT_NO_THROW(document.check_path(path)) << path;
  }
}

TEST(SceneOverrides, AnInvalidBaseSceneIsTheReadersError) {
  const auto dir = test::fresh_temp_dir("scene_overrides_invalid");
  const auto file = test::write_file(dir / "scene.toml", "[time]\nstep = -1\n");
  try {
    SceneDocument::read(file);
    ADD_FAILURE() << "an invalid scene was accepted";
  } catch (const OverrideError&) {
    ADD_FAILURE() << "the base scene's error was blamed on an override";
  } catch (const InputError& error) {
    EXPECT_NE(
        std::string(error.what()).find(file.string() + ":2: 'step' in [time] must be positive"),
        std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace psq

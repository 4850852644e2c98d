#pragma once
// Overriding a scene's numbers by path. An override replaces a number of the base scene
// file's TOML document (or adds a key the file omits), and the scene reader then reads the
// edited document, so overrides obey exactly the rules of the scene format
// (docs/scene-format.md). The sweep expansion validates every job with SceneDocument; the
// executor uses it to build the scene a job runs.
//
// Paths (docs/sweep-format.md): the document's dotted keys ("time.step",
// "contact.ccd.rescaling"); a table of an array of tables by its `name`
// ("shell.strip.material.thickness", "shell.strip.pin.clamp.motion.0.angle_degrees"); an
// element of an array of numbers, or a table without a name, by its index from 0
// ("gravity.2", "shell.strip.load.0.force.2"). One spelling per number, so one job id.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "engine/core/error.hpp"
#include "engine/scene/scene.hpp"
#include "engine/scene/scene_document.hpp"
#include "jobs/job_identity.hpp"

namespace psq::jobs {

/// An override that cannot be applied: an unknown path, a path to something other than a
/// number, or a value the scene reader refuses. The message names the path; path() is the
/// path, or the paths joined by ", " when only their combination is refused.
class OverrideError : public InputError {
 public:
  OverrideError(std::string path, const std::string& message)
      : InputError(message), path_(std::move(path)) {}
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// A valid scene file's TOML document, into which overrides are put before it is read.
class SceneDocument {
 public:
  /// Reads the scene file. Throws the scene reader's InputError if it is not a valid scene.
  static SceneDocument read(const std::filesystem::path& file);

  /// The scene file `file` whose content is `text` (the file need not exist). Throws as read.
  SceneDocument(std::string_view text, std::filesystem::path file);

  /// The path of every number the file writes, each table's keys sorted and array elements
  /// in order (for messages and suggestions). Keys the file omits are paths too but are not
  /// listed.
  std::vector<std::string> numeric_paths() const;

  /// Throws OverrideError unless `path` names a number of the file or a key the scene format
  /// defines where the file omits it: an unknown path (with the nearest valid path), or a
  /// path to a string, boolean, table or array.
  void check_path(const std::string& path) const;

  /// The canonical form of `value` for `path`: a double for a real parameter (an integer
  /// value is converted, so 500000 and 5e5 are the same), an integer for an integer one.
  /// Throws OverrideError as check_path does, for a value that is not a number, and with the
  /// scene reader's message for a value the scene format refuses.
  nlohmann::json canonical_override(const std::string& path, const nlohmann::json& value) const;

  /// The scene with every override put in. Throws OverrideError as check_path does, and with
  /// the scene reader's message if the edited scene is refused.
  Scene apply(const Overrides& overrides) const;

 private:
  struct Slot;
  Slot locate(toml::table& document, const std::string& path) const;
  void put(toml::table& document, const std::string& path, const nlohmann::json& value) const;
  std::optional<std::string> refusal(const std::string& path, const nlohmann::json& value) const;
  [[noreturn]] void fail_unknown(const std::string& path,
                                 const std::vector<std::string>& also_near = {}) const;

  std::filesystem::path file_;
  toml::table document_;
};

}  // namespace psq::jobs

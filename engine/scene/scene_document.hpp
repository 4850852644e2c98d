#pragma once
// The scene reader on a parsed TOML document, for callers that edit a scene file's document
// before reading it: a sweep puts its values into the base scene's document
// (jobs/scene_overrides.hpp), so that the reader's own rules validate them. Apart from
// scene_reader.hpp so that only those callers include toml++.

#include <toml++/toml.h>

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "engine/core/error.hpp"
#include "engine/scene/scene.hpp"

namespace psq {

/// A key the scene format does not define at its place. A caller that added a key to a
/// document tells by this type that the key is unknown rather than its value wrong.
class UnknownKeyError : public InputError {
 public:
  UnknownKeyError(const std::string& message, std::string key, std::optional<std::string> nearest)
      : InputError(message), key_(std::move(key)), nearest_(std::move(nearest)) {}
  /// The unknown key, as written (one key, not a dotted path).
  const std::string& key() const { return key_; }
  /// The defined key of that table nearest to it, if one is close enough to be a typo.
  const std::optional<std::string>& nearest() const { return nearest_; }

 private:
  std::string key_;
  std::optional<std::string> nearest_;
};

/// The TOML document of a scene file's text. Throws InputError "path:line: TOML syntax
/// error: ..." as read_scene does.
toml::table parse_scene_document(std::string_view text, const std::filesystem::path& path);

/// read_scene on a parsed document: messages name `path` and the lines the document's nodes
/// carry (none for nodes a caller added), and mesh files are resolved relative to `path`'s
/// directory. Throws UnknownKeyError for an unknown key, InputError for everything else.
Scene read_scene_document(const toml::table& document, const std::filesystem::path& path);

}  // namespace psq

#pragma once
// Reading scene files (TOML). The format, every key with its unit and default, is documented
// in docs/scene-format.md.

#include <filesystem>
#include <string_view>

#include "engine/scene/scene.hpp"

namespace psq {

/// Reads and validates a scene file. Mesh files are resolved relative to the scene file's
/// directory and must exist; meshes are not built here (see build_shell_mesh), so selectors
/// are checked for form only (see select_vertices for their effect on a mesh).
/// Throws InputError "file:line: message" naming the key for: TOML syntax errors, unknown
/// keys (with the nearest valid key; an UnknownKeyError, engine/scene/scene_document.hpp),
/// wrong types, missing required keys and impossible values (non-positive moduli, densities,
/// thicknesses, sizes and steps; ν ∉ (−1, 0.5); box min > max; motion end < start; zero
/// rotation axes; selectors with zero or several of box / boundary_loop / vertices; repeated
/// shell or pin names).
Scene read_scene(const std::filesystem::path& path);

/// read_scene on `text` as if it were the content of the file `path` (which need not exist):
/// messages name `path` and mesh files are resolved relative to its directory. For callers
/// that hold the text already, such as the fuzz target.
Scene read_scene_text(std::string_view text, const std::filesystem::path& path);

}  // namespace psq

#pragma once
// A scene of the project's library (jobs/scenes), for tests that run or inspect it.

#include <string>

#include "engine/scene/scene_reader.hpp"
#include "support/test_paths.hpp"

namespace psq::test {

/// jobs/scenes/<name>.toml, read and validated.
inline Scene library_scene(const std::string& name) {
  return read_scene(source_dir() / "jobs" / "scenes" / (name + ".toml"));
}

}  // namespace psq::test

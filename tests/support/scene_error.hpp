#pragma once
// Checking the scene reader's refusal of a scene text: an InputError located at a line of the
// file and naming what is wrong.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "engine/core/error.hpp"
#include "engine/scene/scene_reader.hpp"
#include "support/test_paths.hpp"

namespace psq::test {

/// Writes `text` to `path` and expects read_scene to throw an InputError whose message starts
/// with "path:line: " and contains `fragment`.
inline void expect_scene_error(const std::filesystem::path& path, const std::string& text,
                               int line, const std::string& fragment) {
  write_file(path, text);
  try {
    read_scene(path);
    ADD_FAILURE() << "no error for:\n" << text;
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind(fmt::format("{}:{}: ", path.string(), line), 0), 0u) << message;
    EXPECT_NE(message.find(fragment), std::string::npos)
        << "'" << fragment << "' not in: " << message;
  }
}

}  // namespace psq::test

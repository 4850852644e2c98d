// libFuzzer target: the scene reader on TOML text. InputError is the documented answer to a
// bad scene; anything else escapes to libFuzzer and is reported with its input.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string_view>

#include "engine/core/error.hpp"
#include "engine/scene/scene_reader.hpp"

namespace {

// The text is read as if it sat among the library scenes (the seed corpus), so that their
// relative mesh paths ("../data/bunny.obj") resolve and the reader gets past them.
const std::filesystem::path kScenePath = PSQ_SOURCE_DIR "/jobs/scenes/fuzz_input.toml";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    psq::read_scene_text(std::string_view(reinterpret_cast<const char*>(data), size), kScenePath);
  } catch (const psq::InputError&) {
  }
  return 0;
}

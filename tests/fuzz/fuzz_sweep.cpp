// libFuzzer target: the sweep parser on TOML text, with the expansion of its jobs and their
// validation against the base scene. InputError is the documented answer to a bad sweep;
// anything else escapes to libFuzzer and is reported with its input.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string_view>

#include "engine/core/error.hpp"
#include "jobs/sweep_file.hpp"

namespace {

// The text is read as if it sat among the library sweeps (the seed corpus), so that their
// relative scene paths ("../scenes/demo_strip.toml") resolve and the reader gets past them to
// the grids and zips.
const std::filesystem::path kSweepPath = PSQ_SOURCE_DIR "/jobs/sweeps/fuzz_input.toml";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    psq::jobs::read_sweep_text(std::string_view(reinterpret_cast<const char*>(data), size),
                               kSweepPath);
  } catch (const psq::InputError&) {
  }
  return 0;
}

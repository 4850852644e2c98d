// libFuzzer target: the OFF reader (see mesh_fuzz.hpp).
#include "tests/fuzz/mesh_fuzz.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return psq::fuzz::read_mesh_bytes(data, size, psq::parse_off, psq::write_off);
}

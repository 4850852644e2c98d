// libFuzzer target: the PLY reader (see mesh_fuzz.hpp).
#include "tests/fuzz/mesh_fuzz.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return psq::fuzz::read_mesh_bytes(data, size, psq::parse_ply, psq::write_ply);
}

#include "engine/core/checksum.hpp"

namespace psq {

Fnv1a64& Fnv1a64::update(std::span<const std::byte> bytes) {
  constexpr std::uint64_t prime = 1099511628211ull;
  std::uint64_t h = state_;
  for (const std::byte b : bytes) h = (h ^ static_cast<std::uint64_t>(b)) * prime;
  state_ = h;
  return *this;
}

std::uint64_t fnv1a64(std::span<const std::byte> bytes) { return Fnv1a64().update(bytes).value(); }

}  // namespace psq

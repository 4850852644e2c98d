#include "engine/core/checksum.hpp"

#include <fmt/format.h>

#include <charconv>
#include <fstream>
#include <system_error>
#include <vector>

namespace psq {
namespace {
constexpr std::string_view kChecksumPrefix = "fnv1a64:";
constexpr std::size_t kChecksumDigits = 16;
}  // namespace

Fnv1a64& Fnv1a64::update(std::span<const std::byte> bytes) {
  constexpr std::uint64_t prime = 1099511628211ull;
  std::uint64_t h = state_;
  for (const std::byte b : bytes) h = (h ^ static_cast<std::uint64_t>(b)) * prime;
  state_ = h;
  return *this;
}

std::uint64_t fnv1a64(std::span<const std::byte> bytes) { return Fnv1a64().update(bytes).value(); }

std::optional<std::uint64_t> file_fnv1a64(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  Fnv1a64 hash;
  std::vector<char> block(std::size_t{1} << 16);
  while (in.read(block.data(), static_cast<std::streamsize>(block.size())) || in.gcount() > 0)
    hash.update(std::as_bytes(std::span(block.data(), static_cast<std::size_t>(in.gcount()))));
  if (in.bad()) return std::nullopt;
  return hash.value();
}

std::string checksum_text(std::uint64_t checksum) {
  return fmt::format("{}{:016x}", kChecksumPrefix, checksum);
}

std::optional<std::uint64_t> parse_checksum(std::string_view text) {
  if (!text.starts_with(kChecksumPrefix)) return std::nullopt;
  const std::string_view digits = text.substr(kChecksumPrefix.size());
  std::uint64_t value = 0;
  const auto [end, error] =
      std::from_chars(digits.data(), digits.data() + digits.size(), value, 16);
  if (error != std::errc() || end != digits.data() + digits.size() ||
      digits.size() != kChecksumDigits)
    return std::nullopt;
  return value;
}

}  // namespace psq

#pragma once
// 64-bit FNV-1a: a fast, dependency-free checksum for detecting damaged or modified files.
// Not cryptographic; every single-byte change alters it (each step is a bijection of the state).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace psq {

/// Incremental 64-bit FNV-1a: for each byte b, h = (h ⊕ b) · 1099511628211, starting from
/// h = 14695981039346656037 (Fowler–Noll–Vo, the published 64-bit parameters).
class Fnv1a64 {
 public:
  Fnv1a64& update(std::span<const std::byte> bytes);
  Fnv1a64& update(std::string_view text) { return update(std::as_bytes(std::span(text))); }
  [[nodiscard]] std::uint64_t value() const { return state_; }

 private:
  std::uint64_t state_ = 14695981039346656037ull;
};

/// FNV-1a 64 of a byte sequence in one call.
[[nodiscard]] std::uint64_t fnv1a64(std::span<const std::byte> bytes);

/// FNV-1a 64 of a file's bytes, read in blocks; nothing if the file cannot be read (the caller
/// names the file in its own error).
[[nodiscard]] std::optional<std::uint64_t> file_fnv1a64(const std::filesystem::path& file);

/// "fnv1a64:<16 hex digits>": the text form of a checksum wherever one is stored (the job store's
/// checkpoint checksums, the scene hash in a job's parameters).
[[nodiscard]] std::string checksum_text(std::uint64_t checksum);

/// The value of checksum_text's form; nothing for any other text.
[[nodiscard]] std::optional<std::uint64_t> parse_checksum(std::string_view text);

}  // namespace psq

#include "engine/core/checksum.hpp"

#include <gtest/gtest.h>

#include <string_view>

#include "support/test_paths.hpp"

namespace psq {
namespace {

std::uint64_t fnv_of(std::string_view text) { return fnv1a64(std::as_bytes(std::span(text))); }

// Reference values published with the FNV algorithm (64-bit FNV-1a test vectors).
TEST(Fnv1a64, MatchesPublishedTestVectors) {
  EXPECT_EQ(fnv_of(""), 0xcbf29ce484222325ull);
  EXPECT_EQ(fnv_of("a"), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(fnv_of("foobar"), 0x85944171f73967e8ull);
}

TEST(Fnv1a64, IncrementalUpdatesEqualOneCall) {
  Fnv1a64 hash;
  hash.update("foo").update("").update("bar");
  EXPECT_EQ(hash.value(), fnv_of("foobar"));
}

TEST(Fnv1a64, EverySingleByteChangeIsDetected) {
  const std::string original = "checkpoint bytes \x01\x02\x03";
  const std::uint64_t reference = fnv_of(original);
  for (std::size_t i = 0; i < original.size(); ++i) {
    for (int bit = 0; bit < 8; ++bit) {
      std::string changed = original;
      changed[i] = static_cast<char>(changed[i] ^ (1 << bit));
      EXPECT_NE(fnv_of(changed), reference) << "byte " << i << " bit " << bit;
    }
  }
}

TEST(ChecksumText, ReadsBackWhatItWritesAndNothingElse) {
  EXPECT_EQ(checksum_text(0xaf63dc4c8601ec8cull), "fnv1a64:af63dc4c8601ec8c");
  EXPECT_EQ(checksum_text(0xaa), "fnv1a64:00000000000000aa");
  EXPECT_EQ(parse_checksum(checksum_text(0x0123456789abcdefull)), 0x0123456789abcdefull);
  EXPECT_FALSE(parse_checksum("00000000000000aa"));           // the bare digits
  EXPECT_FALSE(parse_checksum("fnv1a64:aa"));                 // too short
  EXPECT_FALSE(parse_checksum("fnv1a64:00000000000000aa0"));  // too long
  EXPECT_FALSE(parse_checksum("fnv1a64:00000000000000ag"));
  EXPECT_FALSE(parse_checksum(""));
}

TEST(FileFnv1a64, HashesTheFileBytesAndReportsAnUnreadableFile) {
  const auto dir = test::fresh_temp_dir("checksum");
  // More than one read block (64 KiB), so the blocks are chained.
  const std::string bytes(200000, '\x5a');
  EXPECT_EQ(file_fnv1a64(test::write_file(dir / "data", bytes)), fnv_of(bytes));
  EXPECT_EQ(file_fnv1a64(test::write_file(dir / "empty", "")), fnv_of(""));
  EXPECT_FALSE(file_fnv1a64(dir / "missing"));
}

}  // namespace
}  // namespace psq

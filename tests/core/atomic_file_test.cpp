#include <gtest/gtest.h>

#include <fstream>

#include "engine/core/atomic_file.hpp"
#include "engine/core/error.hpp"
#include "support/small_filesystem.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

TEST(AtomicFile, WritesAndReplacesWithoutLeavingTemporaries) {
  const auto dir = test::fresh_temp_dir("atomic");
  const auto target = dir / "out.txt";
  write_file_atomically(target, [](std::ostream& o) { o << "first"; });
  write_file_atomically(target, [](std::ostream& o) { o << "second"; });
  EXPECT_EQ(test::read_file(target), "second");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1);
}

TEST(AtomicFile, FailedWriterKeepsThePreviousVersion) {
  const auto dir = test::fresh_temp_dir("atomic");
  const auto target = dir / "out.txt";
  write_file_atomically(target, [](std::ostream& o) { o << "good"; });
  EXPECT_THROW(write_file_atomically(target, [](std::ostream&) { throw std::runtime_error("boom"); }),
               std::runtime_error);
  EXPECT_EQ(test::read_file(target), "good");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()), 1);
}

TEST(AtomicFile, MissingDirectoryNamesThePath) {
  const auto target = test::fresh_temp_dir("atomic") / "no" / "such" / "dir.txt";
  try {
    write_file_atomically(target, [](std::ostream& o) { o << "x"; });
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(target.string()), std::string::npos);
  }
}

TEST(AtomicFile, AFullOrReadOnlyDiskKeepsThePreviousVersionAndSaysWhy) {
  const auto dir = test::fresh_temp_dir("atomic") / "disk";
  const test::SmallFilesystem disk(dir, 1 << 20);
  const auto target = dir / "summary.json";
  write_file_atomically(target, std::string_view("previous"));
  const std::string next(64 * 1024, 'x');
  const auto expect_refused = [&](const std::string& reason) {
    try {
      write_file_atomically(target, [&](std::ostream& o) { o << next; });
      ADD_FAILURE() << "the write succeeded";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(target.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
    }
    EXPECT_EQ(test::read_file(target), "previous");
  };
  disk.fill(4096);  // room for the start of the file, not for all of it
  expect_refused("No space left on device");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir),
                          std::filesystem::directory_iterator()),
            2);  // the target and the filler: no temporary left
  disk.free_space();
  disk.set_read_only(true);
  expect_refused("Read-only file system");
  disk.set_read_only(false);
  write_file_atomically(target, std::string_view(next));
  EXPECT_EQ(test::read_file(target), next);
}

}  // namespace
}  // namespace psq

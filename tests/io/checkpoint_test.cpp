#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>

#include "engine/io/checkpoint.hpp"
#include "engine/core/checksum.hpp"
#include "io/sample_checkpoint.hpp"
#include "support/small_filesystem.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

namespace fs = std::filesystem;
using test::expect_same_checkpoint;
using test::sample_checkpoint;

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::vector<std::string> directory_entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

/// The message of the CheckpointError thrown by read_checkpoint, or "" (and a test failure).
std::string read_error(const fs::path& path, std::optional<std::uint64_t> expected = {}) {
  try {
    read_checkpoint(path, expected);
    ADD_FAILURE() << "reading " << path << " did not throw";
  } catch (const CheckpointError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// Byte offset of a contiguous dataset's data in an HDF5 file, through the C API.
haddr_t dataset_offset(const fs::path& path, const char* dataset) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t set = H5Dopen2(file, dataset, H5P_DEFAULT);
  const haddr_t offset = H5Dget_offset(set);
  H5Dclose(set);
  H5Fclose(file);
  return offset;
}

TEST(Checkpoint, RoundTripKeepsEveryField) {
  const fs::path path = test::fresh_temp_dir("checkpoint") / "level2.h5";
  const Checkpoint written = sample_checkpoint(6, 2, 9);
  write_checkpoint(path, written);
  expect_same_checkpoint(read_checkpoint(path), written);
}

TEST(Checkpoint, RoundTripOfEmptyStatisticsAndLargeParameters) {
  const fs::path path = test::fresh_temp_dir("checkpoint") / "level0.h5";
  Checkpoint written = sample_checkpoint(3, 0, 0);
  written.statistics = {};
  written.solver.scalars = {};
  written.solver.progress = LevelProgress::level_done;
  written.code_version = "";
  // Larger than HDF5's 64 KiB limit for attributes stored in the object header.
  written.parameters = "[" + std::string(100000, ' ') + "1]";
  write_checkpoint(path, written);
  expect_same_checkpoint(read_checkpoint(path), written);
}

TEST(Checkpoint, ReturnsTheChecksumOfTheFileBytes) {
  const fs::path path = test::fresh_temp_dir("checkpoint") / "level1.h5";
  const std::uint64_t checksum = write_checkpoint(path, sample_checkpoint(5, 1, 3));
  const std::string bytes = read_bytes(path);
  EXPECT_EQ(checksum, fnv1a64(std::as_bytes(std::span(bytes))));
  expect_same_checkpoint(read_checkpoint(path, checksum), sample_checkpoint(5, 1, 3));
}

TEST(Checkpoint, WrongExpectedChecksumIsRefused) {
  const fs::path path = test::fresh_temp_dir("checkpoint") / "level1.h5";
  const std::uint64_t checksum = write_checkpoint(path, sample_checkpoint(5, 1, 3));
  const std::string message = read_error(path, checksum ^ 1);
  EXPECT_TRUE(contains(message, path.string())) << message;
  EXPECT_TRUE(contains(message, "checksum")) << message;
}

TEST(Checkpoint, TruncatedFilesAreRefused) {
  const fs::path dir = test::fresh_temp_dir("checkpoint");
  const fs::path original = dir / "original.h5";
  const std::uint64_t checksum = write_checkpoint(original, sample_checkpoint(8, 0, 2));
  const std::string bytes = read_bytes(original);
  const fs::path cut = dir / "cut.h5";
  for (const std::size_t length : {std::size_t{0}, std::size_t{1}, std::size_t{8}, std::size_t{100},
                                   bytes.size() / 4, bytes.size() / 2, bytes.size() - 100,
                                   bytes.size() - 1}) {
    write_bytes(cut, std::string_view(bytes).substr(0, length));
    for (const auto& expected : {std::optional<std::uint64_t>{}, std::optional{checksum}}) {
      const std::string message = read_error(cut, expected);
      EXPECT_TRUE(contains(message, cut.string())) << "length " << length << ": " << message;
    }
  }
}

TEST(Checkpoint, FlippedByteInTheDataFailsTheContentChecksum) {
  const fs::path dir = test::fresh_temp_dir("checkpoint");
  const fs::path path = dir / "level0.h5";
  write_checkpoint(path, sample_checkpoint(6, 0, 1));
  const std::string bytes = read_bytes(path);
  for (const char* dataset : {"/mesh/positions", "/mesh/triangles", "/solver/previous_positions",
                              "/statistics/iterations/gradient_norm"}) {
    const haddr_t offset = dataset_offset(path, dataset);
    ASSERT_NE(offset, HADDR_UNDEF) << dataset;
    ASSERT_LT(offset + 5, bytes.size());
    std::string damaged = bytes;
    damaged[offset + 5] = static_cast<char>(damaged[offset + 5] ^ 0x10);
    const fs::path copy = dir / "damaged.h5";
    write_bytes(copy, damaged);
    const std::string message = read_error(copy);
    EXPECT_TRUE(contains(message, copy.string())) << message;
    EXPECT_TRUE(contains(message, "content checksum")) << dataset << ": " << message;
  }
}

// A flip anywhere is caught by the file checksum; without it, by HDF5's metadata checksums or by
// the content checksum, unless the byte is unused: then the content read back is unchanged.
TEST(Checkpoint, FlippedBytesAnywhereNeverGiveWrongContentOrCrash) {
  const fs::path dir = test::fresh_temp_dir("checkpoint");
  const fs::path path = dir / "level0.h5";
  const Checkpoint written = sample_checkpoint(4, 0, 1);
  const std::uint64_t checksum = write_checkpoint(path, written);
  const std::string bytes = read_bytes(path);
  const fs::path copy = dir / "damaged.h5";
  int detected = 0, positions = 0;
  for (std::size_t i = 0; i < bytes.size(); i += 19, ++positions) {
    std::string damaged = bytes;
    damaged[i] = static_cast<char>(damaged[i] ^ 0x5a);
    write_bytes(copy, damaged);
    EXPECT_THROW(read_checkpoint(copy, checksum), CheckpointError) << "byte " << i;
    try {
      expect_same_checkpoint(read_checkpoint(copy), written);
    } catch (const CheckpointError& e) {
      ++detected;
      ASSERT_TRUE(contains(e.what(), copy.string())) << e.what();
    }
  }
  // Most of a small checkpoint is metadata and data, not padding.
  EXPECT_GT(detected, positions / 2);
}

TEST(Checkpoint, NewerSchemaVersionIsRefusedAsInputError) {
  const fs::path path = test::fresh_temp_dir("checkpoint") / "level0.h5";
  write_checkpoint(path, sample_checkpoint(3, 0, 1));
  const int newer = checkpoint_schema_version + 1;
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  const hid_t attribute = H5Aopen(file, "schema_version", H5P_DEFAULT);
  ASSERT_GE(H5Awrite(attribute, H5T_NATIVE_INT, &newer), 0);
  H5Aclose(attribute);
  H5Fclose(file);
  try {
    read_checkpoint(path);
    FAIL() << "a newer schema version was accepted";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_TRUE(contains(message, path.string())) << message;
    EXPECT_TRUE(contains(message, "newer")) << message;
    EXPECT_TRUE(contains(message, std::to_string(newer))) << message;
  }
}

TEST(Checkpoint, DatasetLargerThanItsStorageIsRefusedWithoutAllocatingIt) {
  const fs::path path = test::fresh_temp_dir("checkpoint") / "level0.h5";
  write_checkpoint(path, sample_checkpoint(3, 0, 1));
  // Replace the positions by a 2^32 × 3 dataset that was never written (no storage allocated).
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(H5Ldelete(file, "/mesh/positions", H5P_DEFAULT), 0);
  const hsize_t dims[2] = {hsize_t{1} << 32, 3};
  const hid_t space = H5Screate_simple(2, dims, nullptr);
  const hid_t set = H5Dcreate2(file, "/mesh/positions", H5T_IEEE_F64LE, space, H5P_DEFAULT,
                               H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(set, 0);
  H5Dclose(set);
  H5Sclose(space);
  H5Fclose(file);
  const std::string message = read_error(path);
  EXPECT_TRUE(contains(message, path.string())) << message;
  EXPECT_TRUE(contains(message, "/mesh/positions")) << message;
  EXPECT_TRUE(contains(message, "more elements than the file stores")) << message;
}

TEST(Checkpoint, NonHdf5AndForeignHdf5FilesAreRefused) {
  const fs::path dir = test::fresh_temp_dir("checkpoint");
  const fs::path text = test::write_file(dir / "notes.h5", "these are not the bytes you want\n");
  std::string message = read_error(text);
  EXPECT_TRUE(contains(message, text.string())) << message;
  EXPECT_TRUE(contains(message, "not an HDF5 file")) << message;

  const fs::path foreign = dir / "foreign.h5";
  const hid_t file = H5Fcreate(foreign.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  const hsize_t dims[1] = {4};
  const hid_t space = H5Screate_simple(1, dims, nullptr);
  const hid_t set = H5Dcreate2(file, "data", H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT,
                               H5P_DEFAULT);
  const double values[4] = {1, 2, 3, 4};
  H5Dwrite(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values);
  H5Dclose(set);
  H5Sclose(space);
  H5Fclose(file);
  message = read_error(foreign);
  EXPECT_TRUE(contains(message, foreign.string())) << message;
  EXPECT_TRUE(contains(message, "not a PSQ checkpoint")) << message;

  const fs::path missing = dir / "missing.h5";
  message = read_error(missing);
  EXPECT_TRUE(contains(message, missing.string())) << message;
  EXPECT_TRUE(contains(message, "no such file")) << message;
}

TEST(Checkpoint, SuccessfulWritesLeaveNoTemporaryAndReplaceThePreviousFile) {
  const fs::path dir = test::fresh_temp_dir("checkpoint");
  const fs::path path = dir / "level1.h5";
  write_checkpoint(path, sample_checkpoint(4, 1, 1));
  const std::uint64_t second = write_checkpoint(path, sample_checkpoint(5, 1, 2));
  EXPECT_EQ(directory_entries(dir), std::vector<std::string>{"level1.h5"});
  expect_same_checkpoint(read_checkpoint(path, second), sample_checkpoint(5, 1, 2));
}

TEST(Checkpoint, InconsistentCheckpointsAreNotWritten) {
  const fs::path dir = test::fresh_temp_dir("checkpoint");
  const fs::path path = dir / "level0.h5";
  Checkpoint bad_index = sample_checkpoint(3, 0, 1);
  bad_index.triangles(1, 2) = 9;
  Checkpoint bad_rows = sample_checkpoint(3, 0, 1);
  bad_rows.rest_positions.conservativeResize(8, 3);
  Checkpoint not_finite = sample_checkpoint(3, 0, 1);
  not_finite.positions(4, 1) = std::nan("");
  Checkpoint bad_json = sample_checkpoint(3, 0, 1);
  bad_json.parameters = "{\"E\": ";
  for (const Checkpoint* bad : {&bad_index, &bad_rows, &not_finite, &bad_json}) {
    try {
      write_checkpoint(path, *bad);
      ADD_FAILURE() << "an inconsistent checkpoint was written";
    } catch (const CheckpointWriteError& e) {
      ADD_FAILURE() << "an inconsistent checkpoint is not a failure to write: " << e.what();
    } catch (const CheckpointError& e) {
      EXPECT_TRUE(contains(e.what(), path.string())) << e.what();
      EXPECT_TRUE(contains(e.what(), "inconsistent")) << e.what();
    }
  }
  EXPECT_TRUE(directory_entries(dir).empty());
}

TEST(Checkpoint, MissingDirectoryIsNamed) {
  const fs::path path = test::fresh_temp_dir("checkpoint") / "no" / "level0.h5";
  try {
    write_checkpoint(path, sample_checkpoint(3, 0, 1));
    FAIL() << "wrote into a missing directory";
  } catch (const CheckpointWriteError& e) {
    EXPECT_TRUE(contains(e.what(), path.string())) << e.what();
    EXPECT_TRUE(contains(e.what(), "no directory")) << e.what();
  }
}

/// In a child process (gtest death test): runs `prepare`, then writes a checkpoint to `path`
/// and exits 0 after printing the CheckpointWriteError's message; 1 if the write succeeded, and
/// any other exception aborts.
void write_in_child_expecting_failure(const fs::path& path, void (*prepare)()) {
  prepare();
  try {
    write_checkpoint(path, sample_checkpoint(20, 0, 2));
  } catch (const CheckpointWriteError& e) {
    std::cerr << e.what() << std::endl;
    std::_Exit(0);
  }
  std::_Exit(1);
}

TEST(CheckpointDeathTest, UnwritableDirectoryKeepsThePreviousCheckpoint) {
  const fs::path dir = test::fresh_temp_dir("checkpoint");
  const fs::path path = dir / "level0.h5";
  const Checkpoint previous = sample_checkpoint(4, 0, 1);
  const std::uint64_t checksum = write_checkpoint(path, previous);
  fs::permissions(dir, fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                           fs::perms::group_exec | fs::perms::others_read |
                           fs::perms::others_exec);
  // root ignores permission bits: the child gives up root for the unprivileged "nobody" first.
  EXPECT_EXIT(write_in_child_expecting_failure(path,
                                               [] {
                                                 if (::geteuid() == 0 &&
                                                     (::setgid(65534) != 0 || ::setuid(65534) != 0))
                                                   std::_Exit(2);
                                               }),
              ::testing::ExitedWithCode(0), "level0.h5");
  fs::permissions(dir, fs::perms::owner_all, fs::perm_options::add);
  EXPECT_EQ(directory_entries(dir), std::vector<std::string>{"level0.h5"});
  expect_same_checkpoint(read_checkpoint(path, checksum), previous);
}

TEST(CheckpointDeathTest, WriteCutShortByAFileSizeLimitKeepsThePreviousCheckpoint) {
  const fs::path dir = test::fresh_temp_dir("checkpoint");
  const fs::path path = dir / "level0.h5";
  const Checkpoint previous = sample_checkpoint(4, 0, 1);
  const std::uint64_t checksum = write_checkpoint(path, previous);
  // Like a full disk: writes past 4 KiB fail with EFBIG (SIGXFSZ ignored, as a runner would).
  EXPECT_EXIT(write_in_child_expecting_failure(path,
                                               [] {
                                                 std::signal(SIGXFSZ, SIG_IGN);
                                                 const rlimit limit{4096, 4096};
                                                 ::setrlimit(RLIMIT_FSIZE, &limit);
                                               }),
              ::testing::ExitedWithCode(0), "level0.h5");
  EXPECT_EQ(directory_entries(dir), std::vector<std::string>{"level0.h5"});
  expect_same_checkpoint(read_checkpoint(path, checksum), previous);
}

TEST(Checkpoint, AFullDiskKeepsThePreviousCheckpointWhereverTheWriteRunsOutOfSpace) {
  const fs::path dir = test::fresh_temp_dir("checkpoint") / "disk";
  const test::SmallFilesystem disk(dir, 1 << 20);
  const fs::path path = dir / "level0.h5";
  const Checkpoint previous = sample_checkpoint(4, 0, 1);
  const std::uint64_t checksum = write_checkpoint(path, previous);
  Checkpoint next = sample_checkpoint(40, 0, 2);
  next.statistics.iterations.resize(100, next.statistics.iterations.back());
  const fs::path elsewhere = test::fresh_temp_dir("checkpoint") / "level0.h5";
  write_checkpoint(elsewhere, next);
  const std::uintmax_t size = fs::file_size(elsewhere);
  // No space at all, and space that runs out anywhere in the file: in the superblock, the
  // metadata or the datasets (HDF5 holds small datasets back until they close: a failure to
  // write one there once went unreported).
  for (std::size_t spare = 0; spare < size; spare += 4096) {
    SCOPED_TRACE(spare);
    disk.fill(spare);
    try {
      write_checkpoint(path, next);
      ADD_FAILURE() << "the write succeeded on a full disk";
    } catch (const CheckpointWriteError& e) {
      EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("No space left on device"), std::string::npos)
          << e.what();
    }
    EXPECT_EQ(directory_entries(dir), (std::vector<std::string>{".filler", "level0.h5"}));
    expect_same_checkpoint(read_checkpoint(path, checksum), previous);
    disk.free_space();
  }
  expect_same_checkpoint(read_checkpoint(path, write_checkpoint(path, next)), next);
}

}  // namespace
}  // namespace psq

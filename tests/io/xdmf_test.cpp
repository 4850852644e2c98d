#include <gtest/gtest.h>
#include <hdf5.h>

#include <fstream>
#include <iterator>
#include <map>
#include <numeric>
#include <regex>
#include <sstream>

#include "engine/io/xdmf.hpp"
#include "io/sample_checkpoint.hpp"
#include "io/xdmf_validator.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

namespace fs = std::filesystem;
using test::read_file;
using test::validate_sidecar;
using test::SidecarSummary;

struct Job {
  fs::path dir;
  std::vector<XdmfEntry> entries;
};

/// Three checkpoints of a job: level 0 at frames 1 and 2, level 1 (finer, in a subdirectory)
/// at frame 2, listed in a sidecar.
Job write_job() {
  Job job{test::fresh_temp_dir("xdmf"), {}};
  fs::create_directories(job.dir / "snapshots");
  const std::vector<std::pair<std::string, Checkpoint>> checkpoints{
      {"level0_frame1.h5", test::sample_checkpoint(3, 0, 1)},
      {"level0_frame2.h5", test::sample_checkpoint(3, 0, 2)},
      {"snapshots/level1_frame2.h5", test::sample_checkpoint(5, 1, 2)}};
  for (const auto& [file, checkpoint] : checkpoints) {
    write_checkpoint(job.dir / file, checkpoint);
    job.entries.push_back(xdmf_entry(file, checkpoint));
  }
  write_xdmf(job.dir / "job.xdmf", job.entries);
  return job;
}

TEST(Xdmf, SidecarMatchesItsHdf5Files) {
  const Job job = write_job();
  const SidecarSummary summary = validate_sidecar(job.dir / "job.xdmf");
  EXPECT_TRUE(summary.problems.empty()) << ::testing::PrintToString(summary.problems);
  EXPECT_EQ(summary.uniform_grids, 3);
  EXPECT_EQ(summary.hdf_items, 3 * 3);  // triangles, positions, rest positions per grid
  EXPECT_EQ(summary.times, (std::vector<std::string>{"0", "1", "2"}));
  const std::string xml = read_file(job.dir / "job.xdmf");
  EXPECT_NE(xml.find(R"(<Xdmf Version="3.0">)"), std::string::npos);
  EXPECT_NE(xml.find(R"(CollectionType="Temporal")"), std::string::npos);
  EXPECT_NE(xml.find(R"(Name="level1_frame2")"), std::string::npos);
}

// The validator itself must catch a sidecar that disagrees with its files.
TEST(Xdmf, ValidatorCatchesWrongCountsAndMissingFiles) {
  Job job = write_job();
  job.entries[1].vertex_count += 1;
  job.entries[2].file = "snapshots/missing.h5";
  write_xdmf(job.dir / "wrong.xdmf", job.entries);
  const SidecarSummary summary = validate_sidecar(job.dir / "wrong.xdmf");
  // Positions and rest positions of entry 1, and the three items of entry 2.
  EXPECT_EQ(summary.problems.size(), 2u + 3u) << ::testing::PrintToString(summary.problems);
}

TEST(Xdmf, WritesAtomicallyAndRefusesUnreferenceableNames) {
  Job job = write_job();
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(job.dir))
    names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"job.xdmf", "level0_frame1.h5", "level0_frame2.h5",
                                             "snapshots"}));
  job.entries[0].file = "C:level0.h5";
  try {
    write_xdmf(job.dir / "bad.xdmf", job.entries);
    FAIL() << "a file name with ':' was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.xdmf"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("C:level0.h5"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(job.dir / "bad.xdmf"));
}

}  // namespace
}  // namespace psq

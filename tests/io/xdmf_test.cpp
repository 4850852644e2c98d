#include "engine/io/xdmf.hpp"

#include <gtest/gtest.h>
#include <hdf5.h>

#include <fstream>
#include <iterator>
#include <map>
#include <numeric>
#include <regex>
#include <sstream>

#include "engine/io/part_meshes.hpp"
#include "io/meshio_reader.hpp"
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
  std::vector<PartMeshes> meshes;  ///< what each entry's file holds
};

/// The moving collider's translation at `frame` (any function of the frame will do).
Eigen::RowVector3d ball_translation(int frame) { return {0.01 * frame, -0.02, 0.125 * frame}; }

/// A system of two parts at `level` and `frame`: a k×k bumpy sheet (part "sheet"), then a
/// tetrahedron (collider "the ball", a name a file cannot hold) translated by
/// ball_translation(frame); cut into parts as a job does.
PartMeshes sample_parts(int k, int level, int frame) {
  const Checkpoint sheet = test::sample_checkpoint(k, level, frame);
  const Positions tetrahedron{{0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {0, 0, 2}};
  TriMesh rest;
  const Eigen::Index n = sheet.rest_positions.rows(), m = sheet.triangles.rows();
  rest.vertices.resize(n + 4, 3);
  rest.vertices << sheet.rest_positions, tetrahedron;
  rest.triangles.resize(m + 4, 3);
  const Triangles faces = Triangles{{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}}.array() + int(n);
  rest.triangles << sheet.triangles, faces;
  Positions positions(n + 4, 3);
  positions << sheet.positions, tetrahedron.rowwise() + ball_translation(frame);
  const std::vector<PartRange> ranges{
      {"sheet", PartKind::shell, 0, static_cast<int>(n), 0, static_cast<int>(m)},
      {"the ball", PartKind::collider, static_cast<int>(n), 4, static_cast<int>(m), 4}};
  return {.level = level,
          .frame = frame,
          .time = sheet.time,
          .parts = split_into_parts(positions, rest, ranges)};
}

/// Three part-meshes files of a job: level 0 at frames 1 and 2, level 1 (finer, in a
/// subdirectory) at frame 2, listed in a sidecar.
Job write_job() {
  Job job{test::fresh_temp_dir("xdmf"), {}, {}};
  fs::create_directories(job.dir / "parts");
  const std::vector<std::pair<std::string, PartMeshes>> files{
      {"level0_frame1.h5", sample_parts(3, 0, 1)},
      {"level0_frame2.h5", sample_parts(3, 0, 2)},
      {"parts/level1_frame2.h5", sample_parts(5, 1, 2)}};
  for (const auto& [file, meshes] : files) {
    write_part_meshes(job.dir / file, meshes);
    job.entries.push_back(xdmf_entry(file, meshes));
    job.meshes.push_back(meshes);
  }
  write_xdmf(job.dir / "job.xdmf", job.entries);
  return job;
}

std::vector<fs::path> part_sidecars(const Job& job) {
  return part_sidecar_paths(job.dir / "job.xdmf", {"sheet", "the ball"});
}

TEST(PartMeshes, SplitsASystemIntoItsPartsAndReadsBackWhatItWrote) {
  const Job job = write_job();
  const PartMeshes& written = job.meshes[2];
  ASSERT_EQ(written.parts.size(), 2u);
  const PartMesh& ball = written.parts[1];
  EXPECT_EQ(ball.kind, PartKind::collider);
  EXPECT_EQ(ball.triangles, (Triangles{{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}}));
  EXPECT_EQ(ball.rest_positions.row(3), Eigen::RowVector3d(0, 0, 2));
  EXPECT_EQ(written.parts[0].positions.rows(), 25);

  const PartMeshes read = read_part_meshes(job.dir / "parts/level1_frame2.h5");
  EXPECT_EQ(read.level, 1);
  EXPECT_EQ(read.frame, 2);
  EXPECT_EQ(read.time, written.time);
  ASSERT_EQ(read.parts.size(), 2u);
  for (std::size_t p = 0; p < 2; ++p) {
    EXPECT_EQ(read.parts[p].name, written.parts[p].name);
    EXPECT_EQ(read.parts[p].kind, written.parts[p].kind);
    EXPECT_EQ(read.parts[p].positions, written.parts[p].positions);
    EXPECT_EQ(read.parts[p].rest_positions, written.parts[p].rest_positions);
    EXPECT_EQ(read.parts[p].triangles, written.parts[p].triangles);
  }
}

TEST(PartMeshes, RefusesRangesOutsideTheSystemAndUnreadableFiles) {
  const PartMeshes meshes = sample_parts(3, 0, 1);
  TriMesh rest{meshes.parts[0].rest_positions, meshes.parts[0].triangles};
  EXPECT_THROW(split_into_parts(rest.vertices, rest, {{"sheet", PartKind::shell, 0, 10, 0, 8}}),
               std::invalid_argument);
  // A range cutting the sheet's triangles from some of their vertices.
  EXPECT_THROW(split_into_parts(rest.vertices, rest, {{"half", PartKind::shell, 0, 4, 0, 8}}),
               std::invalid_argument);
  const fs::path dir = test::fresh_temp_dir("part_meshes");
  test::write_file(dir / "not.h5", "not HDF5");
  for (const fs::path& file : {dir / "missing.h5", dir / "not.h5"}) {
    try {
      read_part_meshes(file);
      FAIL() << file << " was read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    }
  }
}

TEST(Xdmf, SidecarsMatchTheirHdf5Files) {
  const Job job = write_job();
  const SidecarSummary summary = validate_sidecar(job.dir / "job.xdmf");
  EXPECT_TRUE(summary.problems.empty()) << ::testing::PrintToString(summary.problems);
  EXPECT_EQ(summary.uniform_grids, 3 * 2);  // a grid per part and step
  // Triangles, positions, rest positions and displacement per grid.
  EXPECT_EQ(summary.hdf_items, 3 * 2 * 4);
  EXPECT_EQ(summary.times, (std::vector<std::string>{"0", "1", "2"}));
  const std::string xml = read_file(job.dir / "job.xdmf");
  EXPECT_NE(xml.find(R"(<Xdmf Version="3.0">)"), std::string::npos);
  EXPECT_NE(xml.find(R"(CollectionType="Temporal")"), std::string::npos);
  EXPECT_NE(
      xml.find(R"(<Grid Name="level1_frame2" GridType="Collection" CollectionType="Spatial">)"),
      std::string::npos);
  EXPECT_NE(xml.find(R"(<Grid Name="the ball" GridType="Uniform">)"), std::string::npos);
  for (const fs::path& part : part_sidecars(job)) {
    SCOPED_TRACE(part);
    const SidecarSummary own = validate_sidecar(part);
    EXPECT_TRUE(own.problems.empty()) << ::testing::PrintToString(own.problems);
    EXPECT_EQ(own.uniform_grids, 3);
    EXPECT_EQ(own.hdf_items, 3 * 4);
    EXPECT_EQ(own.times, summary.times);
  }
}

// Every block, step and array as meshio, a reader independent of this code, sees them.
TEST(Xdmf, MeshioReadsEveryPartAtEveryStep) {
  const Job job = write_job();
  const std::vector<fs::path> parts = part_sidecars(job);
  EXPECT_EQ(parts[1].filename(), "job.the_ball.xdmf");
  const nlohmann::json read = test::read_with_meshio(job.dir / "job.xdmf", parts);
  EXPECT_TRUE(read["mismatches"].empty()) << read["mismatches"].dump();
  ASSERT_EQ(read["blocks"].size(), 3u);
  for (std::size_t step = 0; step < 3; ++step) {
    const nlohmann::json& block = read["blocks"][step];
    EXPECT_EQ(block["time"], static_cast<double>(step));
    EXPECT_EQ(block["grids"], (nlohmann::json{"sheet", "the ball"}));
  }
  EXPECT_EQ(read["blocks"][2]["name"], "level1_frame2");

  ASSERT_EQ(read["parts"].size(), 2u);
  for (std::size_t p = 0; p < 2; ++p) {
    const nlohmann::json& series = read["parts"][p];
    ASSERT_EQ(series["steps"], 3);
    for (std::size_t step = 0; step < 3; ++step) {
      SCOPED_TRACE(::testing::Message() << "part " << p << " step " << step);
      const PartMesh& expected = job.meshes[step].parts[p];
      const nlohmann::json& frame = series["frames"][step];
      EXPECT_EQ(frame["time"], static_cast<double>(step));
      EXPECT_EQ(frame["cell_types"], (nlohmann::json{"triangle"}));
      test::expect_rows_near(frame["points"], expected.positions, 0.0);
      test::expect_rows_near(frame["triangles"], expected.triangles, 0.0);
      const nlohmann::json& data = frame["point_data"];
      std::vector<std::string> names;
      for (const auto& [name, values] : data.items()) names.push_back(name);
      EXPECT_EQ(names, (std::vector<std::string>{"displacement", "rest_position"}));
      test::expect_rows_near(data["rest_position"], expected.rest_positions, 0.0);
      if (p == 1) {
        // The collider moved rigidly: every vertex by the scripted translation.
        const Positions translation =
            ball_translation(job.meshes[step].frame).replicate(expected.positions.rows(), 1);
        test::expect_rows_near(data["displacement"], translation, 1e-15);
      } else {
        test::expect_rows_near(data["displacement"],
                               Positions(expected.positions - expected.rest_positions), 0.0);
      }
    }
  }
  // Each level's own mesh: level 1's sheet is the finer one.
  EXPECT_EQ(read["parts"][0]["frames"][0]["points"].size(), 9u);
  EXPECT_EQ(read["parts"][0]["frames"][2]["points"].size(), 25u);
}

// The validator itself must catch a sidecar that disagrees with its files.
TEST(Xdmf, ValidatorCatchesWrongCountsAndMissingFiles) {
  Job job = write_job();
  job.entries[1].parts[0].vertex_count += 1;
  job.entries[2].file = "parts/missing.h5";
  write_xdmf(job.dir / "wrong.xdmf", job.entries);
  const SidecarSummary summary = validate_sidecar(job.dir / "wrong.xdmf");
  // Positions, rest positions and displacement of entry 1's sheet, and the eight items of
  // entry 2.
  EXPECT_EQ(summary.problems.size(), 3u + 8u) << ::testing::PrintToString(summary.problems);
}

TEST(Xdmf, WritesAtomicallyAndRefusesUnreferenceableNamesAndChangingParts) {
  Job job = write_job();
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(job.dir))
    names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"job.sheet.xdmf", "job.the_ball.xdmf", "job.xdmf",
                                             "level0_frame1.h5", "level0_frame2.h5", "parts"}));
  const auto expect_refused = [&](std::vector<XdmfEntry> entries, const std::string& expected) {
    try {
      write_xdmf(job.dir / "bad.xdmf", entries);
      FAIL() << "entries with " << expected << " were accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("bad.xdmf"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(job.dir / "bad.xdmf"));
    EXPECT_FALSE(fs::exists(job.dir / "bad.sheet.xdmf"));
  };
  std::vector<XdmfEntry> colon = job.entries;
  colon[0].file = "C:level0.h5";
  expect_refused(colon, "C:level0.h5");
  std::vector<XdmfEntry> renamed = job.entries;
  renamed[2].parts[1].name = "plate";
  expect_refused(renamed, "parts differ");
}

TEST(Xdmf, PartSidecarNamesAreFileNamesAndDistinct) {
  const std::vector<fs::path> paths =
      part_sidecar_paths("/runs/7/job.xdmf", {"sheet", "a/b", "a_b", "a b", "x_2", "x"});
  std::vector<std::string> names;
  for (const fs::path& path : paths) {
    EXPECT_EQ(path.parent_path(), "/runs/7");
    names.push_back(path.filename());
  }
  EXPECT_EQ(names, (std::vector<std::string>{"job.sheet.xdmf", "job.a_b.xdmf", "job.a_b_2.xdmf",
                                             "job.a_b_3.xdmf", "job.x_2.xdmf", "job.x.xdmf"}));
}

}  // namespace
}  // namespace psq

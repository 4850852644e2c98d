#include "engine/mesh/mesh_io.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>

#include "engine/core/error.hpp"
#include "engine/mesh/generators.hpp"
#include "engine/mesh/topology.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

// Runs `read`, expecting an InputError whose message contains every one of `parts`.
template <class F>
void expect_input_error(F&& read, const std::vector<std::string>& parts) {
  try {
    read();
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    for (const std::string& part : parts)
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
          << "message '" << e.what() << "' lacks '" << part << "'";
  }
}

// Writes `text` to a fresh file `name` and expects read_mesh to reject it with a message
// naming the file and, when line > 0, "name:line:".
void expect_rejected(const std::string& name, const std::string& text, long line,
                     const std::string& topic = "") {
  const auto path = test::write_file(test::fresh_temp_dir("bad-mesh") / name, text);
  std::vector<std::string> parts{line > 0 ? path.string() + ":" + std::to_string(line) + ":"
                                          : path.string()};
  if (!topic.empty()) parts.push_back(topic);
  SCOPED_TRACE(name + ":\n" + text);
  expect_input_error([&] { read_mesh(path); }, parts);
}

// A closed mesh with irrational coordinates, so that round trips must be exact to pass.
TriMesh coarse_sphere() { return make_sphere({.radius = 0.7, .edge_length = 0.45}); }

TriMesh unit_square() {
  TriMesh m;
  m.vertices.resize(4, 3);
  m.vertices << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  m.triangles.resize(2, 3);
  m.triangles << 0, 1, 2, 0, 2, 3;
  return m;
}

void expect_same_mesh(const TriMesh& a, const TriMesh& b) {
  ASSERT_EQ(a.vertex_count(), b.vertex_count());
  ASSERT_EQ(a.triangle_count(), b.triangle_count());
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.triangles, b.triangles);
}

// ---- binary PLY by hand ----------------------------------------------------------------------

template <class T>
void append(std::string& bytes, T value, std::endian order) {
  char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  if (order != std::endian::native) std::reverse(raw, raw + sizeof(T));
  bytes.append(raw, sizeof(T));
}

// The unit square as binary PLY in the given byte order: float coordinates with an extra
// "confidence" property, int-counted uint index lists, and an extra "edge" element between.
std::string binary_square_ply(std::endian order) {
  std::string bytes = std::string("ply\nformat ") +
                      (order == std::endian::big ? "binary_big_endian" : "binary_little_endian") +
                      " 1.0\ncomment hand-written\nelement vertex 4\nproperty float x\n"
                      "property float y\nproperty float z\nproperty double confidence\n"
                      "element edge 1\nproperty int vertex1\nproperty int vertex2\n"
                      "element face 2\nproperty list int uint vertex_indices\nend_header\n";
  const float xy[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (const auto& p : xy) {
    append<float>(bytes, p[0], order);
    append<float>(bytes, p[1], order);
    append<float>(bytes, 0.0f, order);
    append<double>(bytes, 0.5, order);
  }
  append<std::int32_t>(bytes, 0, order);
  append<std::int32_t>(bytes, 2, order);
  for (const auto& face : {std::array<std::uint32_t, 3>{0, 1, 2}, {0, 2, 3}}) {
    append<std::int32_t>(bytes, 3, order);
    for (std::uint32_t v : face) append<std::uint32_t>(bytes, v, order);
  }
  return bytes;
}

// ---- round trips -----------------------------------------------------------------------------

TEST(MeshIo, RoundTripIsExactForEveryFormat) {
  const TriMesh mesh = coarse_sphere();
  const auto dir = test::fresh_temp_dir("mesh-io");
  for (const char* name : {"m.obj", "m.ply", "m.off", "UPPER.OBJ"}) {
    SCOPED_TRACE(name);
    write_mesh(dir / name, mesh);
    expect_same_mesh(read_mesh(dir / name), mesh);
  }
}

TEST(MeshIo, PlyIsWrittenBinaryLittleEndian) {
  const auto path = test::fresh_temp_dir("mesh-io") / "square.ply";
  write_mesh(path, unit_square());
  const std::string bytes = test::read_file(path);
  EXPECT_NE(bytes.find("format binary_little_endian 1.0\n"), std::string::npos);
  // Header, then 4 vertices × 3 doubles and 2 faces × (1 count byte + 3 ints).
  const std::size_t data = bytes.find("end_header\n") + std::string("end_header\n").size();
  EXPECT_EQ(bytes.size() - data, 4u * 3 * 8 + 2u * (1 + 3 * 4));
  std::string one;
  append<double>(one, 1.0, std::endian::little);
  EXPECT_EQ(bytes.substr(data + 3 * 8, 8), one);  // x of vertex 1
}

TEST(MeshIo, WriteLeavesNoTemporaryAndReplacesTheFile) {
  const auto dir = test::fresh_temp_dir("mesh-io");
  write_mesh(dir / "m.off", coarse_sphere());
  write_mesh(dir / "m.off", unit_square());
  expect_same_mesh(read_mesh(dir / "m.off"), unit_square());
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir),
                          std::filesystem::directory_iterator()),
            1);
}

TEST(MeshIo, UnwritableDirectoryNamesThePath) {
  const auto dir = test::fresh_temp_dir("mesh-io");
  // A regular file as the parent directory cannot be written into, even by root.
  const auto blocker = test::write_file(dir / "not-a-directory", "x");
  const auto target = blocker / "m.obj";
  expect_input_error([&] { write_mesh(target, unit_square()); }, {target.string()});
  expect_input_error([&] { write_mesh(dir / "m.stl", unit_square()); }, {"m.stl", "extension"});
}

TEST(MeshIo, WritingNonFiniteCoordinatesIsRefused) {
  TriMesh mesh = unit_square();
  mesh.vertices(2, 1) = std::numeric_limits<double>::quiet_NaN();
  const auto path = test::fresh_temp_dir("mesh-io") / "nan.obj";
  EXPECT_THROW(write_mesh(path, mesh), NumericalError);
  EXPECT_FALSE(std::filesystem::exists(path));
}

// ---- OBJ -------------------------------------------------------------------------------------

TEST(MeshIo, ObjSlashFormsNegativeIndicesAndIgnoredStatements) {
  const auto path = test::write_file(test::fresh_temp_dir("obj") / "forms.obj",
                                     "# comment\r\n"
                                     "mtllib none.mtl\n"
                                     "o square\n"
                                     "v 0 0 0\n"
                                     "v 1 0 0\n"
                                     "v +1 1 0 1.0\n"
                                     "vt 0 0\nvt 1 0\nvt 1 1\n"
                                     "vn 0 0 1\n"
                                     "g top\ns off\nusemtl red\n"
                                     "f 1/1/1 2/2/1 3/3/1\n"
                                     "v 0 1 0  # trailing comment\n"
                                     "f -4//1 -2//1 -1//1\n"
                                     "v 5 5 5\n");  // unreferenced vertices are allowed
  const TriMesh mesh = read_mesh(path);
  ASSERT_EQ(mesh.vertex_count(), 5);
  ASSERT_EQ(mesh.triangle_count(), 2);
  EXPECT_EQ(mesh.triangles.row(0), Eigen::RowVector3i(0, 1, 2));
  EXPECT_EQ(mesh.triangles.row(1), Eigen::RowVector3i(0, 2, 3));
  EXPECT_EQ(mesh.vertices.row(2), Eigen::RowVector3d(1, 1, 0));
  EXPECT_EQ(mesh.vertices.row(4), Eigen::RowVector3d(5, 5, 5));
}

TEST(MeshIo, ObjErrorsNameFileAndLine) {
  const std::string square = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";
  expect_rejected("quad.obj", square + "f 1 2 3 4\n", 5, "4 vertices");
  expect_rejected("two.obj", square + "f 1 2\n", 5, "2 vertices");
  expect_rejected("number.obj", "v 0 0 0\nv 1 0x1 0\n", 2, "0x1");
  expect_rejected("short.obj", "v 0 0\n", 1, "coordinates");
  expect_rejected("nan.obj", square + "v nan 0 0\nf 1 2 3\n", 5, "non-finite");
  expect_rejected("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 -inf 0\nf 1 2 3\n", 3, "non-finite");
  expect_rejected("huge.obj", "v 0 0 1e999\n", 1, "out of range");
  expect_rejected("range.obj", square + "f 1 2 3\n\nf 1 3 9\n", 7, "vertex 9");
  expect_rejected("zero.obj", square + "f 0 1 2\n", 5, "index 0");
  expect_rejected("relative.obj", square + "f -1 -2 -5\n", 5, "-5");
  expect_rejected("index.obj", square + "f 1 2 three\n", 5, "three");
  expect_rejected("repeat.obj", square + "f 1 2 3\nf 1 3 3\n", 6, "repeats vertex 3");
  expect_rejected("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 4\nf 1 3 2\n", 6,
                  "degenerate");
  expect_rejected("nothing.obj", "# no faces\nv 0 0 0\n", 0, "empty");
  expect_rejected("empty.obj", "", 0, "empty");
}

TEST(MeshIo, ConnectivityErrorsNameTheFile) {
  const std::string square = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\n";
  expect_rejected("fin.obj", square + "f 1 2 3\nf 1 3 4\nf 3 1 5\n", 0, "non-manifold");
  expect_rejected("flip.obj", square + "f 1 2 3\nf 1 4 3\n", 0, "orient");
}

TEST(MeshIo, UnreadableFilesAndUnknownExtensions) {
  const auto dir = test::fresh_temp_dir("mesh-io");
  expect_input_error([&] { read_mesh(dir / "missing.obj"); }, {"missing.obj", "no such mesh file"});
  std::filesystem::create_directory(dir / "folder.obj");
  expect_input_error([&] { read_mesh(dir / "folder.obj"); }, {"folder.obj"});
  const auto stl = test::write_file(dir / "mesh.stl", "solid x\nendsolid x\n");
  expect_input_error([&] { read_mesh(stl); }, {"mesh.stl", "extension"});
  const auto bare = test::write_file(dir / "mesh", "v 0 0 0\n");
  expect_input_error([&] { read_mesh(bare); }, {bare.string(), "extension"});
}

TEST(MeshIo, ReadsTheSharedBunny) {
  const TriMesh bunny = read_mesh(test::shared_dir() / "data/meshes/bunny.obj");
  EXPECT_EQ(bunny.vertex_count(), 1839);
  EXPECT_EQ(bunny.triangle_count(), 3674);
  const MeshTopology topology = MeshTopology::build(bunny);
  EXPECT_TRUE(topology.boundary_loops.empty());
  EXPECT_EQ(2 * topology.edges.size(), 3u * bunny.triangle_count());  // closed: 2 faces per edge
}

// ---- OFF -------------------------------------------------------------------------------------

TEST(MeshIo, OffWithCommentsColoursAndCountsOnTheHeaderLine) {
  const auto dir = test::fresh_temp_dir("off");
  const TriMesh a = read_mesh(test::write_file(dir / "a.off",
                                               "OFF\n# square\n4 2 5\n\n0 0 0\n1 0 0\n1 1 0\n"
                                               "0 1 0\n3 0 1 2 255 0 0\n3 0 2 3\n"));
  expect_same_mesh(a, unit_square());
  const TriMesh b = read_mesh(test::write_file(dir / "b.off",
                                               "OFF 4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n"
                                               "3 0 1 2\n3 0 2 3\n"));
  expect_same_mesh(b, unit_square());
}

TEST(MeshIo, OffErrorsNameFileAndLine) {
  const std::string header = "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n";
  expect_rejected("header.off", "OFFX\n", 1, "OFF");
  expect_rejected("counts.off", "OFF\n4 x 0\n", 2, "face count");
  expect_rejected("negative.off", "OFF\n-4 1 0\n", 2, "out of range");
  expect_rejected("quad.off", header + "4 0 1 2 3\n", 7, "4 vertices");
  expect_rejected("few.off", header + "3 0 1\n", 7, "indices");
  expect_rejected("range.off", header + "3 0 1 4\n", 7, "vertex 4");
  expect_rejected("negindex.off", header + "3 0 -1 2\n", 7, "-1");
  expect_rejected("nan.off", "OFF\n3 1 0\n0 0 0\n1 NaN 0\n0 1 0\n3 0 1 2\n", 4, "non-finite");
  expect_rejected("cut.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n", 4, "end of file");
}

// ---- PLY -------------------------------------------------------------------------------------

TEST(MeshIo, HandWrittenAsciiPly) {
  const auto path = test::write_file(test::fresh_temp_dir("ply") / "square.ply",
                                     "ply\r\nformat ascii 1.0\r\ncomment by hand\r\n"
                                     "obj_info nothing\r\n"
                                     "element vertex 4\r\nproperty double x\r\n"
                                     "property float y\r\nproperty uchar red\r\n"
                                     "property double z\r\n"
                                     "element face 2\r\nproperty uchar flags\r\n"
                                     "property list uchar int vertex_index\r\n"
                                     "property list uchar float texcoord\r\n"
                                     "end_header\r\n"
                                     "0 0 255 0\r\n1 0 0 0\r\n1 1 0 0\r\n0 1 0 0\r\n"
                                     "7 3 0 1 2 2 0.5 0.5\r\n0 3 0 2 3 0\r\n");
  expect_same_mesh(read_mesh(path), unit_square());
}

TEST(MeshIo, HandWrittenBinaryPlyInBothByteOrders) {
  const auto dir = test::fresh_temp_dir("ply");
  for (std::endian order : {std::endian::big, std::endian::little}) {
    const auto path = test::write_file(dir / "square.ply", binary_square_ply(order));
    expect_same_mesh(read_mesh(path), unit_square());
  }
}

TEST(MeshIo, PlyErrorsNameFileAndLineOrElement) {
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  const std::string square = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n";
  expect_rejected("magic.ply", "plx\n", 1, "PLY");
  expect_rejected("format.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n", 2, "format");
  expect_rejected("type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty real x\n", 4,
                  "real");
  expect_rejected("noend.ply", "ply\nformat ascii 1.0\nelement vertex 0\n", 3, "end_header");
  expect_rejected("noz.ply",
                  "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                  "property float y\nend_header\n0 0\n",
                  3, "'z'");
  expect_rejected("quad.ply", head + square + "4 0 1 2 3\n", 14, "4 vertices");
  expect_rejected("range.ply", head + square + "3 0 1 4\n", 14, "vertex 4");
  expect_rejected("nan.ply", head + "0 0 0\n1 nan 0\n1 1 0\n0 1 0\n3 0 1 2\n", 11, "non-finite");
  expect_rejected("word.ply", head + "0 0 0\n1 0 0\n1 1 zero\n", 12, "zero");
  expect_rejected("extra.ply", head + square + "3 0 1 2 9\n", 14, "values");
  expect_rejected("cut.ply", head + square, 13, "end of file");
  expect_rejected("noface.ply",
                  "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                  "property float y\nproperty float z\nend_header\n0 0 0\n",
                  0, "empty");
}

// Found by fuzz_ply: a second 'vertex' element with x, y, z further along its properties
// than the first's made the reader index past the first element's values (heap overflow).
TEST(MeshIo, PlyElementDeclaredTwiceIsRejectedAtItsLine) {
  const std::string xyz = "property float x\nproperty float y\nproperty float z\n";
  expect_rejected("twovertex.ply",
                  "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz +
                      "element vertex 1\nproperty float a\n" + xyz +
                      "end_header\n0 0 0\n1 0 0\n0 1 0\n9 1 2 3\n",
                  7, "element 'vertex' is declared twice");
  expect_rejected("twoface.ply",
                  "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz +
                      "element face 1\nproperty list uchar int vertex_indices\n"
                      "element face 1\nproperty int a\nproperty list uchar int vertex_indices\n"
                      "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n7 3 0 1 2\n",
                  9, "element 'face' is declared twice");
}

TEST(MeshIo, BinaryPlyErrorsNameTheElement) {
  const std::string good = binary_square_ply(std::endian::little);
  // Cut inside face 1's index list.
  expect_rejected("cut.ply", good.substr(0, good.size() - 2), 0, "face 1");
  expect_rejected("cut-vertex.ply", good.substr(0, good.find("end_header\n") + 11 + 30), 0,
                  "vertex 1");
  // Make the first triangle (0, 1, 2) collinear by moving vertex 2 to (2, 0).
  std::string moved;
  append<float>(moved, 2.0f, std::endian::little);
  append<float>(moved, 0.0f, std::endian::little);
  std::string flat = good;
  flat.replace(good.find("end_header\n") + 11 + 2 * 20, moved.size(), moved);
  expect_rejected("flat.ply", flat, 0, "triangle 0 is degenerate");
}

// ---- robustness ------------------------------------------------------------------------------

// Random truncations and byte mutations of valid files must be read or rejected with
// InputError; any other exception fails the test, and a crash fails the whole executable.
TEST(MeshIo, FuzzedFilesThrowInputErrorOrRead) {
  const auto dir = test::fresh_temp_dir("fuzz");
  // Seeds are formatted here rather than by write_mesh, whose fsyncs are slow on a busy disk.
  const TriMesh mesh = make_sphere({.radius = 1.0, .edge_length = 0.6});
  std::ostringstream obj, off;
  obj.precision(17);
  off.precision(17);
  off << "OFF\n" << mesh.vertex_count() << " " << mesh.triangle_count() << " 0\n";
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    obj << "v " << mesh.vertices.row(v) << "\n";
    off << mesh.vertices.row(v) << "\n";
  }
  for (int f = 0; f < mesh.triangle_count(); ++f) {
    obj << "f " << (mesh.triangles.row(f).array() + 1) << "\n";
    off << "3 " << mesh.triangles.row(f) << "\n";
  }
  std::vector<std::pair<std::string, std::string>> seeds{
      {"seed.obj", obj.str()},
      {"seed.off", off.str()},
      {"big.ply", binary_square_ply(std::endian::big)},
      {"little.ply", binary_square_ply(std::endian::little)}};
  const std::string ascii_ply =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
      "property float y\nproperty float z\nelement face 2\n"
      "property list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n";
  seeds.emplace_back("ascii.ply", ascii_ply);

  std::mt19937 rng(12345);
  const std::string alphabet = "0123456789 -+.eE\n/#nafvply\xff";
  int rejected = 0, accepted = 0;
  for (const auto& [name, bytes] : seeds) {
    for (int trial = 0; trial < 400; ++trial) {
      std::string fuzzed = bytes;
      std::uniform_int_distribution<std::size_t> position(0, fuzzed.size() - 1);
      if (trial % 3 == 0) {
        fuzzed.resize(position(rng));
      } else {
        const int edits = 1 + static_cast<int>(rng() % 4);
        for (int e = 0; e < edits; ++e)
          fuzzed[position(rng)] =
              trial % 3 == 1 ? static_cast<char>(rng() % 256) : alphabet[rng() % alphabet.size()];
      }
      // A new name per trial: rewriting one file makes ext4 flush it on close, which is slow.
      const auto path = test::write_file(dir / (std::to_string(trial) + name), fuzzed);
      try {
        read_mesh(path);
        ++accepted;
      } catch (const InputError&) {
        ++rejected;
      } catch (const std::exception& e) {
        ADD_FAILURE() << name << " trial " << trial << ": unexpected " << e.what();
      }
    }
  }
  EXPECT_GT(rejected, 0);
  EXPECT_GT(accepted, 0);
}

}  // namespace
}  // namespace psq

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
#include "support/test_paths.hpp"

namespace psq {
namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string trimmed(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\n");
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(" \t\n") - first + 1);
}

std::map<std::string, std::string> xml_attributes(const std::string& tag_body) {
  static const std::regex attribute(R"re((\w+)="([^"]*)")re");
  std::map<std::string, std::string> values;
  for (std::sregex_iterator it(tag_body.begin(), tag_body.end(), attribute), end; it != end; ++it)
    values[(*it)[1]] = (*it)[2];
  return values;
}

std::vector<hsize_t> parse_dimensions(const std::string& text) {
  std::vector<hsize_t> dims;
  std::istringstream in(text);
  for (hsize_t d; in >> d;) dims.push_back(d);
  return dims;
}

/// Problems of an element structure that is not well nested (every open tag closed in order).
std::vector<std::string> nesting_problems(const std::string& xml) {
  static const std::regex tag(R"re(<(/?)(\w+)[^>]*?(/?)>)re");
  std::vector<std::string> open, problems;
  for (std::sregex_iterator it(xml.begin(), xml.end(), tag), end; it != end; ++it) {
    const bool closing = (*it)[1].length() > 0, self_closing = (*it)[3].length() > 0;
    const std::string name = (*it)[2];
    if (closing) {
      if (open.empty() || open.back() != name) problems.push_back("unexpected </" + name + ">");
      else open.pop_back();
    } else if (!self_closing) {
      open.push_back(name);
    }
  }
  for (const std::string& name : open) problems.push_back("unclosed <" + name + ">");
  return problems;
}

/// Checks one DataItem that points into an HDF5 file ("file.h5:/dataset") against that file:
/// the dataset exists, with the declared dimensions and number type, via the HDF5 C API.
std::vector<std::string> hdf_item_problems(const fs::path& sidecar_dir,
                                           const std::map<std::string, std::string>& item,
                                           const std::string& reference) {
  const std::size_t colon = reference.find(':');
  if (colon == std::string::npos) return {"no ':' in " + reference};
  const fs::path file = sidecar_dir / reference.substr(0, colon);
  const std::string dataset = reference.substr(colon + 1);
  if (H5Fis_hdf5(file.c_str()) <= 0) return {"not an HDF5 file: " + file.string()};
  std::vector<std::string> problems;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t d = H5Lexists(f, dataset.c_str(), H5P_DEFAULT) > 0
                      ? H5Dopen2(f, dataset.c_str(), H5P_DEFAULT)
                      : H5I_INVALID_HID;
  if (d < 0) {
    problems.push_back("missing dataset " + reference);
  } else {
    const hid_t space = H5Dget_space(d);
    std::vector<hsize_t> dims(static_cast<std::size_t>(H5Sget_simple_extent_ndims(space)));
    H5Sget_simple_extent_dims(space, dims.data(), nullptr);
    if (dims != parse_dimensions(item.at("Dimensions")))
      problems.push_back(reference + ": declared Dimensions " + item.at("Dimensions") +
                         " differ from the dataset");
    const hid_t type = H5Dget_type(d);
    const H5T_class_t expected_class =
        item.at("NumberType") == "Float" ? H5T_FLOAT : item.at("NumberType") == "Int"
                                                           ? H5T_INTEGER
                                                           : H5T_NO_CLASS;
    if (H5Tget_class(type) != expected_class ||
        H5Tget_size(type) != std::stoul(item.at("Precision")) ||
        (expected_class == H5T_INTEGER && H5Tget_sign(type) != H5T_SGN_2))
      problems.push_back(reference + ": declared NumberType " + item.at("NumberType") +
                         " Precision " + item.at("Precision") + " differ from the dataset");
    H5Tclose(type);
    H5Sclose(space);
    H5Dclose(d);
  }
  H5Fclose(f);
  return problems;
}

struct SidecarSummary {
  std::vector<std::string> problems;
  int hdf_items = 0;
  int uniform_grids = 0;
  std::vector<std::string> times;
};

/// Validates a sidecar: nesting, every DataItem (HDF ones against their files, inline ones by
/// their number of values), and each Topology's element count against its DataItem.
SidecarSummary validate_sidecar(const fs::path& sidecar) {
  const std::string xml = read_text(sidecar);
  SidecarSummary summary;
  summary.problems = nesting_problems(xml);
  static const std::regex item(R"re(<DataItem([^>]*)>([^<]*)</DataItem>)re");
  for (std::sregex_iterator it(xml.begin(), xml.end(), item), end; it != end; ++it) {
    const auto attributes = xml_attributes((*it)[1]);
    const std::string content = trimmed((*it)[2]);
    if (attributes.at("Format") == "HDF") {
      ++summary.hdf_items;
      for (std::string& p : hdf_item_problems(sidecar.parent_path(), attributes, content))
        summary.problems.push_back(std::move(p));
    } else {
      const auto dims = parse_dimensions(attributes.at("Dimensions"));
      const auto declared =
          std::accumulate(dims.begin(), dims.end(), hsize_t{1}, std::multiplies{});
      std::istringstream in(content);
      const auto count = std::distance(std::istream_iterator<std::string>(in),
                                       std::istream_iterator<std::string>());
      if (static_cast<hsize_t>(count) != declared)
        summary.problems.push_back("inline DataItem '" + content + "' differs from its Dimensions");
    }
  }
  static const std::regex topology(
      R"re(<Topology[^>]*NumberOfElements="(\d+)"[^>]*>\s*<DataItem[^>]*Dimensions="(\d+) 3")re");
  for (std::sregex_iterator it(xml.begin(), xml.end(), topology), end; it != end; ++it)
    if ((*it)[1] != (*it)[2]) summary.problems.push_back("NumberOfElements differs from DataItem");
  static const std::regex grid(R"re(GridType="Uniform")re");
  summary.uniform_grids = static_cast<int>(
      std::distance(std::sregex_iterator(xml.begin(), xml.end(), grid), std::sregex_iterator()));
  static const std::regex time(R"re(<Time Value="([^"]*)"/>)re");
  for (std::sregex_iterator it(xml.begin(), xml.end(), time), end; it != end; ++it)
    summary.times.push_back((*it)[1]);
  return summary;
}

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
  const std::string xml = read_text(job.dir / "job.xdmf");
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

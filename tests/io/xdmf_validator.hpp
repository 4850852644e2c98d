#pragma once
// Validation of an XDMF sidecar against its HDF5 files, for the io and runner tests: every
// DataItem that points into a file names an existing dataset of the declared shape and type.

#include <hdf5.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <numeric>
#include <regex>
#include <sstream>
#include <string>
#include <vector>
#include "support/test_paths.hpp"

namespace psq::test {

inline std::string trimmed(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\n");
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(" \t\n") - first + 1);
}

inline std::map<std::string, std::string> xml_attributes(const std::string& tag_body) {
  static const std::regex attribute(R"re((\w+)="([^"]*)")re");
  std::map<std::string, std::string> values;
  for (std::sregex_iterator it(tag_body.begin(), tag_body.end(), attribute), end; it != end; ++it)
    values[(*it)[1]] = (*it)[2];
  return values;
}

inline std::vector<hsize_t> parse_dimensions(const std::string& text) {
  std::vector<hsize_t> dims;
  std::istringstream in(text);
  for (hsize_t d; in >> d;) dims.push_back(d);
  return dims;
}

/// Problems of an element structure that is not well nested (every open tag closed in order).
inline std::vector<std::string> nesting_problems(const std::string& xml) {
  static const std::regex tag(R"re(<(/?)(\w+)[^>]*?(/?)>)re");
  std::vector<std::string> open, problems;
  for (std::sregex_iterator it(xml.begin(), xml.end(), tag), end; it != end; ++it) {
    const bool closing = (*it)[1].length() > 0, self_closing = (*it)[3].length() > 0;
    const std::string name = (*it)[2];
    if (closing) {
      if (open.empty() || open.back() != name)
        problems.push_back("unexpected </" + name + ">");
      else
        open.pop_back();
    } else if (!self_closing) {
      open.push_back(name);
    }
  }
  for (const std::string& name : open) problems.push_back("unclosed <" + name + ">");
  return problems;
}

/// Checks one DataItem that points into an HDF5 file ("file.h5:/dataset") against that file:
/// the dataset exists, with the declared dimensions and number type, via the HDF5 C API.
inline std::vector<std::string> hdf_item_problems(const std::filesystem::path& sidecar_dir,
                                                  const std::map<std::string, std::string>& item,
                                                  const std::string& reference) {
  const std::size_t colon = reference.find(':');
  if (colon == std::string::npos) return {"no ':' in " + reference};
  const std::filesystem::path file = sidecar_dir / reference.substr(0, colon);
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
    const H5T_class_t expected_class = item.at("NumberType") == "Float" ? H5T_FLOAT
                                       : item.at("NumberType") == "Int" ? H5T_INTEGER
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
inline SidecarSummary validate_sidecar(const std::filesystem::path& sidecar) {
  const std::string xml = test::read_file(sidecar);
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

}  // namespace psq::test

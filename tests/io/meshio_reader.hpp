#pragma once
// A job's XDMF sidecars as meshio reads them (tests/io/read_xdmf_with_meshio.py, run by Debian's
// python3 with python3-meshio, installed by scripts/setup.sh), for the io and runner tests.

#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/mesh/tri_mesh.hpp"
#include "support/run_process.hpp"
#include "support/test_paths.hpp"

namespace psq::test {

/// Debian's interpreter, where apt installs python3-meshio (another python3 on PATH may lack it).
inline constexpr const char* kDebianPython = "/usr/bin/python3";

/// The script's JSON output for the sidecar `job_xdmf` and the per-part sidecars `part_xdmfs`.
/// Throws std::runtime_error with the script's stderr when it fails.
inline nlohmann::json read_with_meshio(const std::filesystem::path& job_xdmf,
                                       const std::vector<std::filesystem::path>& part_xdmfs) {
  if (!std::filesystem::exists(kDebianPython))
    throw std::runtime_error(std::string(kDebianPython) + " is missing: run scripts/setup.sh");
  std::vector<std::string> arguments{(source_dir() / "tests/io/read_xdmf_with_meshio.py").string(),
                                     job_xdmf.string()};
  for (const std::filesystem::path& part : part_xdmfs) arguments.push_back(part.string());
  const ProcessResult result = run_process(kDebianPython, arguments);
  if (result.exit_code != 0)
    throw std::runtime_error(
        "read_xdmf_with_meshio.py failed (python3-meshio and python3-h5py "
        "come with scripts/setup.sh): " +
        result.errors);
  return nlohmann::json::parse(result.output);
}

/// Expects the rows of `json` (a list of triples) to equal `expected` within `tolerance`.
template <class Matrix>
void expect_rows_near(const nlohmann::json& json, const Matrix& expected, double tolerance) {
  ASSERT_EQ(json.size(), static_cast<std::size_t>(expected.rows()));
  for (Eigen::Index r = 0; r < expected.rows(); ++r)
    for (Eigen::Index c = 0; c < 3; ++c)
      ASSERT_NEAR(json[r][c].get<double>(), expected(r, c), tolerance) << "row " << r;
}

}  // namespace psq::test

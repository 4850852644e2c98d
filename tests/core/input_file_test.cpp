#include "engine/core/input_file.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "engine/core/error.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

std::string error_of(const std::filesystem::path& path) {
  try {
    read_input_file(path, "scene file");
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(InputFile, ReadsEveryByteIncludingNulAndCarriageReturns) {
  const auto dir = test::fresh_temp_dir("input_file");
  const std::string bytes("a\r\nb\0c", 6);
  std::ofstream(dir / "in.toml", std::ios::binary) << bytes;
  EXPECT_EQ(read_input_file(dir / "in.toml", "scene file"), bytes);
}

TEST(InputFile, AMissingPathOrADirectoryIsAnInputErrorNamingThePathAndTheKindOfFile) {
  const auto dir = test::fresh_temp_dir("input_file");
  const std::string missing = error_of(dir / "absent.toml");
  EXPECT_NE(missing.find((dir / "absent.toml").string()), std::string::npos) << missing;
  EXPECT_NE(missing.find("no such scene file"), std::string::npos) << missing;
  const std::string directory = error_of(dir);
  EXPECT_NE(directory.find(dir.string()), std::string::npos) << directory;
  EXPECT_NE(directory.find("the scene file is not a regular file"), std::string::npos)
      << directory;
}

}  // namespace
}  // namespace psq

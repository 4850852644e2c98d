#include "support/test_paths.hpp"

#include <unistd.h>

#include <atomic>
#include <fstream>
#include <iterator>

namespace psq::test {

std::filesystem::path source_dir() { return PSQ_SOURCE_DIR; }
std::filesystem::path shared_dir() { return PSQ_SHARED_DIR; }

std::filesystem::path fresh_temp_dir(const std::string& name) {
  static std::atomic<int> counter{0};
  auto dir = std::filesystem::path(PSQ_BINARY_DIR) / "test-tmp" /
             (name + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::filesystem::path write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  return path;
}

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace psq::test

#pragma once
// A small tmpfs mounted over a directory, for the full-disk and read-only tests: a real file
// system that answers writes with ENOSPC once it is full and with EROFS once it is remounted
// read-only, and that gets its space back when the test says so. Mounting needs
// CAP_SYS_ADMIN: the test suite runs as root (README, .ci/run), and a refused mount fails the
// test with the reason. Unmounted (lazily, so that an open file cannot keep it) on destruction.

#include <sys/mount.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

namespace psq::test {

class SmallFilesystem {
 public:
  /// Mounts a tmpfs of `bytes` over `dir` (created if needed, and empty).
  SmallFilesystem(std::filesystem::path dir, std::size_t bytes)
      : dir_(std::move(dir)), options_("size=" + std::to_string(bytes)) {
    std::filesystem::create_directories(dir_);
    if (::mount("tmpfs", dir_.c_str(), "tmpfs", 0, options_.c_str()) != 0)
      throw std::runtime_error("mount tmpfs on " + dir_.string() + ": " + std::strerror(errno) +
                               " (the full-disk tests need root or CAP_SYS_ADMIN)");
  }
  SmallFilesystem(const SmallFilesystem&) = delete;
  SmallFilesystem& operator=(const SmallFilesystem&) = delete;
  ~SmallFilesystem() { ::umount2(dir_.c_str(), MNT_DETACH); }

  /// Takes every free byte but `spare` with a filler file: a write of more than that fails
  /// with ENOSPC (midway through a file when `spare` is not 0).
  void fill(std::size_t spare = 0) const {
    {
      std::ofstream filler(filler_path(), std::ios::binary);
      const std::string block(4096, '\0');
      while (filler.write(block.data(), block.size())) {
      }
    }
    const std::uintmax_t size = std::filesystem::file_size(filler_path());
    std::filesystem::resize_file(filler_path(), size > spare ? size - spare : 0);
  }
  /// Gives the filler's space back.
  void free_space() const { std::filesystem::remove(filler_path()); }

  /// Remounts read-only (writes fail with EROFS) or read-write again.
  void set_read_only(bool read_only) const {
    const unsigned long flags = MS_REMOUNT | (read_only ? MS_RDONLY : 0);
    if (::mount("tmpfs", dir_.c_str(), "tmpfs", flags, options_.c_str()) != 0)
      throw std::runtime_error("remount " + dir_.string() + ": " + std::strerror(errno));
  }

 private:
  std::filesystem::path filler_path() const { return dir_ / ".filler"; }

  std::filesystem::path dir_;
  std::string options_;
};

}  // namespace psq::test

#pragma once
// A thin RAII layer over the HDF5 C API (Debian's serial HDF5 1.10). Every identifier has one
// owner that closes it; every failure throws Hdf5Error naming the file, the object and HDF5's
// own innermost reason. HDF5's default of printing error stacks to stderr is switched off the
// first time a file is created or opened here: the reason travels in the exception instead.
// Files are written on disk and read from an in-memory image of their bytes, so that a reader
// parses exactly the bytes it has checksummed. (Writing through an image is not an option:
// HDF5 1.10's H5Fget_file_image clears the superblock's status flags without updating its
// checksum, and the image no longer opens.)
// The serial library is not thread-safe: use these classes under library_mutex().

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <hdf5.h>

#include <algorithm>
#include <concepts>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "engine/core/error.hpp"

namespace psq::hdf5 {

/// An HDF5 call failed or an object is not what was asked for. The message reads
/// "file: /object: what went wrong (HDF5's reason)".
class Hdf5Error : public Error {
 public:
  using Error::Error;
};

/// The lock every user of the serial HDF5 library holds around its calls: files may be written
/// and read from any thread.
std::mutex& library_mutex();

/// Element types stored by this layer, each written in a fixed little-endian file type.
template <class T>
concept Element =
    std::same_as<T, double> || std::same_as<T, std::int32_t> || std::same_as<T, std::uint64_t>;

/// Owns one HDF5 identifier and closes it with the function for its kind (H5Fclose, H5Gclose…).
class Id {
 public:
  using Closer = herr_t (*)(hid_t);
  Id() = default;
  Id(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  Id(Id&& other) noexcept;
  Id& operator=(Id&& other) noexcept;
  Id(const Id&) = delete;
  Id& operator=(const Id&) = delete;
  ~Id() { close(); }

  [[nodiscard]] hid_t get() const { return id_; }
  [[nodiscard]] bool valid() const { return id_ >= 0; }
  /// Closes now (if open); false if HDF5 reported a failure.
  bool close() noexcept;

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer closer_ = nullptr;
};

/// A dataset read back: its shape (row-major dimensions) and its elements in order.
template <Element T>
struct Array {
  std::vector<hsize_t> shape;
  std::vector<T> values;
};

/// An open group (the root group of a file included): creates and reads sub-groups, datasets
/// and attributes. Attributes are scalars or strings; datasets are contiguous n-dimensional
/// arrays (possibly empty).
class Group {
 public:
  Group(Id id, std::string file, std::string path);

  [[nodiscard]] bool valid() const { return id_.valid(); }
  [[nodiscard]] const std::string& file_name() const { return file_; }
  /// Closes the group now rather than on destruction.
  void close() { id_.close(); }
  [[nodiscard]] const std::string& path() const { return path_; }

  Group create_group(std::string_view name);
  [[nodiscard]] Group open_group(std::string_view name) const;

  /// Writes `values` as a dataset of the given shape (their product must be values.size()).
  template <Element T>
  void write_dataset(std::string_view name, std::span<const T> values,
                     const std::vector<hsize_t>& shape);
  /// Reads a whole dataset, converting its elements to T. Throws if the stored elements are not
  /// of T's kind (integer or floating point).
  template <Element T>
  [[nodiscard]] Array<T> read_dataset(std::string_view name) const;

  template <Element T>
  void write_attribute(std::string_view name, T value);
  /// Writes a UTF-8 string attribute (fixed length, null-terminated).
  void write_attribute(std::string_view name, std::string_view value);
  /// Reads a single-valued attribute of T's kind (integer or floating point).
  template <Element T>
  [[nodiscard]] T read_attribute(std::string_view name) const;
  /// Reads a string attribute, fixed or variable length.
  [[nodiscard]] std::string read_string_attribute(std::string_view name) const;
  [[nodiscard]] bool has_attribute(std::string_view name) const;
  /// Names of every attribute of this group, in ascending order.
  [[nodiscard]] std::vector<std::string> attribute_names() const;

 private:
  [[nodiscard]] std::string child_path(std::string_view name) const;
  /// Opens attribute `name` (described as `object` in errors), checking that it holds exactly
  /// one value of the given kind.
  [[nodiscard]] Id open_attribute(std::string_view name, H5T_class_t kind,
                                  const std::string& object) const;
  /// Throws Hdf5Error for a failed HDF5 call on `object`, with HDF5's reason appended.
  [[noreturn]] void hdf5_failure(const std::string& object, std::string_view action) const;
  /// Throws Hdf5Error for an object whose content is not what was asked for.
  [[noreturn]] void content_error(const std::string& object, std::string_view problem) const;

  Id id_;
  std::string file_;
  std::string path_;
};

/// An open HDF5 file and its root group.
class File {
 public:
  /// Creates (or truncates) a file on disk in the HDF5 1.8 format: checksummed metadata,
  /// attributes of any size, readable by HDF5 1.8 and later. File locking is off: the callers
  /// write private temporary files.
  static File create(const std::filesystem::path& path);
  /// Opens the bytes of a file read-only, in memory (the bytes are copied); `name` names the
  /// file in messages.
  static File open_image(std::string name, std::span<const char> bytes);

  [[nodiscard]] Group& root() { return root_; }
  [[nodiscard]] const Group& root() const { return root_; }
  /// Flushes and closes the file; throws if HDF5 could not write all of it (disk full, …).
  void close();

 private:
  File(std::string name, Id id);

  std::string name_;
  Id id_;  // declared before root_ so that the root group closes first
  Group root_;
};

/// Writes an Eigen matrix (row-major, as Positions and Triangles are) as a (rows, cols) dataset.
template <class Matrix>
void write_rows(Group& group, std::string_view name, const Matrix& matrix) {
  using Scalar = typename Matrix::Scalar;
  group.write_dataset<Scalar>(
      name, std::span(matrix.data(), static_cast<std::size_t>(matrix.size())),
      {static_cast<hsize_t>(matrix.rows()), static_cast<hsize_t>(matrix.cols())});
}

/// Reads an (n, 3) dataset into a row-major Eigen matrix. Throws Hdf5Error naming the dataset
/// when it has another shape.
template <class Matrix>
Matrix read_rows(const Group& group, std::string_view name) {
  using Scalar = typename Matrix::Scalar;
  const Array<Scalar> array = group.read_dataset<Scalar>(name);
  if (array.shape.size() != 2 || array.shape[1] != 3)
    throw Hdf5Error(located_message(group.file_name(), 0,
                                    fmt::format("{} in {} has shape ({}), expected (n, 3)", name,
                                                group.path(), fmt::join(array.shape, ", "))));
  Matrix matrix(static_cast<typename Matrix::Index>(array.shape[0]), 3);
  std::copy(array.values.begin(), array.values.end(), matrix.data());
  return matrix;
}

}  // namespace psq::hdf5

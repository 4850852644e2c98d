#include "engine/io/hdf5_handle.hpp"

#include <fmt/format.h>

#include <atomic>
#include <functional>
#include <mutex>
#include <numeric>
#include <utility>

namespace psq::hdf5 {
namespace {

/// Growth step of in-memory files; the images opened here are only read, never grown.
constexpr std::size_t core_increment = std::size_t{1} << 20;

/// A distinct name for each in-memory image HDF5 opens. HDF5 needs one, refuses a name that
/// exists on disk, and takes two open files of the same name for one: a path below /dev/null
/// can never exist.
std::string image_name() {
  static std::atomic<unsigned long> count{0};
  return fmt::format("/dev/null/psq-image-{}", count++);
}

/// HDF5 types of each element: in memory (native) and in the file (fixed little-endian).
template <class T>
struct Types;
template <>
struct Types<double> {
  static hid_t memory() { return H5T_NATIVE_DOUBLE; }
  static hid_t stored() { return H5T_IEEE_F64LE; }
  static constexpr H5T_class_t kind = H5T_FLOAT;
};
template <>
struct Types<std::int32_t> {
  static hid_t memory() { return H5T_NATIVE_INT32; }
  static hid_t stored() { return H5T_STD_I32LE; }
  static constexpr H5T_class_t kind = H5T_INTEGER;
};
template <>
struct Types<std::uint64_t> {
  static hid_t memory() { return H5T_NATIVE_UINT64; }
  static hid_t stored() { return H5T_STD_U64LE; }
  static constexpr H5T_class_t kind = H5T_INTEGER;
};

std::string_view kind_name(H5T_class_t kind) {
  switch (kind) {
    case H5T_INTEGER: return "integer";
    case H5T_FLOAT: return "floating-point";
    case H5T_STRING: return "string";
    default: return "other";
  }
}

/// Once per process: HDF5 prints its error stack to stderr by default (errors here become
/// exceptions instead), and it closes leftover files at exit (see below).
void initialize_library() {
  static std::once_flag once;
  std::call_once(once, [] {
    // A file whose final flush failed (disk full) stays in HDF5's open list; the library's
    // exit-time cleanup would try to close it again and crash. Its temporary is discarded by
    // then, so there is nothing left for that cleanup to save.
    H5dont_atexit();
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  });
}

herr_t keep_first_description(unsigned, const H5E_error2_t* entry, void* sink) {
  auto* reason = static_cast<std::string*>(sink);
  if (reason->empty() && entry->desc != nullptr) *reason = entry->desc;
  return 0;
}

/// The system's message in a description of HDF5's file driver, which tells of a failed system
/// call at length (its time, over two lines, the descriptor, buffer address and sizes); the
/// description itself if it has none.
std::string system_message(const std::string& description) {
  constexpr std::string_view marker = "error message = '";
  const std::size_t start = description.find(marker);
  if (start == std::string::npos) return description;
  const std::size_t end = description.find('\'', start + marker.size());
  if (end == std::string::npos) return description;
  return description.substr(start + marker.size(), end - start - marker.size());
}

/// The most specific description on HDF5's error stack (where the failure was detected), after
/// which the stack is cleared.
std::string innermost_reason() {
  std::string reason;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, keep_first_description, &reason);
  H5Eclear2(H5E_DEFAULT);
  return reason.empty() ? "no detail from HDF5" : system_message(reason);
}

[[noreturn]] void fail(const std::string& file, const std::string& object, std::string_view what) {
  throw Hdf5Error(located_message(file, 0, fmt::format("{}: {}", object, what)));
}

/// A fixed-length UTF-8 string type holding `size` bytes.
Id string_type(std::size_t size) {
  Id type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), size);
  H5Tset_strpad(type.get(), H5T_STR_NULLTERM);
  H5Tset_cset(type.get(), H5T_CSET_UTF8);
  return type;
}

herr_t collect_attribute_name(hid_t, const char* name, const H5A_info_t*, void* sink) {
  static_cast<std::vector<std::string>*>(sink)->emplace_back(name);
  return 0;
}

}  // namespace

std::mutex& library_mutex() {
  static std::mutex mutex;
  return mutex;
}

Id::Id(Id&& other) noexcept
    : id_(std::exchange(other.id_, H5I_INVALID_HID)), closer_(other.closer_) {}

Id& Id::operator=(Id&& other) noexcept {
  if (this != &other) {
    close();
    id_ = std::exchange(other.id_, H5I_INVALID_HID);
    closer_ = other.closer_;
  }
  return *this;
}

bool Id::close() noexcept {
  if (id_ < 0) return true;
  const herr_t status = closer_(std::exchange(id_, H5I_INVALID_HID));
  return status >= 0;
}

Group::Group(Id id, std::string file, std::string path)
    : id_(std::move(id)), file_(std::move(file)), path_(std::move(path)) {}

std::string Group::child_path(std::string_view name) const {
  if (name.starts_with('/')) return std::string(name);  // absolute: HDF5 resolves it from the root
  return path_ == "/" ? fmt::format("/{}", name) : fmt::format("{}/{}", path_, name);
}

void Group::hdf5_failure(const std::string& object, std::string_view action) const {
  fail(file_, object, fmt::format("{} ({})", action, innermost_reason()));
}

void Group::content_error(const std::string& object, std::string_view problem) const {
  H5Eclear2(H5E_DEFAULT);
  fail(file_, object, problem);
}

Group Group::create_group(std::string_view name) {
  const std::string path = child_path(name);
  Id id(H5Gcreate2(id_.get(), std::string(name).c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
        H5Gclose);
  if (!id.valid()) hdf5_failure(path, "cannot create group");
  return {std::move(id), file_, path};
}

Group Group::open_group(std::string_view name) const {
  const std::string path = child_path(name);
  Id id(H5Gopen2(id_.get(), std::string(name).c_str(), H5P_DEFAULT), H5Gclose);
  if (!id.valid()) hdf5_failure(path, "missing or unreadable group");
  return {std::move(id), file_, path};
}

template <Element T>
void Group::write_dataset(std::string_view name, std::span<const T> values,
                          const std::vector<hsize_t>& shape) {
  const std::string path = child_path(name);
  const hsize_t count = std::accumulate(shape.begin(), shape.end(), hsize_t{1}, std::multiplies{});
  if (count != values.size())
    content_error(path, fmt::format("{} values do not fill the shape", values.size()));
  Id space(H5Screate_simple(static_cast<int>(shape.size()), shape.data(), nullptr), H5Sclose);
  if (!space.valid()) hdf5_failure(path, "cannot create dataspace");
  Id dataset(H5Dcreate2(id_.get(), std::string(name).c_str(), Types<T>::stored(), space.get(),
                        H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
             H5Dclose);
  if (!dataset.valid()) hdf5_failure(path, "cannot create dataset");
  // An empty dataset has nothing to write (and an empty span may carry no buffer at all).
  if (count > 0 &&
      H5Dwrite(dataset.get(), Types<T>::memory(), H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) < 0)
    hdf5_failure(path, "cannot write dataset");
  // HDF5 may hold the values back (its sieve buffer) until the dataset closes: a write that
  // fails then (disk full) is only reported by the close.
  if (!dataset.close()) hdf5_failure(path, "cannot write dataset");
}

template <Element T>
Array<T> Group::read_dataset(std::string_view name) const {
  const std::string path = child_path(name);
  Id dataset(H5Dopen2(id_.get(), std::string(name).c_str(), H5P_DEFAULT), H5Dclose);
  if (!dataset.valid()) hdf5_failure(path, "missing or unreadable dataset");
  Id type(H5Dget_type(dataset.get()), H5Tclose);
  if (!type.valid()) hdf5_failure(path, "unreadable datatype");
  const H5T_class_t kind = H5Tget_class(type.get());
  if (kind != Types<T>::kind)
    content_error(path, fmt::format("holds {} values, expected {}", kind_name(kind),
                                    kind_name(Types<T>::kind)));
  Id space(H5Dget_space(dataset.get()), H5Sclose);
  const int rank = space.valid() ? H5Sget_simple_extent_ndims(space.get()) : -1;
  if (rank < 0) hdf5_failure(path, "unreadable dataspace");
  Array<T> array;
  array.shape.resize(static_cast<std::size_t>(rank));
  H5Sget_simple_extent_dims(space.get(), array.shape.data(), nullptr);
  const hsize_t count =
      std::accumulate(array.shape.begin(), array.shape.end(), hsize_t{1}, std::multiplies{});
  // A damaged or hostile shape must not make us allocate what the file cannot hold.
  Id creation(H5Dget_create_plist(dataset.get()), H5Pclose);
  if (creation.valid() && H5Pget_layout(creation.get()) == H5D_CONTIGUOUS &&
      H5Dget_storage_size(dataset.get()) < count * H5Tget_size(type.get()))
    content_error(path, "declares more elements than the file stores");
  array.values.resize(count);
  if (count > 0 && H5Dread(dataset.get(), Types<T>::memory(), H5S_ALL, H5S_ALL, H5P_DEFAULT,
                           array.values.data()) < 0)
    hdf5_failure(path, "cannot read dataset");
  return array;
}

template <Element T>
void Group::write_attribute(std::string_view name, T value) {
  const std::string object = fmt::format("{} attribute '{}'", path_, name);
  Id space(H5Screate(H5S_SCALAR), H5Sclose);
  Id attribute(H5Acreate2(id_.get(), std::string(name).c_str(), Types<T>::stored(), space.get(),
                          H5P_DEFAULT, H5P_DEFAULT),
               H5Aclose);
  if (!attribute.valid()) hdf5_failure(object, "cannot create attribute");
  if (H5Awrite(attribute.get(), Types<T>::memory(), &value) < 0)
    hdf5_failure(object, "cannot write attribute");
}

void Group::write_attribute(std::string_view name, std::string_view value) {
  const std::string object = fmt::format("{} attribute '{}'", path_, name);
  const std::string text(value);
  const Id type = string_type(text.size() + 1);
  Id space(H5Screate(H5S_SCALAR), H5Sclose);
  Id attribute(H5Acreate2(id_.get(), std::string(name).c_str(), type.get(), space.get(),
                          H5P_DEFAULT, H5P_DEFAULT),
               H5Aclose);
  if (!attribute.valid()) hdf5_failure(object, "cannot create attribute");
  if (H5Awrite(attribute.get(), type.get(), text.c_str()) < 0)
    hdf5_failure(object, "cannot write attribute");
}

Id Group::open_attribute(std::string_view name, H5T_class_t kind,
                         const std::string& object) const {
  if (!has_attribute(name)) content_error(object, "missing");
  Id attribute(H5Aopen(id_.get(), std::string(name).c_str(), H5P_DEFAULT), H5Aclose);
  if (!attribute.valid()) hdf5_failure(object, "cannot open attribute");
  Id type(H5Aget_type(attribute.get()), H5Tclose);
  Id space(H5Aget_space(attribute.get()), H5Sclose);
  if (!type.valid() || !space.valid()) hdf5_failure(object, "unreadable attribute");
  const H5T_class_t stored_kind = H5Tget_class(type.get());
  if (stored_kind != kind)
    content_error(object, fmt::format("holds a {} value, expected {}", kind_name(stored_kind),
                                      kind_name(kind)));
  if (H5Sget_simple_extent_npoints(space.get()) != 1)
    content_error(object, "holds more than one value");
  return attribute;
}

template <Element T>
T Group::read_attribute(std::string_view name) const {
  const std::string object = fmt::format("{} attribute '{}'", path_, name);
  const Id attribute = open_attribute(name, Types<T>::kind, object);
  T value{};
  if (H5Aread(attribute.get(), Types<T>::memory(), &value) < 0)
    hdf5_failure(object, "cannot read attribute");
  return value;
}

std::string Group::read_string_attribute(std::string_view name) const {
  const std::string object = fmt::format("{} attribute '{}'", path_, name);
  const Id attribute = open_attribute(name, H5T_STRING, object);
  Id type(H5Aget_type(attribute.get()), H5Tclose);
  if (H5Tis_variable_str(type.get()) > 0) {
    Id memory_type(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(memory_type.get(), H5T_VARIABLE);
    char* text = nullptr;
    if (H5Aread(attribute.get(), memory_type.get(), &text) < 0)
      hdf5_failure(object, "cannot read attribute");
    std::string value = text != nullptr ? text : "";
    H5free_memory(text);
    return value;
  }
  const std::size_t size = H5Tget_size(type.get());
  std::string buffer(size, '\0');
  const Id memory_type = string_type(size);
  if (size == 0 || H5Aread(attribute.get(), memory_type.get(), buffer.data()) < 0)
    hdf5_failure(object, "cannot read attribute");
  return buffer.substr(0, buffer.find('\0'));
}

bool Group::has_attribute(std::string_view name) const {
  const htri_t exists = H5Aexists(id_.get(), std::string(name).c_str());
  if (exists < 0) hdf5_failure(path_, fmt::format("cannot look up attribute '{}'", name));
  return exists > 0;
}

std::vector<std::string> Group::attribute_names() const {
  std::vector<std::string> names;
  if (H5Aiterate2(id_.get(), H5_INDEX_NAME, H5_ITER_INC, nullptr, collect_attribute_name, &names) <
      0)
    hdf5_failure(path_, "cannot list attributes");
  return names;
}

File::File(std::string name, Id id)
    : name_(std::move(name)), id_(std::move(id)),
      root_(Id(H5Gopen2(id_.get(), "/", H5P_DEFAULT), H5Gclose), name_, "/") {
  if (!root_.valid())
    fail(name_, "/", fmt::format("cannot open the root group ({})", innermost_reason()));
}

File File::create(const std::filesystem::path& path) {
  initialize_library();
  std::string name = path.string();
  Id access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  // H5F_CLOSE_SEMI: closing the file while one of its objects is open is an error, rather
  // than a close silently deferred (with its final writes) until that object closes.
  if (H5Pset_libver_bounds(access.get(), H5F_LIBVER_V18, H5F_LIBVER_V18) < 0 ||
      H5Pset_file_locking(access.get(), false, true) < 0 ||
      H5Pset_fclose_degree(access.get(), H5F_CLOSE_SEMI) < 0)
    fail(name, "/", fmt::format("cannot set up file access ({})", innermost_reason()));
  Id id(H5Fcreate(name.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, access.get()), H5Fclose);
  if (!id.valid()) fail(name, "/", fmt::format("cannot create file ({})", innermost_reason()));
  return File(std::move(name), std::move(id));
}

File File::open_image(std::string name, std::span<const char> bytes) {
  initialize_library();
  // Without an image the core driver would read the named file from disk instead.
  if (bytes.empty()) fail(name, "/", "the file is empty");
  Id access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  // H5Pset_file_image copies the buffer; it never writes through the pointer.
  if (H5Pset_fapl_core(access.get(), core_increment, false) < 0 ||
      H5Pset_file_image(access.get(), const_cast<char*>(bytes.data()), bytes.size()) < 0)
    fail(name, "/", fmt::format("cannot set up file access ({})", innermost_reason()));
  Id id(H5Fopen(image_name().c_str(), H5F_ACC_RDONLY, access.get()), H5Fclose);
  if (!id.valid())
    fail(name, "/", fmt::format("not a readable HDF5 file ({})", innermost_reason()));
  return File(std::move(name), std::move(id));
}

void File::close() {
  root_.close();
  if (H5Fflush(id_.get(), H5F_SCOPE_GLOBAL) < 0)
    fail(name_, "/", fmt::format("cannot flush ({})", innermost_reason()));
  if (!id_.close()) fail(name_, "/", fmt::format("cannot close ({})", innermost_reason()));
}

template void Group::write_dataset(std::string_view, std::span<const double>,
                                   const std::vector<hsize_t>&);
template void Group::write_dataset(std::string_view, std::span<const std::int32_t>,
                                   const std::vector<hsize_t>&);
template Array<double> Group::read_dataset(std::string_view) const;
template Array<std::int32_t> Group::read_dataset(std::string_view) const;
template void Group::write_attribute(std::string_view, std::int32_t);
template void Group::write_attribute(std::string_view, std::uint64_t);
template void Group::write_attribute(std::string_view, double);
template std::int32_t Group::read_attribute(std::string_view) const;
template std::uint64_t Group::read_attribute(std::string_view) const;
template double Group::read_attribute(std::string_view) const;

}  // namespace psq::hdf5

#include "engine/io/checkpoint.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <array>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <span>
#include <utility>

#include "engine/core/atomic_file.hpp"
#include "engine/core/checksum.hpp"
#include "engine/io/hdf5_handle.hpp"

namespace psq {
namespace {

/// Value of the root attribute "format" that marks a file as a PSQ checkpoint.
constexpr std::string_view format_marker = "psq-checkpoint";

/// The first bytes of every HDF5 file without a user block.
constexpr std::string_view hdf5_signature = "\x89HDF\r\n\x1a\n";

[[noreturn]] void fail(const std::string& file, std::string_view problem) {
  throw CheckpointError(located_message(file, 0, std::string(problem)));
}

/// The same for a consistent checkpoint that the file system would not take.
[[noreturn]] void fail_to_write(const std::string& file, std::string_view problem) {
  throw CheckpointWriteError(located_message(file, 0, std::string(problem)));
}

constexpr std::array progress_names{std::pair{LevelProgress::inside_frame, "inside_frame"},
                                    std::pair{LevelProgress::frame_done, "frame_done"},
                                    std::pair{LevelProgress::level_done, "level_done"}};

std::string_view progress_name(LevelProgress progress) {
  for (const auto& [value, name] : progress_names)
    if (value == progress) return name;
  return "unknown";
}

std::optional<LevelProgress> parse_progress(std::string_view name) {
  for (const auto& [value, known] : progress_names)
    if (known == name) return value;
  return std::nullopt;
}

// The iteration records are stored as one column (1-D dataset) per field; these tables drive
// the writer, the reader and the content checksum alike.
constexpr std::array integer_columns{std::pair{"frame", &IterationRecord::frame},
                                     std::pair{"iteration", &IterationRecord::iteration}};
constexpr std::array real_columns{std::pair{"energy", &IterationRecord::energy},
                                  std::pair{"gradient_norm", &IterationRecord::gradient_norm},
                                  std::pair{"step_norm", &IterationRecord::step_norm},
                                  std::pair{"step_length", &IterationRecord::step_length},
                                  std::pair{"seconds", &IterationRecord::seconds}};

// ---- Content checksum: FNV-1a 64 over every stored value in a fixed order, each variable-size
// item preceded by its size so that no two different checkpoints give the same byte stream.

static_assert(std::endian::native == std::endian::little,
              "the content checksum is defined on little-endian bytes");

template <class T>
void hash_value(Fnv1a64& hash, const T& value) {
  static_assert(std::is_arithmetic_v<T>);
  hash.update(std::as_bytes(std::span(&value, 1)));
}

void hash_text(Fnv1a64& hash, std::string_view text) {
  hash_value(hash, static_cast<std::uint64_t>(text.size()));
  hash.update(text);
}

template <class Matrix>
void hash_matrix(Fnv1a64& hash, const Matrix& matrix) {
  hash_value(hash, static_cast<std::int64_t>(matrix.rows()));
  hash_value(hash, static_cast<std::int64_t>(matrix.cols()));
  hash.update(std::as_bytes(std::span(matrix.data(), static_cast<std::size_t>(matrix.size()))));
}

void hash_named_values(Fnv1a64& hash, const std::map<std::string, double>& values) {
  hash_value(hash, static_cast<std::uint64_t>(values.size()));
  for (const auto& [name, value] : values) {
    hash_text(hash, name);
    hash_value(hash, value);
  }
}

/// Checksum of everything a checkpoint stores except the checksum itself.
std::uint64_t content_checksum(const Checkpoint& c, int schema_version) {
  Fnv1a64 hash;
  hash_text(hash, format_marker);
  hash_value(hash, schema_version);
  hash_text(hash, c.code_version);
  hash_text(hash, c.parameters);
  hash_value(hash, c.level);
  hash_value(hash, c.frame);
  hash_value(hash, c.time);
  hash_matrix(hash, c.positions);
  hash_matrix(hash, c.rest_positions);
  hash_matrix(hash, c.triangles);
  hash_matrix(hash, c.finest_positions);
  hash_text(hash, progress_name(c.solver.progress));
  hash_matrix(hash, c.solver.previous_positions);
  hash_value(hash, c.solver.iterations_in_frame);
  hash_named_values(hash, c.solver.scalars);
  hash_value(hash, static_cast<std::uint64_t>(c.statistics.iterations.size()));
  for (const IterationRecord& record : c.statistics.iterations) {
    for (const auto& [name, field] : integer_columns) hash_value(hash, record.*field);
    for (const auto& [name, field] : real_columns) hash_value(hash, record.*field);
  }
  hash_named_values(hash, c.statistics.timings);
  if (schema_version >= 3) hash_named_values(hash, c.statistics.refinement);
  return hash.value();
}

// ---- Consistency, checked before writing and after reading.

/// Every name is non-empty (HDF5 attribute names cannot be) and every value finite.
bool all_named_and_finite(const std::map<std::string, double>& values) {
  for (const auto& [name, value] : values)
    if (name.empty() || !std::isfinite(value)) return false;
  return true;
}

/// The first inconsistency of a checkpoint, if any.
std::optional<std::string> inconsistency(const Checkpoint& c) {
  const Eigen::Index n = c.positions.rows();
  if (c.rest_positions.rows() != n)
    return fmt::format("{} rest positions for {} vertices", c.rest_positions.rows(), n);
  if (c.solver.previous_positions.rows() != n)
    return fmt::format("{} previous positions for {} vertices", c.solver.previous_positions.rows(),
                       n);
  if (c.triangles.size() > 0 && (c.triangles.minCoeff() < 0 || c.triangles.maxCoeff() >= n))
    return fmt::format("triangle vertex indices outside [0, {})", n);
  if (!c.positions.allFinite() || !c.rest_positions.allFinite() ||
      !c.finest_positions.allFinite() || !c.solver.previous_positions.allFinite())
    return std::string("positions contain NaN or infinite values");
  if (!std::isfinite(c.time)) return std::string("the time is NaN or infinite");
  if (!all_named_and_finite(c.solver.scalars) || !all_named_and_finite(c.statistics.timings) ||
      !all_named_and_finite(c.statistics.refinement))
    return std::string(
        "solver scalars, timings or refinement statistics with an empty name or a non-finite "
        "value");
  if (c.level < 0 || c.frame < 0 || c.solver.iterations_in_frame < 0)
    return fmt::format("negative level ({}), frame ({}) or iteration count ({})", c.level, c.frame,
                       c.solver.iterations_in_frame);
  if (!nlohmann::json::accept(c.parameters)) return std::string("parameters are not valid JSON");
  return std::nullopt;
}

// ---- Encoding.

void write_named_values(hdf5::Group group, const std::map<std::string, double>& values) {
  for (const auto& [name, value] : values) group.write_attribute(name, value);
}

void write_iterations(hdf5::Group group, const std::vector<IterationRecord>& records) {
  const std::vector<hsize_t> shape{records.size()};
  for (const auto& [name, field] : integer_columns) {
    std::vector<std::int32_t> column;
    for (const IterationRecord& record : records) column.push_back(record.*field);
    group.write_dataset<std::int32_t>(name, column, shape);
  }
  for (const auto& [name, field] : real_columns) {
    std::vector<double> column;
    for (const IterationRecord& record : records) column.push_back(record.*field);
    group.write_dataset<double>(name, column, shape);
  }
}

void write_solver_state(hdf5::Group group, const SolverState& solver) {
  group.write_attribute("progress", progress_name(solver.progress));
  group.write_attribute("iterations_in_frame", solver.iterations_in_frame);
  hdf5::write_rows(group, "previous_positions", solver.previous_positions);
  write_named_values(group.create_group("scalars"), solver.scalars);
}

void write_statistics(hdf5::Group group, const LevelStatistics& statistics) {
  write_iterations(group.create_group("iterations"), statistics.iterations);
  write_named_values(group.create_group("timings"), statistics.timings);
  write_named_values(group.create_group("refinement"), statistics.refinement);
}

/// Writes the checkpoint as an HDF5 file at `path`, flushed and closed.
void encode(const Checkpoint& c, const std::filesystem::path& path) {
  hdf5::File file = hdf5::File::create(path);
  hdf5::Group& root = file.root();
  root.write_attribute("format", format_marker);
  root.write_attribute("schema_version", checkpoint_schema_version);
  root.write_attribute("code_version", c.code_version);
  root.write_attribute("parameters", c.parameters);
  root.write_attribute("level", c.level);
  root.write_attribute("frame", c.frame);
  root.write_attribute("time", c.time);
  root.write_attribute("content_checksum", content_checksum(c, checkpoint_schema_version));
  root.create_group("mesh");
  hdf5::write_rows(root, checkpoint_layout::positions, c.positions);
  hdf5::write_rows(root, checkpoint_layout::rest_positions, c.rest_positions);
  hdf5::write_rows(root, checkpoint_layout::triangles, c.triangles);
  hdf5::write_rows(root, checkpoint_layout::finest_positions, c.finest_positions);
  write_solver_state(root.create_group("solver"), c.solver);
  write_statistics(root.create_group("statistics"), c.statistics);
  file.close();
}

// ---- Decoding.

std::map<std::string, double> read_named_values(const hdf5::Group& group) {
  std::map<std::string, double> values;
  for (const std::string& name : group.attribute_names())
    values[name] = group.read_attribute<double>(name);
  return values;
}

/// Reads one column of the iteration records; the first column read sets their number.
template <hdf5::Element T, class Field>
void read_column(const hdf5::Group& group, const char* name, Field field,
                 std::vector<IterationRecord>& records, bool& sized) {
  const hdf5::Array<T> column = group.read_dataset<T>(name);
  if (column.shape.size() != 1)
    fail(group.file_name(), fmt::format("{}/{} is not one-dimensional", group.path(), name));
  if (!sized) records.resize(column.values.size());
  sized = true;
  if (column.values.size() != records.size())
    fail(group.file_name(),
         fmt::format("{}/{} has {} entries where other columns have {}", group.path(), name,
                     column.values.size(), records.size()));
  for (std::size_t i = 0; i < records.size(); ++i) records[i].*field = column.values[i];
}

std::vector<IterationRecord> read_iterations(const hdf5::Group& group) {
  std::vector<IterationRecord> records;
  bool sized = false;
  for (const auto& [name, field] : integer_columns)
    read_column<std::int32_t>(group, name, field, records, sized);
  for (const auto& [name, field] : real_columns)
    read_column<double>(group, name, field, records, sized);
  return records;
}

void check_schema_version(const std::string& file_name, int version) {
  if (version > checkpoint_schema_version)
    fail(file_name, fmt::format("written with checkpoint schema version {}, newer than version {} "
                                "that this program reads; use a newer psq",
                                version, checkpoint_schema_version));
  if (version < 1) fail(file_name, fmt::format("invalid checkpoint schema version {}", version));
}

Checkpoint decode(const std::string& file_name, std::span<const char> bytes) {
  const hdf5::File file = hdf5::File::open_image(file_name, bytes);
  const hdf5::Group& root = file.root();
  if (!root.has_attribute("format") || root.read_string_attribute("format") != format_marker)
    fail(file_name, fmt::format("an HDF5 file but not a PSQ checkpoint (no root attribute "
                                "format = \"{}\")",
                                format_marker));
  Checkpoint c;
  c.schema_version = root.read_attribute<std::int32_t>("schema_version");
  check_schema_version(file_name, c.schema_version);
  c.code_version = root.read_string_attribute("code_version");
  c.parameters = root.read_string_attribute("parameters");
  c.level = root.read_attribute<std::int32_t>("level");
  c.frame = root.read_attribute<std::int32_t>("frame");
  c.time = root.read_attribute<double>("time");
  c.positions = hdf5::read_rows<Positions>(root, checkpoint_layout::positions);
  c.rest_positions = hdf5::read_rows<Positions>(root, checkpoint_layout::rest_positions);
  c.triangles = hdf5::read_rows<Triangles>(root, checkpoint_layout::triangles);
  c.finest_positions = hdf5::read_rows<Positions>(root, checkpoint_layout::finest_positions);

  const hdf5::Group solver = root.open_group("solver");
  const std::string progress = solver.read_string_attribute("progress");
  const std::optional<LevelProgress> parsed = parse_progress(progress);
  if (!parsed) fail(file_name, fmt::format("unknown solver progress '{}'", progress));
  c.solver.progress = *parsed;
  c.solver.iterations_in_frame = solver.read_attribute<std::int32_t>("iterations_in_frame");
  c.solver.previous_positions = hdf5::read_rows<Positions>(solver, "previous_positions");
  c.solver.scalars = read_named_values(solver.open_group("scalars"));

  const hdf5::Group statistics = root.open_group("statistics");
  c.statistics.iterations = read_iterations(statistics.open_group("iterations"));
  c.statistics.timings = read_named_values(statistics.open_group("timings"));
  if (c.schema_version >= 3)
    c.statistics.refinement = read_named_values(statistics.open_group("refinement"));

  const auto stored_checksum = root.read_attribute<std::uint64_t>("content_checksum");
  if (content_checksum(c, c.schema_version) != stored_checksum)
    fail(file_name, "content checksum mismatch: the stored data were damaged after writing");
  if (const auto problem = inconsistency(c))
    fail(file_name, fmt::format("inconsistent checkpoint: {}", *problem));
  return c;
}

std::vector<char> read_bytes(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error))
    fail(file, std::filesystem::exists(path, error) ? "not a regular file" : "no such file");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(file, fmt::format("cannot open: {}", std::strerror(errno)));
  std::vector<char> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) fail(file, "read error");
  return bytes;
}

}  // namespace

std::uint64_t write_checkpoint(const std::filesystem::path& path, const Checkpoint& checkpoint) {
  const std::string file_name = path.string();
  if (const auto problem = inconsistency(checkpoint))
    fail(file_name, fmt::format("refusing to write an inconsistent checkpoint: {}", *problem));
  const std::filesystem::path directory = path.parent_path().empty() ? "." : path.parent_path();
  if (std::error_code error; !std::filesystem::is_directory(directory, error))
    fail_to_write(file_name,
                  fmt::format("cannot write checkpoint: no directory '{}'", directory.string()));
  try {
    std::uint64_t checksum = 0;
    replace_file_atomically(path, [&](const std::filesystem::path& temporary) {
      const std::lock_guard lock(hdf5::library_mutex());
      encode(checkpoint, temporary);
      // Reading the file back proves that HDF5 wrote all of it: a write it held back and lost
      // without an error (as its dataset buffer once did on a full disk) must not replace the
      // previous checkpoint.
      const std::vector<char> bytes = read_bytes(temporary);
      decode(temporary.string(), bytes);
      checksum = fnv1a64(std::as_bytes(std::span(bytes)));
    });
    return checksum;
  } catch (const std::exception& e) {
    // HDF5 errors name the temporary file; the caller knows the checkpoint by its final name.
    fail_to_write(file_name, fmt::format("cannot write checkpoint: {}", e.what()));
  }
}

Checkpoint read_checkpoint(const std::filesystem::path& path,
                           std::optional<std::uint64_t> expected_file_checksum) {
  const std::string file_name = path.string();
  const std::vector<char> bytes = read_bytes(path);
  if (expected_file_checksum) {
    const std::uint64_t actual = fnv1a64(std::as_bytes(std::span(bytes)));
    if (actual != *expected_file_checksum)
      fail(file_name, fmt::format("file checksum {:016x} differs from the recorded {:016x}: the "
                                  "file is damaged, truncated or was replaced",
                                  actual, *expected_file_checksum));
  }
  if (bytes.empty()) fail(file_name, "the file is empty");
  if (!std::string_view(bytes.data(), bytes.size()).starts_with(hdf5_signature))
    fail(file_name, "not an HDF5 file (no HDF5 signature at its start)");
  try {
    const std::lock_guard lock(hdf5::library_mutex());
    return decode(file_name, bytes);
  } catch (const hdf5::Hdf5Error& e) {
    throw CheckpointError(
        fmt::format("{}; the checkpoint is damaged, truncated or not a PSQ checkpoint", e.what()));
  }
}

}  // namespace psq

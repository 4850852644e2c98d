#include "engine/scene/scene_reader.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <numbers>
#include <set>
#include <type_traits>

#include "engine/core/error.hpp"
#include "engine/core/input_file.hpp"
#include "engine/scene/key_suggestion.hpp"
#include "engine/scene/scene_document.hpp"

namespace psq {
namespace {

namespace fs = std::filesystem;
using Keys = std::vector<std::string>;

std::string type_name(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a floating-point number";
    case toml::node_type::boolean:
      return "a boolean";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::table:
      return "a table";
    case toml::node_type::date:
    case toml::node_type::time:
    case toml::node_type::date_time:
      return "a date or time";
    case toml::node_type::none:
      break;
  }
  return "nothing";
}

long line_of(const toml::node& node) { return static_cast<long>(node.source().begin.line); }

std::string quoted_list(const Keys& keys) {
  std::string out;
  for (const std::string& key : keys) out += (out.empty() ? "'" : ", '") + key + "'";
  return out;
}

/// One table of a scene file. Hands out its values by key with type checks and defaults, and
/// raises InputErrors that name the file, the line, the key and the table ("in [shell.pin]").
class Section {
 public:
  /// `name` is the dotted path of the table ("shell.material"); empty for the top level.
  Section(const toml::table& table, std::string name, std::string file)
      : table_(table),
        name_(std::move(name)),
        file_(std::move(file)),
        line_(name_.empty() ? 0 : line_of(table)) {}

  [[nodiscard]] const std::string& file() const { return file_; }
  [[nodiscard]] long line() const { return line_; }
  [[nodiscard]] bool has(std::string_view key) const { return table_.contains(key); }

  /// "in [shell.material]" or "at the top level".
  [[nodiscard]] std::string where() const {
    return name_.empty() ? "at the top level" : fmt::format("in [{}]", name_);
  }

  /// Line of a key's value, or of the table when the key is absent.
  [[nodiscard]] long line(std::string_view key) const {
    const toml::node* node = table_.get(key);
    return node ? line_of(*node) : line_;
  }

  [[noreturn]] void fail(long line, const std::string& message) const {
    throw InputError(located_message(file_, line, message));
  }

  /// Fails at the key's line with "'key' in [table] must be <requirement>".
  void check(bool ok, std::string_view key, const std::string& requirement) const {
    if (!ok) fail(line(key), fmt::format("'{}' {} must be {}", key, where(), requirement));
  }

  /// Rejects every key not in `allowed`, the first in the file first, suggesting the
  /// nearest allowed key or listing them all.
  void allow_only(const Keys& allowed) const {
    const toml::key* unknown = nullptr;
    for (auto&& [key, value] : table_) {
      if (std::find(allowed.begin(), allowed.end(), key.str()) != allowed.end()) continue;
      if (!unknown || key.source().begin.line < unknown->source().begin.line) unknown = &key;
    }
    if (!unknown) return;
    const auto suggestion = suggest_key(unknown->str(), allowed);
    const std::string hint = suggestion ? fmt::format("did you mean '{}'?", *suggestion)
                                        : fmt::format("valid keys: {}", quoted_list(allowed));
    throw UnknownKeyError(
        located_message(file_, static_cast<long>(unknown->source().begin.line),
                        fmt::format("unknown key '{}' {}; {}", unknown->str(), where(), hint)),
        std::string(unknown->str()), suggestion);
  }

  /// The value of an optional key, `fallback` when absent.
  template <class T>
  [[nodiscard]] T get(std::string_view key, T fallback) const {
    const toml::node* node = table_.get(key);
    return node ? convert<T>(key, *node) : fallback;
  }
  template <class T>
  [[nodiscard]] std::optional<T> get_optional(std::string_view key) const {
    const toml::node* node = table_.get(key);
    return node ? std::optional<T>(convert<T>(key, *node)) : std::nullopt;
  }
  template <class T>
  [[nodiscard]] T get_required(std::string_view key) const {
    const toml::node* node = table_.get(key);
    if (!node) fail(line_, fmt::format("missing required key '{}' {}", key, where()));
    return convert<T>(key, *node);
  }

  [[nodiscard]] Section table(std::string_view key) const {
    const toml::node* node = table_.get(key);
    if (!node) fail(line_, fmt::format("missing required table '{}' {}", key, where()));
    return child(key, *node);
  }
  [[nodiscard]] std::optional<Section> optional_table(std::string_view key) const {
    const toml::node* node = table_.get(key);
    return node ? std::optional<Section>(child(key, *node)) : std::nullopt;
  }

  /// The tables of an array of tables ([[key]] or key = [{...}, ...]); none when absent.
  [[nodiscard]] std::vector<Section> tables(std::string_view key) const {
    const toml::node* node = table_.get(key);
    if (!node) return {};
    const toml::array* array = node->as_array();
    if (!array || (!array->empty() && !array->is_array_of_tables()))
      fail(line_of(*node), fmt::format("expected an array of tables for '{}' {} (write [[{}]] "
                                       "sections or a list of {{ ... }}), got {}",
                                       key, where(), dotted(key), type_name(*node)));
    std::vector<Section> out;
    for (const toml::node& element : *array)
      out.emplace_back(*element.as_table(), dotted(key), file_);
    return out;
  }

 private:
  [[nodiscard]] std::string dotted(std::string_view key) const {
    return name_.empty() ? std::string(key) : fmt::format("{}.{}", name_, key);
  }

  [[nodiscard]] Section child(std::string_view key, const toml::node& node) const {
    if (!node.is_table())
      fail(line_of(node),
           fmt::format("expected a table for '{}' {}, got {}", key, where(), type_name(node)));
    return Section(*node.as_table(), dotted(key), file_);
  }

  [[noreturn]] void wrong_type(std::string_view key, const toml::node& node,
                               std::string_view expected) const {
    fail(line_of(node),
         fmt::format("expected {} for '{}' {}, got {}", expected, key, where(), type_name(node)));
  }

  [[nodiscard]] double to_number(std::string_view key, const toml::node& node) const {
    double value = 0;
    if (const auto* i = node.as_integer())
      value = static_cast<double>(i->get());
    else if (const auto* f = node.as_floating_point())
      value = f->get();
    else
      wrong_type(key, node, "a number");
    if (!std::isfinite(value)) wrong_type(key, node, "a finite number");
    return value;
  }

  [[nodiscard]] int to_integer(std::string_view key, const toml::node& node) const {
    const auto* i = node.as_integer();
    if (!i) wrong_type(key, node, "an integer");
    if (i->get() < INT_MIN || i->get() > INT_MAX) wrong_type(key, node, "an integer of int range");
    return static_cast<int>(i->get());
  }

  /// An array of exactly `size` numbers, e.g. a point [x, y, z].
  template <int size>
  [[nodiscard]] Eigen::Matrix<double, size, 1> to_vector(std::string_view key,
                                                         const toml::node& node) const {
    const std::string expected = fmt::format("an array of {} numbers", size);
    const toml::array* array = node.as_array();
    if (!array || array->size() != static_cast<std::size_t>(size)) wrong_type(key, node, expected);
    Eigen::Matrix<double, size, 1> out;
    for (int k = 0; k < size; ++k) {
      const toml::node& element = *array->get(static_cast<std::size_t>(k));
      if (!element.is_number()) wrong_type(key, node, expected);
      out[k] = to_number(key, element);
    }
    return out;
  }

  template <class T>
  [[nodiscard]] T convert(std::string_view key, const toml::node& node) const {
    if constexpr (std::is_same_v<T, double>) {
      return to_number(key, node);
    } else if constexpr (std::is_same_v<T, int>) {
      return to_integer(key, node);
    } else if constexpr (std::is_same_v<T, bool>) {
      if (!node.is_boolean()) wrong_type(key, node, "true or false");
      return node.as_boolean()->get();
    } else if constexpr (std::is_same_v<T, std::string>) {
      if (!node.is_string()) wrong_type(key, node, "a string");
      return node.as_string()->get();
    } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
      const toml::array* array = node.as_array();
      if (!array) wrong_type(key, node, "an array of strings");
      std::vector<std::string> out;
      for (const toml::node& element : *array) out.push_back(convert<std::string>(key, element));
      return out;
    } else if constexpr (std::is_same_v<T, std::vector<Eigen::Vector2d>>) {
      const toml::array* array = node.as_array();
      if (!array) wrong_type(key, node, "an array of [a, b] pairs of numbers");
      std::vector<Eigen::Vector2d> out;
      for (const toml::node& element : *array) out.push_back(to_vector<2>(key, element));
      return out;
    } else if constexpr (std::is_same_v<T, std::vector<int>>) {
      const toml::array* array = node.as_array();
      if (!array) wrong_type(key, node, "an array of integers");
      std::vector<int> out;
      for (const toml::node& element : *array) out.push_back(to_integer(key, element));
      return out;
    } else {
      return to_vector<T::RowsAtCompileTime>(key, node);
    }
  }

  const toml::table& table_;
  std::string name_;
  std::string file_;
  long line_;
};

std::string format_vector(const Eigen::Vector3d& v) {
  return fmt::format("[{:g}, {:g}, {:g}]", v.x(), v.y(), v.z());
}

/// Fails unless the value of `key` is a nonzero direction.
void check_direction(const Section& section, std::string_view key, const Eigen::Vector3d& axis) {
  section.check(axis.norm() > 0, key, "a nonzero direction (got [0, 0, 0])");
}

/// One of `choices` as written for `key`. Anything else fails listing the choices, with the
/// nearest one suggested on a typo.
std::string read_choice(const Section& section, std::string_view key, const Keys& choices,
                        std::optional<std::string> fallback = std::nullopt) {
  const std::string value =
      fallback ? section.get<std::string>(key, *fallback) : section.get_required<std::string>(key);
  if (std::find(choices.begin(), choices.end(), value) != choices.end()) return value;
  const auto suggestion = suggest_key(value, choices);
  section.fail(section.line(key),
               fmt::format("unknown {} '{}' {}; {}expected one of {}", key, value, section.where(),
                           suggestion ? fmt::format("did you mean '{}'? ", *suggestion) : "",
                           quoted_list(choices)));
}

// Checked numbers: each reads `key` and fails naming its requirement and the value given.

/// A positive number: required, or `fallback` when absent.
double read_positive(const Section& section, std::string_view key,
                     std::optional<double> fallback = std::nullopt) {
  const double value =
      fallback ? section.get<double>(key, *fallback) : section.get_required<double>(key);
  section.check(value > 0, key, fmt::format("positive (got {:g})", value));
  return value;
}

/// A number that must be positive when given.
std::optional<double> read_optional_positive(const Section& section, std::string_view key) {
  if (!section.has(key)) return std::nullopt;
  return read_positive(section, key);
}

/// A number of at least 0, `fallback` when absent.
double read_non_negative(const Section& section, std::string_view key, double fallback) {
  const double value = section.get<double>(key, fallback);
  section.check(value >= 0, key, fmt::format("at least 0 (got {:g})", value));
  return value;
}

/// A number in the open interval (0, 1), `fallback` when absent.
double read_unit_fraction(const Section& section, std::string_view key, double fallback) {
  const double value = section.get<double>(key, fallback);
  section.check(value > 0 && value < 1, key, fmt::format("in (0, 1) (got {:g})", value));
  return value;
}

/// An integer of at least 1 (a count of frames, levels or iterations), `fallback` when absent.
int read_count(const Section& section, std::string_view key, int fallback) {
  const int value = section.get<int>(key, fallback);
  section.check(value >= 1, key, fmt::format("at least 1 (got {})", value));
  return value;
}

// ---------------------------------------------------------------------------------------------
// Meshes

const Keys kSheetKeys = {"generator", "width", "height", "edge_length", "structured", "holes"};
const Keys kCylinderKeys = {"generator", "radius", "height", "edge_length"};
const Keys kSphereKeys = {"generator", "radius", "edge_length"};
const Keys kCylindricalPanelKeys = {"generator", "radius", "height", "angle_degrees",
                                    "edge_length"};
const Keys kSphericalPanelKeys = {"generator",         "radius",          "polar_min_degrees",
                                  "polar_max_degrees", "azimuth_degrees", "edge_length"};

/// The target edge length, which must be positive and smaller than the shape's smallest size.
double read_edge_length(const Section& mesh, double smallest_size, std::string_view size_name) {
  const double edge = read_positive(mesh, "edge_length");
  mesh.check(edge < smallest_size, "edge_length",
             fmt::format("smaller than the {} ({:g}); got {:g}", size_name, smallest_size, edge));
  return edge;
}

std::vector<SheetGenerator::Hole> read_holes(const Section& mesh, const SheetGenerator& sheet) {
  std::vector<SheetGenerator::Hole> holes;
  for (const Section& hole : mesh.tables("holes")) {
    hole.allow_only({"center", "radius"});
    const Eigen::Vector2d center = hole.get_required<Eigen::Vector2d>("center");
    const double radius = read_positive(hole, "radius");
    hole.check(std::abs(center.x()) + radius < 0.5 * sheet.width &&
                   std::abs(center.y()) + radius < 0.5 * sheet.height,
               "radius",
               fmt::format("small enough for the hole to lie inside the {:g} × {:g} "
                           "sheet (centred at the origin)",
                           sheet.width, sheet.height));
    for (const SheetGenerator::Hole& other : holes)
      hole.check(std::hypot(center.x() - other.center_x, center.y() - other.center_y) >
                     radius + other.radius,
                 "radius", "small enough for the hole not to overlap an earlier hole");
    holes.push_back({center.x(), center.y(), radius});
  }
  return holes;
}

SheetGenerator read_sheet(const Section& mesh) {
  mesh.allow_only(kSheetKeys);
  SheetGenerator sheet;
  sheet.width = read_positive(mesh, "width");
  sheet.height = read_positive(mesh, "height");
  sheet.edge_length =
      read_edge_length(mesh, std::min(sheet.width, sheet.height), "sheet's width and height");
  sheet.structured = mesh.get<bool>("structured", false);
  sheet.holes = read_holes(mesh, sheet);
  if (sheet.structured && !sheet.holes.empty())
    mesh.fail(mesh.line("holes"), fmt::format("'holes' {} need an unstructured sheet "
                                              "(structured = false)",
                                              mesh.where()));
  return sheet;
}

CylinderGenerator read_cylinder(const Section& mesh) {
  mesh.allow_only(kCylinderKeys);
  CylinderGenerator cylinder;
  cylinder.radius = read_positive(mesh, "radius");
  cylinder.height = read_positive(mesh, "height");
  cylinder.edge_length = read_edge_length(mesh, std::min(cylinder.radius, cylinder.height),
                                          "cylinder's radius and height");
  return cylinder;
}

SphereGenerator read_sphere(const Section& mesh) {
  mesh.allow_only(kSphereKeys);
  SphereGenerator sphere;
  sphere.radius = read_positive(mesh, "radius");
  sphere.edge_length = read_edge_length(mesh, sphere.radius, "sphere's radius");
  return sphere;
}

/// An angle in degrees in (low, high], or (low, high) when the bound is not allowed; required
/// without a fallback.
double read_angle(const Section& mesh, std::string_view key, std::optional<double> fallback,
                  double low, double high, bool high_allowed) {
  const double value =
      fallback ? mesh.get<double>(key, *fallback) : mesh.get_required<double>(key);
  mesh.check(value > low && (high_allowed ? value <= high : value < high), key,
             fmt::format("in ({:g}, {:g}{} degrees (got {:g})", low, high,
                         high_allowed ? "]" : ")", value));
  return value;
}

CylindricalPanelGenerator read_cylindrical_panel(const Section& mesh) {
  mesh.allow_only(kCylindricalPanelKeys);
  CylindricalPanelGenerator panel;
  panel.radius = read_positive(mesh, "radius");
  panel.height = read_positive(mesh, "height");
  panel.angle_degrees = read_angle(mesh, "angle_degrees", 360.0, 0, 360, true);
  const double arc = panel.radius * panel.angle_degrees * std::numbers::pi / 180.0;
  panel.edge_length =
      read_edge_length(mesh, std::min(arc, panel.height), "panel's arc length and height");
  return panel;
}

SphericalPanelGenerator read_spherical_panel(const Section& mesh) {
  mesh.allow_only(kSphericalPanelKeys);
  SphericalPanelGenerator panel;
  panel.radius = read_positive(mesh, "radius");
  panel.polar_min_degrees = read_angle(mesh, "polar_min_degrees", std::nullopt, 0, 180, false);
  panel.polar_max_degrees =
      read_angle(mesh, "polar_max_degrees", 90.0, panel.polar_min_degrees, 180, false);
  panel.azimuth_degrees = read_angle(mesh, "azimuth_degrees", 360.0, 0, 360, true);
  const double meridian =
      panel.radius * (panel.polar_max_degrees - panel.polar_min_degrees) * std::numbers::pi / 180.0;
  panel.edge_length = read_edge_length(mesh, meridian, "panel's meridian length");
  return panel;
}

/// A mesh file, resolved relative to the scene file's directory; it must exist.
fs::path read_mesh_file(const Section& mesh, const fs::path& scene_path) {
  mesh.allow_only({"file"});
  const std::string written = mesh.get_required<std::string>("file");
  const fs::path resolved = fs::absolute(scene_path.parent_path() / written).lexically_normal();
  std::string extension = resolved.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  mesh.check(extension == ".obj" || extension == ".ply" || extension == ".off", "file",
             fmt::format("an .obj, .ply or .off file (got '{}')", written));
  // Without the error code, a name the OS refuses (e.g. too long) would throw filesystem_error.
  std::error_code error;
  if (!fs::is_regular_file(resolved, error))
    mesh.fail(mesh.line("file"),
              fmt::format("mesh file '{}' not found: {}", written,
                          error ? fmt::format("{}: {}", resolved.string(), error.message())
                                : fmt::format("{} does not exist", resolved.string())));
  return resolved;
}

void read_placement(const Section& shell, MeshSource& source) {
  const auto placement = shell.optional_table("placement");
  if (!placement) return;
  placement->allow_only({"scale", "rotation_axis", "rotation_degrees", "translation"});
  source.scale = read_positive(*placement, "scale", source.scale);
  source.rotation_axis = placement->get<Eigen::Vector3d>("rotation_axis", source.rotation_axis);
  check_direction(*placement, "rotation_axis", source.rotation_axis);
  source.rotation_degrees = placement->get<double>("rotation_degrees", source.rotation_degrees);
  source.translation = placement->get<Eigen::Vector3d>("translation", source.translation);
}

MeshSource read_mesh_source(const Section& shell, const fs::path& scene_path) {
  const Section mesh = shell.table("mesh");
  MeshSource source;
  if (mesh.has("file") && mesh.has("generator"))
    mesh.fail(mesh.line("generator"),
              fmt::format("give either 'file' or 'generator' {}, not both", mesh.where()));
  if (mesh.has("file")) {
    source.kind = MeshSource::Kind::File;
    source.file = read_mesh_file(mesh, scene_path);
  } else if (!mesh.has("generator")) {
    mesh.fail(mesh.line(), fmt::format("missing 'file' or 'generator' {}", mesh.where()));
  } else {
    const std::string generator =
        read_choice(mesh, "generator",
                    {"sheet", "cylinder", "sphere", "cylindrical_panel", "spherical_panel"});
    if (generator == "sheet") {
      source.kind = MeshSource::Kind::Sheet;
      source.sheet = read_sheet(mesh);
    } else if (generator == "cylinder") {
      source.kind = MeshSource::Kind::Cylinder;
      source.cylinder = read_cylinder(mesh);
    } else if (generator == "cylindrical_panel") {
      source.kind = MeshSource::Kind::CylindricalPanel;
      source.cylindrical_panel = read_cylindrical_panel(mesh);
    } else if (generator == "spherical_panel") {
      source.kind = MeshSource::Kind::SphericalPanel;
      source.spherical_panel = read_spherical_panel(mesh);
    } else {
      source.kind = MeshSource::Kind::Sphere;
      source.sphere = read_sphere(mesh);
    }
  }
  read_placement(shell, source);
  return source;
}

// ---------------------------------------------------------------------------------------------
// Materials, selectors, pins, loads

Material read_material(const Section& section) {
  section.allow_only({"youngs_modulus", "poisson_ratio", "density", "thickness", "strain_limit",
                      "strain_limit_stiffness"});
  Material material;
  material.youngs_modulus = read_positive(section, "youngs_modulus");
  material.poisson_ratio = section.get_required<double>("poisson_ratio");
  section.check(material.poisson_ratio > -1 && material.poisson_ratio < 0.5, "poisson_ratio",
                fmt::format("in (-1, 0.5) (got {:g})", material.poisson_ratio));
  material.density = read_positive(section, "density");
  material.thickness = read_positive(section, "thickness");
  return material;
}

/// The shell's `bending` key: "hinge" (the default) or "midedge".
BendingModel read_bending_model(const Section& shell) {
  return read_choice(shell, "bending", {"hinge", "midedge"}, "hinge") == "midedge"
             ? BendingModel::midedge
             : BendingModel::hinge;
}

/// The material table's optional strain limit: `strain_limit` > 1 (a stretch; 1 is the rest
/// length) and, with it only, a positive `strain_limit_stiffness`.
std::optional<StrainLimitSettings> read_strain_limit(const Section& material) {
  if (!material.has("strain_limit")) {
    material.check(!material.has("strain_limit_stiffness"), "strain_limit_stiffness",
                   "given together with 'strain_limit'");
    return std::nullopt;
  }
  StrainLimitSettings limit;
  limit.limit = material.get_required<double>("strain_limit");
  material.check(limit.limit > 1, "strain_limit",
                 fmt::format("greater than 1, a principal stretch above the rest length (got {:g})",
                             limit.limit));
  limit.stiffness = read_optional_positive(material, "strain_limit_stiffness");
  return limit;
}

const Keys kSelectorKeys = {"box", "boundary_loop", "vertices"};

/// Keys of a table that also holds a vertex selector.
Keys with_selector_keys(Keys keys) {
  keys.insert(keys.end(), kSelectorKeys.begin(), kSelectorKeys.end());
  return keys;
}

/// The selector written in `owner` (a pin or load table): exactly one of box, boundary_loop
/// or vertices.
VertexSelector read_selector(const Section& owner) {
  Keys given;
  for (const std::string& key : kSelectorKeys)
    if (owner.has(key)) given.push_back(key);
  if (given.empty())
    owner.fail(owner.line(), fmt::format("missing a vertex selector {}: give one of {}",
                                         owner.where(), quoted_list(kSelectorKeys)));
  if (given.size() > 1)
    owner.fail(owner.line(given[1]), fmt::format("several vertex selectors {} ({}); give exactly "
                                                 "one",
                                                 owner.where(), quoted_list(given)));
  const std::string& key = given.front();
  VertexSelector selector;
  selector.source_file = owner.file();
  selector.source_line = owner.line(key);
  if (key == "box") {
    const Section box = owner.table("box");
    box.allow_only({"min", "max"});
    selector.kind = VertexSelector::Kind::Box;
    selector.box_min = box.get_required<Eigen::Vector3d>("min");
    selector.box_max = box.get_required<Eigen::Vector3d>("max");
    box.check((selector.box_min.array() <= selector.box_max.array()).all(), "max",
              fmt::format("at least min in every coordinate (min {}, max {})",
                          format_vector(selector.box_min), format_vector(selector.box_max)));
  } else if (key == "boundary_loop") {
    selector.kind = VertexSelector::Kind::BoundaryLoop;
    selector.boundary_loop = owner.get_required<int>("boundary_loop");
    owner.check(selector.boundary_loop >= 0, "boundary_loop",
                fmt::format("a loop index ≥ 0 (got {})", selector.boundary_loop));
  } else {
    selector.kind = VertexSelector::Kind::List;
    selector.indices = owner.get_required<std::vector<int>>("vertices");
    owner.check(!selector.indices.empty(), "vertices", "a non-empty list of vertex indices");
    for (int v : selector.indices)
      owner.check(v >= 0, "vertices", fmt::format("a list of indices ≥ 0 (got {})", v));
  }
  return selector;
}

RigidMotion read_motion(const Section& section) {
  section.allow_only({"start", "end", "translation", "axis_point", "axis", "angle_degrees"});
  RigidMotion motion;
  motion.start_time = section.get<double>("start", motion.start_time);
  motion.end_time = section.get<double>("end", motion.end_time);
  section.check(motion.end_time >= motion.start_time, "end",
                fmt::format("at least start ({:g}); got {:g}", motion.start_time, motion.end_time));
  motion.translation = section.get<Eigen::Vector3d>("translation", motion.translation);
  motion.axis_point = section.get<Eigen::Vector3d>("axis_point", motion.axis_point);
  motion.axis_direction = section.get<Eigen::Vector3d>("axis", motion.axis_direction);
  check_direction(section, "axis", motion.axis_direction);
  motion.angle_degrees = section.get<double>("angle_degrees", motion.angle_degrees);
  return motion;
}

std::string read_name(const Section& section) {
  const std::string name = section.get_required<std::string>("name");
  section.check(!name.empty(), "name", "a non-empty string");
  return name;
}

/// The optional `components` of a pin: a non-empty list of distinct names among "x", "y", "z"
/// (all three when absent).
PinComponents read_pin_components(const Section& section) {
  static const Keys kNames = {"x", "y", "z"};
  if (!section.has("components")) return {true, true, true};
  const auto names = section.get<std::vector<std::string>>("components", {});
  section.check(!names.empty(), "components",
                "a non-empty list of the fixed components among 'x', 'y', 'z' (omit the key to "
                "fix all three)");
  PinComponents fixed{false, false, false};
  for (const std::string& name : names) {
    const auto it = std::find(kNames.begin(), kNames.end(), name);
    if (it == kNames.end()) {
      // Every one-letter name is one edit from each choice, so only a change of case counts as
      // a typo worth suggesting.
      std::string lower = name;
      for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      const bool wrong_case = std::find(kNames.begin(), kNames.end(), lower) != kNames.end();
      const std::string hint = wrong_case ? fmt::format("did you mean '{}'? ", lower) : "";
      section.fail(section.line("components"),
                   fmt::format("unknown component '{}' in 'components' {}; {}expected one of {}",
                               name, section.where(), hint, quoted_list(kNames)));
    }
    bool& slot = fixed[static_cast<std::size_t>(it - kNames.begin())];
    section.check(!slot, "components",
                  fmt::format("a list of distinct components ('{}' is listed twice)", name));
    slot = true;
  }
  return fixed;
}

PinnedSet read_pin(const Section& section) {
  section.allow_only(with_selector_keys({"name", "components", "motion"}));
  PinnedSet pin;
  pin.name = read_name(section);
  pin.selector = read_selector(section);
  pin.components = read_pin_components(section);
  for (const Section& motion : section.tables("motion")) pin.motions.push_back(read_motion(motion));
  return pin;
}

Load read_load(const Section& section) {
  section.allow_only(with_selector_keys({"kind", "force"}));
  Load load;
  load.kind = read_choice(section, "kind", {"point", "line"}, "point") == "line"
                  ? Load::Kind::Line
                  : Load::Kind::Point;
  load.selector = read_selector(section);
  load.total_force = section.get_required<Eigen::Vector3d>("force");
  return load;
}

/// A [[shell.probe]]: a name and either a vertex selector (the selection's mean displacement)
/// or `pin`, the name of one of `pins` (that set's reaction).
Probe read_probe(const Section& section, const std::vector<PinnedSet>& pins) {
  section.allow_only(with_selector_keys({"name", "pin"}));
  Probe probe;
  probe.name = read_name(section);
  if (!section.has("pin")) {
    probe.selector = read_selector(section);
    return probe;
  }
  for (const std::string& key : kSelectorKeys)
    if (section.has(key))
      section.fail(section.line(key),
                   fmt::format("'{}' and 'pin' {} exclude each other: a probe records either a "
                               "selection's displacement or a pin's reaction",
                               key, section.where()));
  probe.kind = ProbeKind::reaction;
  probe.pin = section.get_required<std::string>("pin");
  Keys pin_names;
  for (const PinnedSet& pin : pins) pin_names.push_back(pin.name);
  if (std::find(pin_names.begin(), pin_names.end(), probe.pin) == pin_names.end()) {
    const auto suggestion = suggest_key(probe.pin, pin_names);
    section.fail(section.line("pin"),
                 fmt::format("unknown pin '{}' {}; {}", probe.pin, section.where(),
                             suggestion ? fmt::format("did you mean '{}'?", *suggestion)
                             : pin_names.empty()
                                 ? std::string("the shell has no [[shell.pin]]")
                                 : fmt::format("the shell's pins: {}", quoted_list(pin_names))));
  }
  return probe;
}

/// Fails if `name` was already used by an earlier item of the same kind.
void check_unique_name(const Section& section, std::set<std::string>& used, const std::string& name,
                       std::string_view kind) {
  if (!used.insert(name).second)
    section.fail(section.line("name"), fmt::format("{} name '{}' is used twice; names must be "
                                                   "unique",
                                                   kind, name));
}

/// A [[shell]]; its probes' names join `probe_names`, the scene's (they name its outputs).
Shell read_shell(const Section& section, const fs::path& scene_path,
                 std::set<std::string>& probe_names) {
  section.allow_only(
      {"name", "mesh", "placement", "material", "bending", "pin", "load", "probe"});
  Shell shell;
  shell.name = read_name(section);
  shell.mesh = read_mesh_source(section, scene_path);
  const Section material = section.table("material");
  shell.material = read_material(material);
  shell.strain_limit = read_strain_limit(material);
  shell.bending = read_bending_model(section);
  std::set<std::string> pin_names;
  for (const Section& pin : section.tables("pin")) {
    shell.pins.push_back(read_pin(pin));
    check_unique_name(pin, pin_names, shell.pins.back().name, "pin");
  }
  for (const Section& load : section.tables("load")) shell.loads.push_back(read_load(load));
  for (const Section& probe : section.tables("probe")) {
    shell.probes.push_back(read_probe(probe, shell.pins));
    check_unique_name(probe, probe_names, shell.probes.back().name, "probe");
  }
  return shell;
}

// ---------------------------------------------------------------------------------------------
// Top level

TimeStepping read_time(const Section& root) {
  TimeStepping time;
  const auto section = root.optional_table("time");
  if (!section) return time;
  section->allow_only({"step", "frames"});
  time.step = read_positive(*section, "step", time.step);
  time.frames = read_count(*section, "frames", time.frames);
  return time;
}

/// The [load_scale] table: a ramp from 0 at `start` to 1 at `end`, or `keyframes` [[t, s], ...]
/// with times in non-decreasing order.
LoadScale read_load_scale(const Section& root) {
  LoadScale scale;
  const auto section = root.optional_table("load_scale");
  if (!section) return scale;
  section->allow_only({"start", "end", "keyframes"});
  if (!section->has("keyframes")) {
    const double start = section->get<double>("start", 0.0);
    const double end = section->get<double>("end", 1.0);
    section->check(end >= start, "end",
                   fmt::format("at least start ({:g}); got {:g}", start, end));
    scale.keyframes = {{start, 0.0}, {end, 1.0}};
    return scale;
  }
  for (const std::string key : {"start", "end"})
    if (section->has(key))
      section->fail(section->line(key),
                    fmt::format("'{}' and 'keyframes' {} exclude each other: give a ramp (start, "
                                "end) or keyframes",
                                key, section->where()));
  const auto keys = section->get_required<std::vector<Eigen::Vector2d>>("keyframes");
  section->check(!keys.empty(), "keyframes", "a non-empty array of [time, scale] keyframes");
  scale.keyframes.clear();
  for (const Eigen::Vector2d& key : keys) {
    if (!scale.keyframes.empty())
      section->check(key.x() >= scale.keyframes.back().first, "keyframes",
                     fmt::format("in time order ({:g} follows {:g})", key.x(),
                                 scale.keyframes.back().first));
    scale.keyframes.emplace_back(key.x(), key.y());
  }
  return scale;
}

SolverSettings read_solver(const Section& root) {
  SolverSettings solver;
  const auto section = root.optional_table("solver");
  if (!section) return solver;
  section->allow_only({"tolerance", "max_iterations", "frame_solution", "hessian"});
  solver.tolerance = read_optional_positive(*section, "tolerance");
  solver.max_iterations = read_count(*section, "max_iterations", solver.max_iterations);
  solver.frame_solution =
      read_choice(*section, "frame_solution", {"equilibrium", "fixed_step"}, "equilibrium") ==
              "fixed_step"
          ? FrameSolution::fixed_step
          : FrameSolution::equilibrium;
  solver.project_on_demand =
      read_choice(*section, "hessian", {"projected", "project_on_demand"}, "projected") ==
      "project_on_demand";
  return solver;
}

/// The [hierarchy] table; refine_frame must name one of the scene's frames.
HierarchyOptions read_hierarchy(const Section& root, const TimeStepping& time) {
  HierarchyOptions hierarchy;
  const auto section = root.optional_table("hierarchy");
  if (!section) return hierarchy;
  section->allow_only(
      {"levels", "vertex_ratio", "preview_tolerance", "preview_iterations", "refine_frame"});
  hierarchy.levels = read_count(*section, "levels", hierarchy.levels);
  hierarchy.vertex_ratio = read_unit_fraction(*section, "vertex_ratio", hierarchy.vertex_ratio);
  hierarchy.preview_tolerance = read_optional_positive(*section, "preview_tolerance");
  hierarchy.preview_iterations =
      read_count(*section, "preview_iterations", hierarchy.preview_iterations);
  hierarchy.refine_frame = section->get_optional<int>("refine_frame");
  if (hierarchy.refine_frame)
    section->check(*hierarchy.refine_frame >= 1 && *hierarchy.refine_frame <= time.frames,
                   "refine_frame",
                   fmt::format("a frame in 1..{} ([time] frames; got {})", time.frames,
                               *hierarchy.refine_frame));
  return hierarchy;
}

/// A [[contact.pair]]: two body names from `body_names` (shells and colliders) and their μ.
BodyPairFriction read_pair_friction(const Section& section,
                                    const std::set<std::string>& body_names) {
  section.allow_only({"bodies", "friction"});
  const auto bodies = section.get_required<std::vector<std::string>>("bodies");
  section.check(bodies.size() == 2, "bodies",
                fmt::format("a list of two shell or collider names (got {})", bodies.size()));
  for (const std::string& body : bodies)
    if (!body_names.contains(body)) {
      const Keys known(body_names.begin(), body_names.end());
      const auto suggestion = suggest_key(body, known);
      section.fail(
          section.line("bodies"),
          fmt::format("unknown body '{}' in 'bodies' {}; {}", body, section.where(),
                      suggestion ? fmt::format("did you mean '{}'?", *suggestion)
                                 : fmt::format("shells and colliders: {}", quoted_list(known))));
    }
  return {{bodies[0], bodies[1]}, read_non_negative(section, "friction", 0.0)};
}

/// The [contact] table with its optional [contact.ccd] sub-table and [[contact.pair]] list;
/// pairs name bodies from `body_names`.
ContactSettings read_contact(const Section& root, const std::set<std::string>& body_names) {
  ContactSettings contact;
  const auto section = root.optional_table("contact");
  if (!section) return contact;
  section->allow_only({"enabled", "self_contact", "activation_distance", "thickness", "stiffness",
                       "friction", "friction_slip_velocity", "pair", "skip_when_apart", "ccd"});
  contact.enabled = section->get_optional<bool>("enabled");
  contact.self_contact = section->get<bool>("self_contact", contact.self_contact);
  contact.activation_distance = read_optional_positive(*section, "activation_distance");
  contact.thickness = read_non_negative(*section, "thickness", contact.thickness);
  contact.stiffness = read_optional_positive(*section, "stiffness");
  contact.friction = read_non_negative(*section, "friction", contact.friction);
  contact.friction_slip_velocity = read_optional_positive(*section, "friction_slip_velocity");
  std::set<std::pair<std::string, std::string>> pairs_given;
  for (const Section& pair : section->tables("pair")) {
    contact.pair_friction.push_back(read_pair_friction(pair, body_names));
    const auto& [a, b] = contact.pair_friction.back().bodies;
    if (!pairs_given.insert(std::minmax(a, b)).second)
      pair.fail(pair.line("bodies"),
                fmt::format("the pair '{}', '{}' {} is given twice", a, b, pair.where()));
  }
  contact.skip_when_apart = section->get<bool>("skip_when_apart", contact.skip_when_apart);
  if (const auto ccd = section->optional_table("ccd")) {
    ccd->allow_only({"rescaling", "ratio_bound", "max_iterations"});
    contact.ccd_rescaling = read_unit_fraction(*ccd, "rescaling", contact.ccd_rescaling);
    contact.ccd_ratio_bound = read_unit_fraction(*ccd, "ratio_bound", contact.ccd_ratio_bound);
    contact.ccd_max_iterations = read_count(*ccd, "max_iterations", contact.ccd_max_iterations);
  }
  return contact;
}

/// A [[collider]]: a name, a mesh with its placement (as for shells) and optional motions.
Collider read_collider(const Section& section, const fs::path& scene_path) {
  section.allow_only({"name", "mesh", "placement", "motion"});
  Collider collider;
  collider.name = read_name(section);
  collider.mesh = read_mesh_source(section, scene_path);
  for (const Section& motion : section.tables("motion"))
    collider.motions.push_back(read_motion(motion));
  return collider;
}

}  // namespace

toml::table parse_scene_document(std::string_view text, const fs::path& path) {
  const std::string source = path.string();
  try {
    return toml::parse(text, std::string_view(source));
  } catch (const toml::parse_error& error) {
    std::string message = fmt::format("TOML syntax error: {}", error.description());
    // TOML 1.0 inline tables end at the line's end, a frequent surprise.
    if (message.find("inline table") != std::string::npos &&
        message.find("'\\n'") != std::string::npos)
      message += " (an inline table { ... } must fit on one line; use a [table] section instead)";
    throw InputError(
        located_message(source, static_cast<long>(error.source().begin.line), message));
  }
}

Scene read_scene(const fs::path& path) {
  return read_scene_text(read_input_file(path, "scene file"), path);
}

Scene read_scene_text(std::string_view text, const fs::path& path) {
  return read_scene_document(parse_scene_document(text, path), path);
}

Scene read_scene_document(const toml::table& document, const fs::path& path) {
  const Section root(document, "", path.string());
  root.allow_only({"name", "gravity", "time", "load_scale", "solver", "hierarchy", "contact",
                   "shell", "collider"});
  Scene scene;
  scene.source = path;
  scene.name = root.get<std::string>("name", path.stem().string());
  root.check(!scene.name.empty(), "name", "a non-empty string");
  scene.gravity = root.get<Eigen::Vector3d>("gravity", scene.gravity);
  scene.time = read_time(root);
  scene.load_scale = read_load_scale(root);
  scene.solver = read_solver(root);
  scene.hierarchy = read_hierarchy(root, scene.time);
  const std::vector<Section> shells = root.tables("shell");
  if (shells.empty()) root.fail(0, "the scene has no shell; add at least one [[shell]] section");
  std::set<std::string> shell_names, probe_names;
  for (const Section& shell : shells) {
    scene.shells.push_back(read_shell(shell, path, probe_names));
    check_unique_name(shell, shell_names, scene.shells.back().name, "shell");
  }
  for (const Section& collider : root.tables("collider")) {
    scene.colliders.push_back(read_collider(collider, path));
    check_unique_name(collider, shell_names, scene.colliders.back().name, "shell or collider");
  }
  scene.contact = read_contact(root, shell_names);  // its pairs name shells and colliders
  return scene;
}

}  // namespace psq

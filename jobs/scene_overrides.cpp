#include "jobs/scene_overrides.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cctype>
#include <optional>

#include "engine/core/input_file.hpp"
#include "engine/scene/key_suggestion.hpp"

namespace psq::jobs {
namespace {

std::vector<std::string> split_path(std::string_view path) {
  std::vector<std::string> keys;
  for (std::size_t start = 0;;) {
    const std::size_t dot = path.find('.', start);
    keys.emplace_back(path.substr(start, dot == std::string_view::npos ? dot : dot - start));
    if (dot == std::string_view::npos) return keys;
    start = dot + 1;
  }
}

/// An array index as a path writes it: decimal digits without a leading zero, so that each
/// element has one spelling (and so one job id).
std::optional<std::size_t> parse_index(std::string_view key) {
  if (key.empty() || key.size() > 9 || (key.size() > 1 && key.front() == '0')) return std::nullopt;
  if (!std::all_of(key.begin(), key.end(), [](unsigned char c) { return std::isdigit(c); }))
    return std::nullopt;
  return std::stoul(std::string(key));
}

/// The name an element of an array is addressed by: a table's `name` string, if it has one.
std::optional<std::string> element_name(const toml::node& element) {
  const toml::table* table = element.as_table();
  if (!table) return std::nullopt;
  const toml::node* name = table->get("name");
  if (!name || !name->is_string()) return std::nullopt;
  return name->as_string()->get();
}

/// How many of keys[k...] the name spans (its dot-separated parts, as a name may contain
/// dots), or 0 if they do not spell it.
std::size_t keys_spanned(const std::string& name, const std::vector<std::string>& keys,
                         std::size_t k) {
  const std::vector<std::string> parts = split_path(name);
  if (k + parts.size() > keys.size()) return 0;
  return std::equal(parts.begin(), parts.end(), keys.begin() + static_cast<std::ptrdiff_t>(k))
             ? parts.size()
             : 0;
}

struct Element {
  std::size_t index = 0;
  std::size_t keys = 0;  ///< how many keys of the path address it
};

/// The element of `array` that keys[k...] address: a named table by its name (the longest
/// name that matches, in case one name extends another), an unnamed element by its index.
std::optional<Element> find_element(const toml::array& array, const std::vector<std::string>& keys,
                                    std::size_t k) {
  std::optional<Element> found;
  for (std::size_t i = 0; i < array.size(); ++i)
    if (const auto name = element_name(*array.get(i)))
      if (const std::size_t spanned = keys_spanned(*name, keys, k);
          spanned > (found ? found->keys : 0))
        found = Element{i, spanned};
  if (found) return found;
  const auto index = parse_index(keys[k]);
  if (index && *index < array.size() && !element_name(*array.get(*index)))
    return Element{*index, 1};
  return std::nullopt;
}

std::string joined_path(const std::string& prefix, std::string_view key) {
  return prefix.empty() ? std::string(key) : prefix + "." + std::string(key);
}

/// The path of every number under `node`, whose own path is `prefix`.
void collect_numeric_paths(const toml::node& node, const std::string& prefix,
                           std::vector<std::string>& paths) {
  if (const toml::table* table = node.as_table()) {
    for (auto&& [key, child] : *table)
      collect_numeric_paths(child, joined_path(prefix, key.str()), paths);
  } else if (const toml::array* array = node.as_array()) {
    for (std::size_t i = 0; i < array->size(); ++i) {
      const toml::node& element = *array->get(i);
      collect_numeric_paths(
          element, joined_path(prefix, element_name(element).value_or(std::to_string(i))), paths);
    }
  } else if (node.is_number()) {
    paths.push_back(prefix);
  }
}

std::string type_name(const toml::node& node) {
  if (node.is_table()) return "a table";
  if (node.is_array()) return "an array";
  if (node.is_string()) return "a string";
  if (node.is_boolean()) return "a boolean";
  return "a date or time";
}

/// Calls `insert` with `value` (an integer or a real) as a TOML value. The new value has no
/// source line: the reader's messages about it must not point at the scene file's line.
template <class Insert>
void insert_number(const nlohmann::json& value, Insert&& insert) {
  if (value.is_number_integer())
    insert(toml::value<std::int64_t>(value.get<std::int64_t>()));
  else
    insert(toml::value<double>(value.get<double>()));
}

}  // namespace

/// Where a path leads in a document: to a number in a table or an array, or, for a value
/// the document lacks, to the deepest table on the path and the keys below it.
struct SceneDocument::Slot {
  toml::node* parent = nullptr;
  std::string key;                   ///< of the number, when `parent` is a table
  std::size_t index = 0;             ///< of the number, when `parent` is an array
  std::vector<std::string> missing;  ///< the path's keys below `parent` the document lacks
};

SceneDocument SceneDocument::read(const std::filesystem::path& file) {
  return SceneDocument(read_input_file(file, "scene file"), file);
}

SceneDocument::SceneDocument(std::string_view text, std::filesystem::path file)
    : file_(std::move(file)), document_(parse_scene_document(text, file_)) {
  // Refuses an invalid base scene here, so that no override is blamed for it.
  read_scene_document(document_, file_);
}

std::vector<std::string> SceneDocument::numeric_paths() const {
  std::vector<std::string> paths;
  collect_numeric_paths(document_, "", paths);
  return paths;
}

void SceneDocument::fail_unknown(const std::string& path,
                                 const std::vector<std::string>& also_near) const {
  // Nearby keys the reader names come first: ties in suggest_key go to the earlier candidate.
  std::vector<std::string> candidates = also_near;
  const std::vector<std::string> numbers = numeric_paths();
  candidates.insert(candidates.end(), numbers.begin(), numbers.end());
  const auto suggestion = suggest_key(path, candidates);
  throw OverrideError(
      path, suggestion
                ? fmt::format("unknown parameter '{}'; did you mean '{}'?", path, *suggestion)
                : fmt::format("unknown parameter '{}'; the scene's numbers are {}", path,
                              fmt::join(numbers, ", ")));
}

SceneDocument::Slot SceneDocument::locate(toml::table& document, const std::string& path) const {
  const std::vector<std::string> keys = split_path(path);
  Slot slot;  // where the last key led; split_path gives at least one key
  toml::node* node = &document;
  for (std::size_t k = 0; k < keys.size();) {
    if (toml::table* table = node->as_table()) {
      toml::node* child = table->get(keys[k]);
      if (!child) {
        slot = {table, "", 0, {keys.begin() + static_cast<std::ptrdiff_t>(k), keys.end()}};
        // Only tables and keys can be added: an index below an absent key leads nowhere.
        if (std::any_of(slot.missing.begin(), slot.missing.end(),
                        [](const std::string& key) { return parse_index(key).has_value(); }))
          fail_unknown(path);
        return slot;
      }
      slot = {table, keys[k], 0, {}};
      node = child;
      ++k;
    } else if (toml::array* array = node->as_array()) {
      const auto element = find_element(*array, keys, k);
      if (!element) fail_unknown(path);
      slot = {array, "", element->index, {}};
      node = array->get(element->index);
      k += element->keys;
    } else {
      fail_unknown(path);  // the path goes on below a number or a string
    }
  }
  if (!node->is_number()) {
    std::vector<std::string> inside;
    for (const std::string& number : numeric_paths())
      if (number.starts_with(path + ".")) inside.push_back(number);
    throw OverrideError(
        path, fmt::format("parameter '{}' is {} in the scene, not a number; only numbers can be "
                          "varied{}",
                          path, type_name(*node),
                          inside.empty() ? "" : fmt::format(", such as '{}'", inside.front())));
  }
  return slot;
}

void SceneDocument::put(toml::table& document, const std::string& path,
                        const nlohmann::json& value) const {
  if (!value.is_number())
    throw OverrideError(
        path, fmt::format("parameter '{}' must be a number (got {})", path, value.dump()));
  const Slot slot = locate(document, path);
  if (slot.missing.empty()) {
    if (toml::table* table = slot.parent->as_table())
      insert_number(value, [&](auto&& number) { table->insert_or_assign(slot.key, number); });
    else
      insert_number(value, [&](auto&& number) {
        toml::array& array = *slot.parent->as_array();
        array.replace(array.cbegin() + static_cast<std::ptrdiff_t>(slot.index), number);
      });
    return;
  }
  toml::table* table = slot.parent->as_table();
  for (std::size_t k = 0; k + 1 < slot.missing.size(); ++k)
    table = table->insert_or_assign(slot.missing[k], toml::table{}).first->second.as_table();
  insert_number(value,
                [&](auto&& number) { table->insert_or_assign(slot.missing.back(), number); });
}

void SceneDocument::check_path(const std::string& path) const {
  toml::table probe = document_;
  const Slot slot = locate(probe, path);
  if (slot.missing.empty()) return;
  // A key the file omits: the reader tells whether the format defines it. The probe's value
  // is arbitrary; a rule it breaks means the key is defined (the values given are checked
  // one by one later).
  put(probe, path, 0);
  try {
    read_scene_document(probe, file_);
  } catch (const UnknownKeyError& error) {
    std::vector<std::string> keys = split_path(path);
    const auto unknown = std::find(keys.end() - static_cast<std::ptrdiff_t>(slot.missing.size()),
                                   keys.end(), error.key());
    if (!error.nearest() || unknown == keys.end()) fail_unknown(path);
    *unknown = *error.nearest();
    fail_unknown(path, {fmt::format("{}", fmt::join(keys, "."))});
  } catch (const InputError&) {
  }
}

std::optional<std::string> SceneDocument::refusal(const std::string& path,
                                                  const nlohmann::json& value) const {
  toml::table edited = document_;
  put(edited, path, value);
  try {
    read_scene_document(edited, file_);
  } catch (const InputError& error) {
    return error.what();
  }
  return std::nullopt;
}

nlohmann::json SceneDocument::canonical_override(const std::string& path,
                                                 const nlohmann::json& value) const {
  check_path(path);
  // The reader takes an integer for a real but not a real for an integer: an integer value
  // that reads as a real is a real parameter, stored as a double so that 500000 and 5e5
  // make the same job.
  if (value.is_number_integer()) {
    const nlohmann::json real = value.get<double>();
    if (!refusal(path, real)) return real;
  }
  if (const auto message = refusal(path, value))
    throw OverrideError(path, fmt::format("parameter '{}': {}", path, *message));
  return value;
}

Scene SceneDocument::apply(const Overrides& overrides) const {
  toml::table edited = document_;
  for (const auto& [path, value] : overrides) put(edited, path, value);
  try {
    return read_scene_document(edited, file_);
  } catch (const UnknownKeyError&) {
    for (const auto& [path, value] : overrides) check_path(path);  // names the unknown one
    throw;
  } catch (const InputError& error) {
    std::vector<std::string> paths;
    for (const auto& [path, value] : overrides) paths.push_back(path);
    throw OverrideError(
        fmt::format("{}", fmt::join(paths, ", ")),
        paths.size() == 1
            ? fmt::format("parameter '{}': {}", paths.front(), error.what())
            : fmt::format("parameters '{}' together: {}", fmt::join(paths, "', '"), error.what()));
  }
}

}  // namespace psq::jobs

#include "engine/contact/ccd_query_file.hpp"

#include <fmt/format.h>
#include <gmp.h>
#include <mpfr.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>

#include "engine/core/error.hpp"

namespace psq {
namespace {

constexpr int kRowsPerQuery = 8;
constexpr int kColumns = 7;

bool is_decimal_integer(std::string_view word) {
  if (!word.empty() && (word.front() == '-' || word.front() == '+')) word.remove_prefix(1);
  return !word.empty() && std::all_of(word.begin(), word.end(), [](char c) {
    return std::isdigit(static_cast<unsigned char>(c)) != 0;
  });
}

/// GMP's parser rejects a leading '+'.
std::string_view without_plus(std::string_view word) {
  if (!word.empty() && word.front() == '+') word.remove_prefix(1);
  return word;
}

/// Narrows MPFR's exponent range to that of IEEE doubles for its lifetime, so that rounding
/// to 53 bits followed by mpfr_subnormalize rounds exactly as a double does (subnormals too).
class DoubleExponentRange {
 public:
  DoubleExponentRange() : emin_(mpfr_get_emin()), emax_(mpfr_get_emax()) {
    mpfr_set_emin(-1073);  // 2⁻¹⁰⁷⁴, the smallest subnormal, is 0.5·2⁻¹⁰⁷³ in MPFR's terms
    mpfr_set_emax(1024);
  }
  ~DoubleExponentRange() {
    mpfr_set_emin(emin_);
    mpfr_set_emax(emax_);
  }
  DoubleExponentRange(const DoubleExponentRange&) = delete;
  DoubleExponentRange& operator=(const DoubleExponentRange&) = delete;

 private:
  mpfr_exp_t emin_, emax_;
};

/// An exact rational, freed on scope exit.
class Rational {
 public:
  Rational() { mpq_init(value_); }
  ~Rational() { mpq_clear(value_); }
  Rational(const Rational&) = delete;
  Rational& operator=(const Rational&) = delete;
  mpq_ptr get() { return value_; }

 private:
  mpq_t value_;
};

std::string_view trimmed(std::string_view text) {
  auto space = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
  while (!text.empty() && space(text.front())) text.remove_prefix(1);
  while (!text.empty() && space(text.back())) text.remove_suffix(1);
  return text;
}

std::vector<std::string_view> split_fields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t begin = 0;
  while (true) {
    const std::size_t comma = line.find(',', begin);
    fields.push_back(trimmed(line.substr(begin, comma - begin)));
    if (comma == std::string_view::npos) return fields;
    begin = comma + 1;
  }
}

/// One parsed row: a vertex position and the row's truth flag.
struct Row {
  Eigen::Vector3d position;
  bool truth = false;
};

Row parse_row(std::string_view line, const std::string& file, long line_number) {
  auto fail = [&](const std::string& message) {
    throw InputError(located_message(file, line_number, message));
  };
  const std::vector<std::string_view> fields = split_fields(line);
  if (fields.size() != kColumns)
    fail(fmt::format("expected {} columns x_num,x_den,y_num,y_den,z_num,z_den,truth, found {}",
                     kColumns, fields.size()));
  static constexpr std::array<const char*, 3> kAxes = {"x", "y", "z"};
  Row row;
  for (int axis = 0; axis < 3; ++axis) {
    try {
      row.position[axis] = rational_to_double(fields[2 * axis], fields[2 * axis + 1]);
    } catch (const std::logic_error& e) {  // std::invalid_argument or std::out_of_range
      fail(fmt::format("{} coordinate {}/{}: {}", kAxes[axis], fields[2 * axis],
                       fields[2 * axis + 1], e.what()));
    }
  }
  if (fields[6] != "0" && fields[6] != "1")
    fail(fmt::format("truth (column 7) must be 0 or 1, found '{}'", fields[6]));
  row.truth = fields[6] == "1";
  return row;
}

bool is_blank(std::string_view line) { return trimmed(line).empty(); }

}  // namespace

CcdQueryKind ccd_query_kind(const std::filesystem::path& file) {
  const std::filesystem::path absolute = std::filesystem::absolute(file);
  for (auto part = absolute.end(); part != absolute.begin();) {
    --part;
    if (*part == "vertex-face") return CcdQueryKind::vertex_face;
    if (*part == "edge-edge") return CcdQueryKind::edge_edge;
  }
  throw InputError(located_message(
      file.string(), 0,
      "cannot tell vertex-face from edge-edge queries: put the file in a folder named "
      "'vertex-face' or 'edge-edge'"));
}

double rational_to_double(std::string_view numerator, std::string_view denominator) {
  for (const std::string_view word : {numerator, denominator})
    if (!is_decimal_integer(word))
      throw std::invalid_argument(fmt::format("'{}' is not a decimal integer", word));
  const std::string text = fmt::format("{}/{}", without_plus(numerator), without_plus(denominator));
  Rational q;
  if (mpq_set_str(q.get(), text.c_str(), 10) != 0)
    throw std::invalid_argument(fmt::format("'{}' is not a rational number", text));
  if (mpz_sgn(mpq_denref(q.get())) == 0) throw std::invalid_argument("zero denominator");
  mpq_canonicalize(q.get());

  double value = 0;
  {
    const DoubleExponentRange range;
    mpfr_t rounded;
    mpfr_init2(rounded, 53);
    const int inexact = mpfr_set_q(rounded, q.get(), MPFR_RNDN);
    mpfr_subnormalize(rounded, inexact, MPFR_RNDN);
    value = mpfr_get_d(rounded, MPFR_RNDN);
    mpfr_clear(rounded);
  }
  if (!std::isfinite(value)) throw std::out_of_range("the value is beyond the range of a double");
  return value;
}

std::vector<CcdQuery> read_ccd_queries(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(located_message(name, 0, "cannot open the CCD query file"));

  std::vector<CcdQuery> queries;
  CcdQuery query;
  int rows = 0;
  long line_number = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_number;
    if (is_blank(line)) continue;
    const Row row = parse_row(line, name, line_number);
    if (rows == 0) {
      query.line = line_number;
      query.truth = row.truth;
    } else if (row.truth != query.truth) {
      throw InputError(located_message(
          name, line_number,
          fmt::format("truth {} differs from the truth {} of this query's first row (line {}); "
                      "the 8 rows of a query share one truth",
                      int(row.truth), int(query.truth), query.line)));
    }
    (rows < 4 ? query.start[rows] : query.end[rows - 4]) = row.position;
    if (++rows == kRowsPerQuery) {
      queries.push_back(query);
      rows = 0;
    }
  }
  if (in.bad()) throw InputError(located_message(name, line_number, "read error"));
  if (rows != 0)
    throw InputError(located_message(
        name, query.line,
        fmt::format("the file ends inside this query: {} of its {} rows are present", rows,
                    kRowsPerQuery)));
  return queries;
}

CcdResult run_ccd_query(const CcdQuery& query, CcdQueryKind kind,
                        const AdditiveCcdSettings& settings) {
  return kind == CcdQueryKind::vertex_face ? point_triangle_ccd(query.start, query.end, settings)
                                           : edge_edge_ccd(query.start, query.end, settings);
}

CcdTally& CcdTally::operator+=(const CcdTally& other) {
  queries += other.queries;
  touching += other.touching;
  false_negatives += other.false_negatives;
  false_positives += other.false_positives;
  return *this;
}

CcdTally tally_ccd_queries(const std::vector<CcdQuery>& queries, CcdQueryKind kind,
                           const AdditiveCcdSettings& settings) {
  CcdTally tally;
  for (const CcdQuery& query : queries) {
    const bool collision = run_ccd_query(query, kind, settings).collision;
    ++tally.queries;
    tally.touching += query.truth;
    tally.false_negatives += query.truth && !collision;
    tally.false_positives += !query.truth && collision;
  }
  return tally;
}

}  // namespace psq

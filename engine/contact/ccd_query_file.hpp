#pragma once
// CCD benchmark query files (the "Sample-Queries" format of Wang et al. 2021, see
// ../shared/data/README.md): reading them and scoring the additive CCD against their truth.
//
// A file holds queries of one kind, told by the folder it sits in (vertex-face or edge-edge).
// Each query is 8 rows "x_num,x_den,y_num,y_den,z_num,z_den,truth": the 4 vertices at t = 0,
// then the same 4 at t = 1 (p, t0, t1, t2 or a0, a1, b0, b1). Coordinates are exact rationals.

#include <filesystem>
#include <string_view>
#include <vector>

#include "engine/contact/additive_ccd.hpp"

namespace psq {

/// The primitive pair a query file holds.
enum class CcdQueryKind { vertex_face, edge_edge };

/// One query: a primitive pair moving linearly over t ∈ [0, 1], with the exact answer.
struct CcdQuery {
  PairPositions start;  ///< the four vertices at t = 0 (rows 1–4)
  PairPositions end;    ///< the same vertices at t = 1 (rows 5–8)
  bool truth = false;   ///< the primitives touch at some t ∈ [0, 1]
  long line = 0;        ///< line of the query's first row in its file
};

/// The kind named by the last path component that is "vertex-face" or "edge-edge" (of the
/// absolute path). InputError naming the file when there is none.
CcdQueryKind ccd_query_kind(const std::filesystem::path& file);

/// numerator/denominator (decimal integers of any length, optional sign) rounded to the
/// nearest double, ties to even, subnormals included. Throws std::invalid_argument for a
/// malformed integer or a zero denominator and std::out_of_range beyond the double range.
double rational_to_double(std::string_view numerator, std::string_view denominator);

/// Every query of a file. InputError naming the file and line for a row that is not 7
/// integers with a nonzero denominator and truth 0 or 1, a query whose rows disagree on the
/// truth, or a file that ends inside a query. Blank lines are skipped.
std::vector<CcdQuery> read_ccd_queries(const std::filesystem::path& file);

/// Runs the additive CCD of the query's kind on it.
CcdResult run_ccd_query(const CcdQuery& query, CcdQueryKind kind,
                        const AdditiveCcdSettings& settings);

/// How the CCD's answers compare with the truth over a set of queries.
struct CcdTally {
  long queries = 0;
  long touching = 0;         ///< queries whose truth is 1
  long false_negatives = 0;  ///< truth 1, but the CCD reported no collision
  long false_positives = 0;  ///< truth 0, but the CCD reported a collision

  CcdTally& operator+=(const CcdTally& other);
};

/// Runs every query and counts the CCD's misses and false alarms.
CcdTally tally_ccd_queries(const std::vector<CcdQuery>& queries, CcdQueryKind kind,
                           const AdditiveCcdSettings& settings);

}  // namespace psq

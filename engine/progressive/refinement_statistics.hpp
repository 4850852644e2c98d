#pragma once
// One refinement's statistics by name: the form the checkpoints (/statistics/refinement), the
// job store's level records, summary.json and the reports share (docs/progressive.md,
// "Refinement statistics"). Counts are stored as doubles like every other named value.

#include <map>
#include <optional>
#include <string>

#include "engine/progressive/safe_refinement.hpp"
#include "engine/progressive/strain_limit_correction.hpp"

namespace psq {

/// The statistics of the refinement into one level: `safe_initialization` with contact,
/// `strain_correction` with a strain limit, `seconds` for the whole refinement (prolongation
/// included). Non-finite values (no batch measured a gap) are left out, so that every stored
/// value is a number.
std::map<std::string, double> named_refinement_statistics(
    const std::optional<RefinementStats>& safe_initialization,
    const std::optional<StrainCorrectionStats>& strain_correction, double seconds);

}  // namespace psq

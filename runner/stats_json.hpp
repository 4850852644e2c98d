#pragma once
#include <nlohmann/json.hpp>

#include "engine/sim/quasistatic.hpp"

namespace psq::runner {

nlohmann::json phase_times_json(const PhaseTimes& times);
/// A frame's solve: convergence, energies, per-iteration residuals and time split.
nlohmann::json frame_json(const FrameRecord& record);

}  // namespace psq::runner

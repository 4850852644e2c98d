#pragma once
#include <nlohmann/json.hpp>

#include "engine/sim/quasistatic.hpp"

namespace psq::runner {

nlohmann::json phase_times_json(const PhaseTimes& times);
/// A frame's contact: κ, kinematic pull rounds, active pairs, skips and contact time (all zero
/// in a scene without contact).
nlohmann::json contact_json(const FrameRecord& record);
/// A frame's solve: convergence, energies, per-iteration residuals, time split, friction
/// iterations and contact_json.
nlohmann::json frame_json(const FrameRecord& record);
/// The probe readings of a frame: name, kind, value [x, y, z] and its magnitude each.
nlohmann::json probes_json(const std::vector<ProbeReading>& readings);

}  // namespace psq::runner

#pragma once
// A CI-sized contact scene shared by the progressive and the runner tests.

namespace psq::test {

/// A sheet held at its rim, pressed by a descending sphere (bunny_press with a sphere): the
/// frames are equilibria, and the pressed shape is unique up to the barrier's band: two solves
/// whose κ differ rest at gaps anywhere within d̂, so d̂ (0.27e-3 of the diagonal) is kept
/// below the 1e-3 of the diagonal by which the progressive and direct answers must agree.
inline constexpr const char* kPressScene = R"(
name = "press"
gravity = [0, 0, -9.81]
[time]
step = 0.04
frames = 10
[contact]
activation_distance = 2e-4
[[shell]]
name = "sheet"
mesh = { generator = "sheet", width = 0.5, height = 0.5, edge_length = 0.04 }
material = { youngs_modulus = 1e7, poisson_ratio = 0.4, density = 1000, thickness = 1e-3 }
[[shell.pin]]
name = "rim"
boundary_loop = 0
[[collider]]
name = "ball"
mesh = { generator = "sphere", radius = 0.1, edge_length = 0.03 }
placement = { translation = [0, 0, 0.1011] }
[[collider.motion]]
start = 0.0
end = 0.4
translation = [0, 0, -0.06]
)";

}  // namespace psq::test

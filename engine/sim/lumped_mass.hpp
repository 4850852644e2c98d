#pragma once
#include "engine/mesh/tri_mesh.hpp"
#include "engine/elastic/material.hpp"

namespace psq {

/// Lumped vertex masses ρ·h·(area/3) summed over each vertex's triangles.
Eigen::VectorXd lumped_vertex_masses(const TriMesh& rest, const Material& material);

}  // namespace psq

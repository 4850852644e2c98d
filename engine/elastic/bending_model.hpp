#pragma once
// Which discrete bending energy a shell uses. Kept apart from the energies themselves so that
// the scene model can name the choice without depending on their implementation.

namespace psq {

/// A shell's bending discretization (docs/midedge-bending.md, "Choosing").
enum class BendingModel {
  /// Dihedral-angle hinges, one per interior edge (engine/elastic/bending.hpp), k = D/6.
  hinge,
  /// Mid-edge shape operator, one element per face (engine/elastic/midedge_bending.hpp), with
  /// the halves split: consistent under load on the structured grid, ~4× the hinges' cost.
  midedge,
};

}  // namespace psq

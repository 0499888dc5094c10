// The bounded symplectic Euler step of a range of nodes (mass_spring.h, TissueIntegrator): a portable
// loop and an AVX2 one, chosen at run time. The AVX2 loop steps four nodes per instruction with the
// portable loop's operations in its order (no contraction, the build forbids it), so the lane width
// changes no bit.
#pragma once

#include <cstddef>
#include <limits>

#include "rtcore/geometry/vec3.h"

namespace resecto {

/// The arrays one step of the nodes reads and writes, node-indexed.
struct NodeStepArrays {
  const double* mass;             ///< m
  const double* stiffness_bound;  ///< R_K of this step
  const double* damping_bound;    ///< R_C of this step
  const Vec3* force;              ///< f of this step
  double* step_mass;              ///< D of the last step in, this step's out
  Vec3* v;                        ///< velocity in and out
  Vec3* x;                        ///< position in and out
};

/// What the nodes' step found.
struct NodeStepSummary {
  static constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
  double fastest2 = 0.0;                 ///< the largest |v|^2 after the step (NaNs ignored)
  std::size_t first_non_finite = kNone;  ///< the first node whose x + v sum is not finite
};

/// For nodes [begin, end): D = m + h^2 R_K / 2 + h R_C; a rise of D keeps the momentum D v (v *= D_old
/// / D), a fall keeps v; then v += (h / D) f and x += h v.
NodeStepSummary step_nodes_portable(const NodeStepArrays& nodes, double h_s, std::size_t begin, std::size_t end);
/// The same, four nodes per instruction; call only where cpu_has_avx2().
NodeStepSummary step_nodes_avx2(const NodeStepArrays& nodes, double h_s, std::size_t begin, std::size_t end);
/// The fastest loop this processor runs.
NodeStepSummary step_nodes(const NodeStepArrays& nodes, double h_s, std::size_t begin, std::size_t end);

}  // namespace resecto

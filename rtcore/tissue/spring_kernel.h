// The per-spring force kernel: a portable loop and an AVX2 one chosen at run time. Both form every
// spring's force with the same IEEE operations in the same order (no contraction, the build forbids
// it; + - * / sqrt are correctly rounded), so the lane width cannot change a bit of the result.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "rtcore/geometry/vec3.h"

namespace resecto {

/// Per-spring inputs and outputs, one array per field, in the network's spring order.
struct SpringArrays {
  std::vector<std::uint32_t> i, j;  ///< nodes, i < j (springs sorted by i, then j)
  std::vector<double> rest_m;       ///< rest length
  std::vector<double> k, c;         ///< stiffness (N/m), damping (N*s/m)
  std::vector<double> fx, fy, fz;   ///< the spring's force on node i of the last pass (node j gets minus)
};

/// Writes the force of springs [begin, end) at positions x and velocities v into fx, fy, fz:
/// f = (k (L - L0) + c (v_j - v_i).u) u with u = (x_j - x_i) / L (u = 0 when L = 0). Returns how
/// many of them are compressed below half their rest length.
std::size_t spring_forces_portable(SpringArrays& springs, const Vec3* x, const Vec3* v, std::size_t begin, std::size_t end);

/// The same with four springs per instruction; call only where cpu_has_avx2().
std::size_t spring_forces_avx2(SpringArrays& springs, const Vec3* x, const Vec3* v, std::size_t begin, std::size_t end);

/// Whether this processor runs the AVX2 kernel (checked once).
bool cpu_has_avx2();

/// The fastest kernel this processor runs, over all springs.
std::size_t spring_forces(SpringArrays& springs, const Vec3* x, const Vec3* v);

}  // namespace resecto

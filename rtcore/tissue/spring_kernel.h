// The per-spring force kernel and the per-node sum of the springs' forces: a portable loop and an
// AVX2 one for each, chosen at run time. Both form every value with the same IEEE operations in the
// same order (no contraction, the build forbids it; + - * / sqrt are correctly rounded), so the lane
// width cannot change a bit of the result.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "rtcore/base/cpu_features.h"
#include "rtcore/geometry/vec3.h"

namespace resecto {

/// One spring's force on its node i, as a 32-byte row (x, y, z, 0): the node pass adds it with one
/// aligned load, where three separate arrays cost three cache lines.
struct alignas(32) SpringForce {
  double x = 0.0, y = 0.0, z = 0.0, unused = 0.0;
};

/// Per-spring inputs and outputs, one array per field, in the network's spring order.
struct SpringArrays {
  std::vector<std::uint32_t> i, j;  ///< nodes (sorted by i; i < j for the mesh's springs, i > j for refinement's)
  std::vector<double> rest_m;       ///< rest length
  std::vector<double> k, c;         ///< stiffness (N/m), damping (N*s/m)
  /// The spring's force on node i of the last pass (node j gets minus), then two padding rows, +0 at
  /// [spring count] and -0 after it, which leave any sum's every bit alone (x - (+0) = x and
  /// x + (-0) = x for every x): the node pass adds them where a node's list is shorter than its group's.
  std::vector<SpringForce> f;
  /// Room for every spring: the force pass lists here, ascending, the springs it found compressed
  /// below half their rest length, so the rare bound correction visits only those.
  std::vector<std::uint32_t> compressed;
};

/// Which springs meet at each node, in the order the node pass adds them.
struct SpringIncidence {
  /// Per node + 1: offsets into `second_springs` of the springs whose node j it is (ascending). All
  /// come before its springs as node i, since springs are sorted by i.
  std::vector<std::uint32_t> second_first;
  std::vector<std::uint32_t> second_springs;
  /// Per node + 1: the spring range whose node i it is.
  std::vector<std::uint32_t> first_first;

  /// The same lists for the AVX2 node pass, four nodes to a group (group g: nodes 4g..4g+3; a last
  /// group of fewer nodes has none): each group's lists padded to its longest with the padding rows
  /// and interleaved, so node 4g+k's entry e is at [4 (group_second_first[g] + e) + k]. Four sums then
  /// run side by side, each in its node's own order.
  std::vector<std::uint32_t> group_second_first, group_second;
  std::vector<std::uint32_t> group_first_first, group_first;
};

/// Nodes per group of SpringIncidence's interleaved lists.
inline constexpr std::size_t kSpringSumGroup = 4;

/// Whether the AVX2 node pass sums four nodes side by side (SpringIncidence's groups) on this
/// processor, or node by node (no groups are built). Same bits either way; only the speed differs, and
/// it differs by processor (benchmarks/results/README.md, "Tissue mechanics"): on the Intel Xeon
/// (Cascade Lake) vCPU one node's chain of adds stalled the pass, and the groups made the whole step
/// 13-15% faster; on the AMD EPYC (Zen 5) vCPU, whose out-of-order window overlaps the chains by
/// itself, an earlier lockstep version with the same padding was 20% slower.
inline bool spring_sums_in_groups() {
  static const bool in_groups = cpu_has_avx2() && __builtin_cpu_is("intel");
  return in_groups;
}

/// Writes the force of springs [begin, end) at positions x and velocities v into f:
/// f = (k (L - L0) + c (v_j - v_i).u) u with u = (x_j - x_i) / L (u = 0 when L = 0). Lists the
/// springs compressed below half their rest length, ascending, at `compressed` (room for end - begin)
/// and returns how many there are.
std::size_t spring_forces_portable(SpringArrays& springs, const Vec3* x, const Vec3* v, std::size_t begin, std::size_t end,
                                   std::uint32_t* compressed);
/// The same with four springs per instruction; call only where cpu_has_avx2(). x and v hold
/// `node_count` nodes: a node's row is read with one 32-byte load, which reaches into the next node,
/// so the last node's is read masked.
std::size_t spring_forces_avx2(SpringArrays& springs, const Vec3* x, const Vec3* v, std::size_t node_count, std::size_t begin, std::size_t end,
                               std::uint32_t* compressed);

/// For nodes [begin, end): force[n] = force[n] - (n's forces as node j, ascending) + (its forces as
/// node i, ascending), component by component.
void add_spring_sums_portable(const SpringIncidence& incidence, const SpringForce* f, Vec3* force, std::size_t begin, std::size_t end);
/// The same a row at a time; call only where cpu_has_avx2().
void add_spring_sums_avx2(const SpringIncidence& incidence, const SpringForce* f, Vec3* force, std::size_t begin, std::size_t end);

/// The fastest kernel this processor runs, over springs [begin, end) (listing the compressed ones at
/// `compressed`, room for end - begin).
std::size_t spring_forces(SpringArrays& springs, const Vec3* x, const Vec3* v, std::size_t node_count, std::size_t begin, std::size_t end,
                          std::uint32_t* compressed);
/// The fastest node sums this processor runs, over nodes [begin, end).
void add_spring_sums(const SpringIncidence& incidence, const SpringForce* f, Vec3* force, std::size_t begin, std::size_t end);

}  // namespace resecto

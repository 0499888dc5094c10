// The springs' forces in two passes: one over springs that writes each spring's force into its own
// slot (independent iterations over structure-of-arrays data, so they pipeline and vectorise), then
// one over nodes that sums each node's spring forces through a fixed-order incidence list. The second
// pass replaces a scatter `force[i] += f; force[j] -= f` whose stores chained through memory.
#pragma once

#include <cstdint>
#include <vector>

#include "rtcore/geometry/vec3.h"
#include "rtcore/tissue/spring_kernel.h"
#include "rtcore/tissue/springs.h"

namespace resecto {

class SpringForces {
 public:
  explicit SpringForces(const SpringNetwork& network);

  std::size_t spring_count() const { return arrays_.i.size(); }
  const SpringArrays& arrays() const { return arrays_; }
  /// Sets a spring's stiffness and damping (between steps).
  void set_material(std::size_t s, double k_n_m, double c_ns_m) {
    arrays_.k[s] = k_n_m;
    arrays_.c[s] = c_ns_m;
  }

  /// The per-spring pass at positions x and velocities v (spring_kernel.h). Returns how many springs
  /// are compressed below half their rest length (add_compression_bounds handles those; usually none).
  std::size_t compute(const Vec3* x, const Vec3* v) { return spring_forces(arrays_, x, v); }

  /// The per-node pass for node n: `sum` plus n's spring forces of the last compute(), added in
  /// ascending spring order, which is the order the scatter formed them in (same bits).
  Vec3 gather(std::size_t n, Vec3 sum) const {
    for (std::uint32_t e = second_first_[n]; e < second_first_[n + 1]; ++e) {
      const std::uint32_t s = second_springs_[e];
      sum -= Vec3(arrays_.fx[s], arrays_.fy[s], arrays_.fz[s]);
    }
    for (std::uint32_t s = first_first_[n]; s < first_first_[n + 1]; ++s) sum += Vec3(arrays_.fx[s], arrays_.fy[s], arrays_.fz[s]);
    return sum;
  }

  /// Adds, in spring order, the Hessian-norm excess of each spring compressed below half its rest
  /// length to both its nodes' stiffness bounds (k |1 - L0/L| exceeds the k already counted).
  void add_compression_bounds(const Vec3* x, double* stiffness_bound) const;

  /// Implicit Euler's linearisation: each spring's unit direction and transverse stiffness.
  void linearise(const Vec3* x, Vec3* direction, double* transverse_k) const;

 private:
  SpringArrays arrays_;
  // Incidence: a node's springs as second node (all come before its springs as first node, since
  // springs are sorted by first node), ascending; its springs as first node are one range.
  std::vector<std::uint32_t> second_first_;    // per node + 1: offsets into second_springs_
  std::vector<std::uint32_t> second_springs_;
  std::vector<std::uint32_t> first_first_;     // per node + 1: spring index ranges
};

}  // namespace resecto

// Strokes of the loop's wire through the 1296 gland, made straight through a Resection (no core):
// the tests of the tissue's edits and of their replay on a second copy cut the same way.
#pragma once

#include <vector>

#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/resection/resection.h"

namespace resecto {

/// Collision steps first_step .. first_step + steps - 1 of one stroke: the wire in a plane z = const
/// at the channel wall, hanging to the patient's left, drawn back 1 mm a step from 30 mm, radius 1.2 mm.
inline void cut_through_gland(Resection& resection, int steps, int first_step = 0) {
  const std::vector<Vec3> arc = loop_cutting_arc();
  SweptVolume sweep(arc.size());
  std::vector<Vec3> from, to;
  for (int step = first_step; step < first_step + steps; ++step) {
    from.clear();
    to.clear();
    for (const Vec3& p : arc) {
      const Vec3 q{-p.y + 0.001, p.x, 0.0};
      from.push_back(q + Vec3(0.0, 0.0, 0.030 - 0.001 * step));
      to.push_back(q + Vec3(0.0, 0.0, 0.029 - 0.001 * step));
    }
    sweep.set(from, to, 0.0012);
    (void)resection.step(&sweep, true, false, 1.0 / 60.0);
  }
}

}  // namespace resecto

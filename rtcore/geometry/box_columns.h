// Axis-aligned boxes stored a coordinate per column, so that finding which of many boxes lie within
// a reach of one point is four boxes per instruction: the contact search tests each tool vertex of a
// cluster against every tissue face near the cluster, a few hundred boxes per vertex, and as a row
// of Vec3 pairs that test cost over twenty cycles a box.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "rtcore/geometry/vec3.h"

namespace resecto {

class BoxColumns {
 public:
  /// Room for `count` boxes: push() and within() then allocate nothing.
  void reserve(std::size_t count);
  void clear();
  std::size_t size() const { return low_x_.size(); }
  /// Adds the box [low, high].
  void push(const Vec3& low, const Vec3& high);
  /// Writes to `indices` the boxes (ascending) whose squared distance from p is at most `reach2`
  /// (0 inside a box); returns how many. `indices` has room for size() entries.
  std::size_t within(const Vec3& p, double reach2, std::uint32_t* indices) const;

 private:
  std::vector<double> low_x_, low_y_, low_z_, high_x_, high_y_, high_z_;
};

}  // namespace resecto

// SweptVolume: the tissue the loop wire reaches during one collision step while the cutting pedal is
// down. Each sampled point of the wire moves in a straight line from where it was at the previous
// collision step to where it is now; consecutive points span a ribbon of two triangles, and the swept
// volume is every point within the live cutting radius of the ribbon (the wire's path, inflated).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "rtcore/geometry/vec3.h"
#include "rtcore/mesh/triangle_mesh.h"

namespace resecto {

class SweptVolume {
 public:
  /// Room for wires of up to `max_points` samples (no allocation afterwards).
  explicit SweptVolume(std::size_t max_points = 64);
  /// The wire's samples (world, metres) at the previous and the current collision step, in the same
  /// order along the wire, and the cutting radius. A first step with no previous pose passes the
  /// current samples twice (the volume is then the wire itself, inflated).
  void set(std::span<const Vec3> from, std::span<const Vec3> to, double radius_m);
  /// Distance from p to the wire's path (0 on it); p is inside the volume when this is <= radius().
  double path_distance(const Vec3& p) const;
  bool contains(const Vec3& p) const { return within(p, radius_m_); }
  /// Whether p is within `reach` of the wire's path (path_distance(p) <= reach), answered early: a
  /// box test first, then the first ribbon that close.
  bool within(const Vec3& p, double reach) const;
  /// A cheap necessary condition for within(p, reach): p is inside some ribbon's bounding sphere grown
  /// by `reach` (no closest-point work; for filtering many points before the exact test).
  bool may_be_within(const Vec3& p, double reach) const;
  double radius() const { return radius_m_; }
  /// The wire's samples where the path starts (the last collision tick's).
  std::span<const Vec3> start() const { return from_; }
  /// The volume's bounding box (the path's, grown by the radius).
  const Aabb& bounds() const { return bounds_; }
  /// Exact volume of a straight stroke: a segment of length `span_m` moving `travel_m` across
  /// itself, inflated by r (a box with half-cylinders and a quarter-sphere rim): the oracle's value.
  static double straight_stroke_volume(double span_m, double travel_m, double radius_m);
  /// How far the wire's samples (at both steps) moved from `other`'s: every point of this path lies
  /// within this distance of `other`'s path (the same point of the same ribbon). Infinite when the
  /// two have different sample counts.
  double sample_displacement(const SweptVolume& other) const;

 private:
  struct Quad {
    Vec3 a0, a1, b1, b0;  // the ribbon between two samples: from[i], from[i+1], to[i+1], to[i]
    Vec3 centre;
    double reach;  // every point of the quad is within this of centre
  };
  /// Whether p is inside the volume's box grown by what `reach` exceeds the radius.
  bool in_grown_bounds(const Vec3& p, double reach) const;
  /// Consecutive quads in fours under one bounding sphere, so a far point costs a few tests.
  struct Group {
    Vec3 centre;
    double reach;  // every point of its quads is within this of centre
    std::uint32_t first, end;
  };
  static constexpr std::size_t kGroupSize = 4;
  std::vector<Quad> quads_;
  std::vector<Group> groups_;
  std::vector<Vec3> from_, to_;  // the samples, as set()
  double radius_m_ = 0.0;
  Aabb bounds_;
};

}  // namespace resecto

// The loop's swept volume: ribbons of triangles between the wire's samples at two collision steps.
#include "rtcore/resection/swept_volume.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "rtcore/geometry/closest_point.h"

namespace resecto {

SweptVolume::SweptVolume(std::size_t max_points) {
  quads_.reserve(max_points);
  groups_.reserve(max_points / kGroupSize + 1);
  from_.reserve(max_points);
  to_.reserve(max_points);
}

double SweptVolume::sample_displacement(const SweptVolume& other) const {
  if (from_.size() != other.from_.size()) return std::numeric_limits<double>::infinity();
  double largest2 = 0.0;
  for (std::size_t i = 0; i < from_.size(); ++i) {
    largest2 = std::max({largest2, length_squared(from_[i] - other.from_[i]), length_squared(to_[i] - other.to_[i])});
  }
  return std::sqrt(largest2);
}

void SweptVolume::set(std::span<const Vec3> from, std::span<const Vec3> to, double radius_m) {
  quads_.clear();
  radius_m_ = radius_m;
  const std::size_t count = std::min({from.size(), to.size(), from_.capacity()});
  from_.assign(from.begin(), from.begin() + static_cast<std::ptrdiff_t>(count));
  to_.assign(to.begin(), to.begin() + static_cast<std::ptrdiff_t>(count));
  bounds_.min = Vec3(std::numeric_limits<double>::infinity());
  bounds_.max = Vec3(-std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < count; ++i) {
    for (const Vec3& p : {from[i], to[i]}) {
      bounds_.min = glm::min(bounds_.min, p);
      bounds_.max = glm::max(bounds_.max, p);
    }
  }
  bounds_.min -= Vec3(radius_m);
  bounds_.max += Vec3(radius_m);
  for (std::size_t i = 0; i + 1 < count && quads_.size() < quads_.capacity(); ++i) {
    Quad q{from[i], from[i + 1], to[i + 1], to[i], Vec3(0.0), 0.0};
    q.centre = 0.25 * (q.a0 + q.a1 + q.b1 + q.b0);
    for (const Vec3& p : {q.a0, q.a1, q.b1, q.b0}) q.reach = std::max(q.reach, length(p - q.centre));
    quads_.push_back(q);
  }
  groups_.clear();
  for (std::size_t first = 0; first < quads_.size(); first += kGroupSize) {
    const std::size_t end = std::min(quads_.size(), first + kGroupSize);
    Group g{Vec3(0.0), 0.0, static_cast<std::uint32_t>(first), static_cast<std::uint32_t>(end)};
    for (std::size_t k = first; k < end; ++k) g.centre += quads_[k].centre;
    g.centre /= static_cast<double>(end - first);
    for (std::size_t k = first; k < end; ++k) g.reach = std::max(g.reach, length(quads_[k].centre - g.centre) + quads_[k].reach);
    groups_.push_back(g);
  }
}

double SweptVolume::path_distance(const Vec3& p) const {
  // Quads in wire order; the sphere around each skips those that cannot be nearer than the best.
  double best2 = std::numeric_limits<double>::infinity();
  for (const Quad& q : quads_) {
    const double far = length(p - q.centre) - q.reach;
    if (far > 0.0 && far * far >= best2) continue;
    for (const Vec3& c : {closest_point_on_triangle(p, q.a0, q.a1, q.b1), closest_point_on_triangle(p, q.a0, q.b1, q.b0)}) {
      best2 = std::min(best2, length_squared(p - c));
    }
  }
  return std::sqrt(best2);
}

bool SweptVolume::within(const Vec3& p, double reach) const {
  if (!in_grown_bounds(p, reach)) return false;
  const double reach2 = reach * reach;
  for (const Group& g : groups_) {
    const double group_bound = g.reach + reach;
    if (length_squared(p - g.centre) > group_bound * group_bound) continue;
    for (std::uint32_t k = g.first; k < g.end; ++k) {
      const Quad& q = quads_[k];
      const double bound = q.reach + reach;
      if (length_squared(p - q.centre) > bound * bound) continue;
      for (const Vec3& c : {closest_point_on_triangle(p, q.a0, q.a1, q.b1), closest_point_on_triangle(p, q.a0, q.b1, q.b0)}) {
        if (length_squared(p - c) <= reach2) return true;
      }
    }
  }
  return false;
}

bool SweptVolume::in_grown_bounds(const Vec3& p, double reach) const {
  // The box holds the path grown by the radius; grown further by what reach exceeds it.
  const double grow = std::max(0.0, reach - radius_m_);
  return p.x >= bounds_.min.x - grow && p.y >= bounds_.min.y - grow && p.z >= bounds_.min.z - grow && p.x <= bounds_.max.x + grow &&
         p.y <= bounds_.max.y + grow && p.z <= bounds_.max.z + grow;
}

bool SweptVolume::may_be_within(const Vec3& p, double reach) const {
  if (!in_grown_bounds(p, reach)) return false;
  for (const Group& g : groups_) {
    const double group_bound = g.reach + reach;
    if (length_squared(p - g.centre) > group_bound * group_bound) continue;
    for (std::uint32_t k = g.first; k < g.end; ++k) {
      const double bound = quads_[k].reach + reach;
      if (length_squared(p - quads_[k].centre) <= bound * bound) return true;
    }
  }
  return false;
}

double SweptVolume::straight_stroke_volume(double span_m, double travel_m, double radius_m) {
  // Minkowski sum of a span x travel rectangle with a ball: the slab 2 r s t, half-cylinders along the
  // four sides pi r^2 (s + t), and the four quarter... corners, which together make one ball 4/3 pi r^3.
  const double r = radius_m;
  return 2.0 * r * span_m * travel_m + std::numbers::pi * r * r * (span_m + travel_m) + 4.0 / 3.0 * std::numbers::pi * r * r * r;
}

}  // namespace resecto

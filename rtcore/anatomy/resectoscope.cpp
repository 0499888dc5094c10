// The paper's benchmark resectoscope. Triangle budgets are exact, so the grids below are sized from
// them: sheath 20 sides x 3 segments (120) + a centre-fan tip cap (20) + a polygon back cap (18) = 158;
// loop wire a pentagonal tube along 33 path points (2 * 5 * 32 = 320) + two centre-fan end caps (10) = 330.
#include "rtcore/anatomy/resectoscope.h"

#include <cmath>
#include <numbers>
#include <vector>

namespace resecto {
namespace {

constexpr int kSheathSides = 20;
/// Ring heights along the sheath, tip first: short segments where it meets tissue, one long shaft.
constexpr double kSheathRingFractions[] = {0.0, 0.125, 0.4, 1.0};
constexpr int kWireSides = 5;
constexpr int kArmSegments = 3;
constexpr int kArcSegments = 26;
/// The wire's half-ring hangs below the axis; its arms run back inside the sheath, long enough to
/// stay inside at full travel, so the loop is one rigid object that translates with travel. The arms'
/// height puts the ring's lowest wire just inside the sheath's outline (4.28 of 4.34 mm), so the
/// retracted ring lies within the sheath and holds no tissue against it.
constexpr double kArmLengthM = 0.042;
constexpr double kArmHeightM = -0.0011;

TriangleMesh make_sheath(const ResectoscopeShape& s) {
  TriangleMesh mesh;
  const double radius = 0.5 * s.sheath_diameter_m;
  for (double fraction : kSheathRingFractions) {
    for (int j = 0; j < kSheathSides; ++j) {
      const double angle = 2.0 * std::numbers::pi * j / kSheathSides;
      mesh.positions.push_back({radius * std::cos(angle), radius * std::sin(angle), -fraction * s.sheath_length_m});
    }
  }
  auto ring = [](int r, int j) { return static_cast<std::uint32_t>(r * kSheathSides + (j % kSheathSides)); };
  constexpr int kRings = static_cast<int>(std::size(kSheathRingFractions));
  for (int r = 0; r + 1 < kRings; ++r) {
    for (int j = 0; j < kSheathSides; ++j) {
      // Ring r is nearer the tip (+z); outward normals with counter-clockwise winding.
      mesh.triangles.push_back({ring(r, j), ring(r + 1, j), ring(r + 1, j + 1)});
      mesh.triangles.push_back({ring(r, j), ring(r + 1, j + 1), ring(r, j + 1)});
    }
  }
  const auto tip_centre = static_cast<std::uint32_t>(mesh.positions.size());
  mesh.positions.push_back({0.0, 0.0, 0.0});
  for (int j = 0; j < kSheathSides; ++j) mesh.triangles.push_back({tip_centre, ring(0, j), ring(0, j + 1)});
  for (int j = 1; j + 1 < kSheathSides; ++j) {
    mesh.triangles.push_back({ring(kRings - 1, 0), ring(kRings - 1, j + 1), ring(kRings - 1, j)});
  }
  return mesh;
}

/// Point i (0 .. kArcSegments) of the half-ring below the axis, from the left arm to the right.
Vec3 arc_point(const ResectoscopeShape& s, int i) {
  const double half_span = 0.5 * s.loop_span_m;
  const double angle = std::numbers::pi * (1.0 + static_cast<double>(i) / kArcSegments);
  return {half_span * std::cos(angle), kArmHeightM + half_span * std::sin(angle), s.retracted_loop_z_m + s.loop_travel_m};
}

/// Centre line of the wire: left arm forward, the half-ring below the axis, right arm back.
std::vector<Vec3> loop_path(const ResectoscopeShape& s) {
  const double half_span = 0.5 * s.loop_span_m;
  const double front = s.retracted_loop_z_m + s.loop_travel_m;
  std::vector<Vec3> path;
  for (int i = 0; i <= kArmSegments; ++i) {
    path.push_back({-half_span, kArmHeightM, front - kArmLengthM * (1.0 - static_cast<double>(i) / kArmSegments)});
  }
  for (int i = 1; i <= kArcSegments; ++i) path.push_back(arc_point(s, i));
  for (int i = 1; i <= kArmSegments; ++i) {
    path.push_back({half_span, kArmHeightM, front - kArmLengthM * static_cast<double>(i) / kArmSegments});
  }
  return path;
}

TriangleMesh make_loop(const ResectoscopeShape& s) {
  const std::vector<Vec3> path = loop_path(s);
  const int points = static_cast<int>(path.size());
  const double radius = 0.5 * s.wire_diameter_m;
  TriangleMesh mesh;
  // Rotation-minimising frames carried along the path; at a corner the ring lies in the bisecting
  // plane and widens by 1 / cos(half the turn), so the wire keeps its thickness through the bend.
  Vec3 normal{0.0, 1.0, 0.0};
  for (int p = 0; p < points; ++p) {
    const Vec3 in = p > 0 ? glm::normalize(path[p] - path[p - 1]) : glm::normalize(path[1] - path[0]);
    const Vec3 out = p + 1 < points ? glm::normalize(path[p + 1] - path[p]) : in;
    const Vec3 tangent = glm::normalize(in + out);
    normal = glm::normalize(normal - dot(normal, tangent) * tangent);
    const Vec3 binormal = cross(tangent, normal);
    const double widen = 1.0 / std::max(dot(tangent, out), 0.5);
    for (int j = 0; j < kWireSides; ++j) {
      const double angle = 2.0 * std::numbers::pi * j / kWireSides;
      mesh.positions.push_back(path[p] + radius * widen * (std::cos(angle) * normal + std::sin(angle) * binormal));
    }
  }
  auto ring = [](int p, int j) { return static_cast<std::uint32_t>(p * kWireSides + (j % kWireSides)); };
  for (int p = 0; p + 1 < points; ++p) {
    for (int j = 0; j < kWireSides; ++j) {
      mesh.triangles.push_back({ring(p, j), ring(p + 1, j + 1), ring(p + 1, j)});
      mesh.triangles.push_back({ring(p, j), ring(p, j + 1), ring(p + 1, j + 1)});
    }
  }
  const auto start = static_cast<std::uint32_t>(mesh.positions.size());
  mesh.positions.push_back(path.front());
  const auto end = static_cast<std::uint32_t>(mesh.positions.size());
  mesh.positions.push_back(path.back());
  for (int j = 0; j < kWireSides; ++j) {
    mesh.triangles.push_back({start, ring(0, j + 1), ring(0, j)});
    mesh.triangles.push_back({end, ring(points - 1, j), ring(points - 1, j + 1)});
  }
  if (signed_volume(mesh) < 0.0) {
    for (Triangle& t : mesh.triangles) std::swap(t[1], t[2]);
  }
  return mesh;
}

}  // namespace

ResectoscopeModel generate_resectoscope(const ResectoscopeShape& shape) {
  return {make_sheath(shape), make_loop(shape)};
}

std::vector<Vec3> loop_cutting_arc(const ResectoscopeShape& shape) {
  std::vector<Vec3> arc;
  for (int i = 0; i <= kArcSegments; ++i) arc.push_back(arc_point(shape, i));
  return arc;
}

TriangleMesh combined_resectoscope_mesh(const ResectoscopeModel& model) {
  TriangleMesh mesh = model.sheath;
  append_mesh(mesh, model.loop);
  return mesh;
}

}  // namespace resecto

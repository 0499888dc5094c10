// The procedural hyperplastic prostate. The surface is a torus-like grid: around the channel axis
// (angle theta) and around a meridian loop (apex cap -> outer gland wall -> bladder-neck cap -> channel
// wall). For each theta the meridian is a simple closed curve in its own half-plane {r > 0}, so the
// smooth surface is embedded by construction, and the grid closes it as a genus-1 manifold.
#include "rtcore/anatomy/prostate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <nlohmann/json.hpp>

#include "rtcore/base/units.h"

namespace resecto {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
/// Superellipse exponent of the meridian: 4 gives flat walls and well-rounded caps.
constexpr double kMeridianExponent = 4.0;
/// Preferred ratio of meridian rows to columns around the axis: the meridian loop is about 1.5
/// times the mean circumference, so this keeps grid cells near square.
constexpr double kPreferredAspect = 1.45;

double wrap_angle(double a) {
  a = std::fmod(a, kTwoPi);
  if (a > std::numbers::pi) a -= kTwoPi;
  if (a < -std::numbers::pi) a += kTwoPi;
  return a;
}

double gaussian(double x, double centre, double width) {
  const double u = (x - centre) / width;
  return std::exp(-0.5 * u * u);
}

double angular_gaussian(double theta, double centre, double width) {
  return gaussian(wrap_angle(theta - centre), 0.0, width);
}

/// Signed power keeping the sign of the base: the superellipse's coordinate functions.
double signed_power(double base, double exponent) {
  return std::copysign(std::pow(std::abs(base), exponent), base);
}

/// Distance from the axis to the gland's outer wall at height z in direction theta: an ellipse whose
/// centre lies posterior of the urethra, narrowing toward the apex.
double outer_radius_at(const ProstateShape& s, double z_m, double theta) {
  const double zn = std::clamp(z_m / s.length_m, 0.0, 1.0);
  const double taper = 1.0 - s.apex_taper * (1.0 - zn) * (1.0 - zn);
  const double ax = 0.5 * s.width_m * taper;
  const double ay = 0.5 * s.height_m * taper;
  const double dy = s.posterior_offset_m * taper;
  // Ray from the axis, direction (cos, sin), meets ((t c)/ax)^2 + ((t s + dy)/ay)^2 = 1.
  const double c = std::cos(theta);
  const double sn = std::sin(theta);
  const double qa = c * c / (ax * ax) + sn * sn / (ay * ay);
  const double qb = 2.0 * sn * dy / (ay * ay);
  const double qc = dy * dy / (ay * ay) - 1.0;
  return (-qb + std::sqrt(qb * qb - 4.0 * qa * qc)) / (2.0 * qa);
}

/// Midline of the meridian loop: between the widest channel and the narrowest gland wall.
double meridian_midline(const ProstateShape& s, double theta) {
  return s.channel_radius_m + 0.5 * (outer_radius_at(s, 0.0, theta) - s.channel_radius_m);
}

struct MeridianPoint {
  double r;
  double z;
};

/// Point of the meridian loop at parameter phi in [0, 2 pi): phi = 0 is the apex cap, (0, pi) the
/// outer wall rising to the base, pi the bladder-neck cap, (pi, 2 pi) the channel wall descending.
MeridianPoint meridian_point(const ProstateShape& s, double theta, double phi) {
  const double e = 2.0 / kMeridianExponent;
  const double height = 0.5 * s.length_m * (1.0 - signed_power(std::cos(phi), e));
  const double across = signed_power(std::sin(phi), e);
  const double mid = meridian_midline(s, theta);
  // Each half is a graph over z on its own side of the midline, so the loop cannot cross itself.
  const double r = across >= 0.0 ? mid + across * (outer_radius_at(s, height, theta) - mid)
                                  : mid + across * (mid - channel_radius_at(s, height, theta));
  return {r, height};
}

Vec3 to_world(const MeridianPoint& m, double theta) {
  return {m.r * std::cos(theta), m.r * std::sin(theta), m.z};
}

/// Grid size (columns around the axis, rows around the meridian) whose 2 * columns * rows is
/// closest to the target, preferring near-square cells among counts within half a percent.
std::pair<int, int> choose_grid(int target_triangles) {
  const int quads = std::max(target_triangles / 2, 12);
  std::pair<int, int> best{3, 4};
  double best_error = 1e300;
  double best_aspect_gap = 1e300;
  for (int columns = 3; columns <= quads; ++columns) {
    const int rows = std::max(4, static_cast<int>(std::lround(static_cast<double>(target_triangles) / (2.0 * columns))));
    const double error = std::abs(2.0 * columns * rows - target_triangles) / target_triangles;
    const double aspect_gap = std::abs(std::log(static_cast<double>(rows) / columns / kPreferredAspect));
    const bool within = error <= 0.005;
    const bool best_within = best_error <= 0.005;
    const bool better = within ? (!best_within || aspect_gap < best_aspect_gap)
                               : (!best_within && error < best_error);
    if (better) {
      best = {columns, rows};
      best_error = error;
      best_aspect_gap = aspect_gap;
    }
    if (columns > 4 * std::sqrt(quads)) break;
  }
  return best;
}

/// The meridian parameters of `rows` points equally spaced in arc length, starting at the apex cap.
std::vector<double> equal_arc_parameters(const ProstateShape& s, double theta, int rows) {
  const int samples = std::max(4096, 16 * rows);
  std::vector<double> arc(samples + 1, 0.0);
  MeridianPoint previous = meridian_point(s, theta, 0.0);
  for (int i = 1; i <= samples; ++i) {
    const MeridianPoint p = meridian_point(s, theta, kTwoPi * i / samples);
    arc[i] = arc[i - 1] + std::hypot(p.r - previous.r, p.z - previous.z);
    previous = p;
  }
  std::vector<double> phis(rows);
  int segment = 0;
  for (int k = 0; k < rows; ++k) {
    const double target = arc[samples] * k / rows;
    while (segment < samples - 1 && arc[segment + 1] < target) ++segment;
    const double span = arc[segment + 1] - arc[segment];
    const double t = span > 0.0 ? (target - arc[segment]) / span : 0.0;
    phis[k] = kTwoPi * (segment + t) / samples;
  }
  return phis;
}

}  // namespace

double channel_radius_at(const ProstateShape& s, double z_m, double theta) {
  const double zn = std::clamp(z_m / s.length_m, 0.0, 1.0);
  // theta = 0 is +x, the patient's left; pi is the right; -pi/2 is posterior (-y).
  const double lateral = s.lateral_lobe_bulge_m * gaussian(zn, 0.55, 0.20) *
                         (angular_gaussian(theta, 0.0, 0.55) + angular_gaussian(theta, std::numbers::pi, 0.55));
  const double median = s.median_lobe_bulge_m * gaussian(zn, 0.90, 0.09) * angular_gaussian(theta, -0.5 * std::numbers::pi, 0.50);
  const double verumontanum =
      s.verumontanum_bulge_m * gaussian(zn, 0.22, 0.05) * angular_gaussian(theta, -0.5 * std::numbers::pi, 0.28);
  return s.channel_radius_m - lateral - median - verumontanum;
}

ProstateModel generate_prostate(int target_triangles, const ProstateShape& shape) {
  ProstateModel model;
  model.shape = shape;
  const auto [columns, rows] = choose_grid(target_triangles);
  model.meridian_segments = columns;
  model.profile_segments = rows;

  TriangleMesh& mesh = model.surface;
  mesh.positions.reserve(static_cast<std::size_t>(columns) * rows);
  // Vertex (i, k) at index i * rows + k: column i around the axis, row k along the meridian.
  for (int i = 0; i < columns; ++i) {
    const double theta = kTwoPi * i / columns;
    for (double phi : equal_arc_parameters(shape, theta, rows)) {
      mesh.positions.push_back(to_world(meridian_point(shape, theta, phi), theta));
    }
  }
  auto vertex = [&](int i, int k) {
    return static_cast<std::uint32_t>(((i + columns) % columns) * rows + (k + rows) % rows);
  };
  mesh.triangles.reserve(2 * static_cast<std::size_t>(columns) * rows);
  for (int i = 0; i < columns; ++i) {
    for (int k = 0; k < rows; ++k) {
      const std::uint32_t a = vertex(i, k), b = vertex(i + 1, k), c = vertex(i + 1, k + 1), d = vertex(i, k + 1);
      // Split each quad along its shorter diagonal: the better-shaped pair of triangles.
      const double ac = length_squared(mesh.positions[a] - mesh.positions[c]);
      const double bd = length_squared(mesh.positions[b] - mesh.positions[d]);
      if (ac <= bd) {
        mesh.triangles.push_back({a, c, b});
        mesh.triangles.push_back({a, d, c});
      } else {
        mesh.triangles.push_back({a, d, b});
        mesh.triangles.push_back({b, d, c});
      }
    }
  }
  if (signed_volume(mesh) < 0.0) {
    for (Triangle& t : mesh.triangles) std::swap(t[1], t[2]);
  }

  const double posterior = -0.5 * std::numbers::pi;
  const double verumontanum_z = 0.22 * shape.length_m;
  const double lobe_z = 0.55 * shape.length_m;
  const double median_z = 0.90 * shape.length_m;
  auto on_channel_wall = [&](double z, double theta) {
    return to_world({channel_radius_at(shape, z, theta), z}, theta);
  };
  model.landmarks = {
      {"bladder_neck", {0.0, 0.0, shape.length_m}, "centre of the channel's opening into the bladder"},
      {"median_lobe", on_channel_wall(median_z, posterior), "crest of the median lobe on the posterior wall"},
      {"lateral_lobe_left", on_channel_wall(lobe_z, 0.0), "crest of the left lateral lobe (+x)"},
      {"lateral_lobe_right", on_channel_wall(lobe_z, std::numbers::pi), "crest of the right lateral lobe (-x)"},
      {"verumontanum", on_channel_wall(verumontanum_z, posterior), "mound on the posterior wall; resect no further distally"},
      {"apex", {0.0, 0.0, 0.0}, "centre of the channel's opening at the gland's apex"},
      {"external_sphincter", {0.0, 0.0, -0.008}, "striated sphincter distal to the apex; must never be cut"},
  };
  return model;
}

std::string landmarks_to_json(const ProstateModel& model) {
  using nlohmann::ordered_json;
  auto mm = [](const Vec3& p) {
    return ordered_json::array({units::m_to_mm(p.x), units::m_to_mm(p.y), units::m_to_mm(p.z)});
  };
  ordered_json doc;
  doc["units"] = "mm";
  doc["frame"] = "x patient's left, y anterior, z toward the bladder; channel axis = z";
  doc["channel_axis"] = {{"apex", mm({0.0, 0.0, 0.0})}, {"bladder_neck", mm({0.0, 0.0, model.shape.length_m})}};
  doc["capsule_thickness_mm"] = units::m_to_mm(model.shape.capsule_thickness_m);
  ordered_json landmarks = ordered_json::array();
  for (const Landmark& l : model.landmarks) {
    landmarks.push_back({{"name", l.name}, {"position", mm(l.position)}, {"description", l.description}});
  }
  doc["landmarks"] = landmarks;
  return doc.dump(2) + "\n";
}

}  // namespace resecto

// Exact predicates (a floating-point filter backed by Shewchuk-style expansion arithmetic) and the
// Guigue-Devillers triangle-triangle test: only signs of determinants, so touching is decided exactly.
#include "rtcore/geometry/triangle_triangle.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

namespace resecto {
namespace {

// ---- Exact expansion arithmetic --------------------------------------------------------------
// A value is a sum of doubles with no overlapping bits; adding a double or a product to it is exact.
// Used only when the filter below cannot decide a sign, i.e. for (near-)degenerate inputs.

constexpr double kEpsilon = 0x1p-53;  // half an ulp of 1.0
// Error bounds of the filters (Shewchuk's orient3d/orient2d "A" bounds), doubled for headroom.
constexpr double kOrient3dBound = 2.0 * (7.0 + 56.0 * kEpsilon) * kEpsilon;
constexpr double kOrient2dBound = 2.0 * (3.0 + 16.0 * kEpsilon) * kEpsilon;

struct Expansion {
  std::array<double, 200> terms{};  // 24 triple products of at most 4 terms each, plus slack
  int count = 0;

  // Exact: the running sum is carried through two-sums, the round-off of each step kept as a term.
  void add(double b) {
    double q = b;
    int kept = 0;
    for (int i = 0; i < count; ++i) {
      const double sum = q + terms[i];
      const double b_virtual = sum - q;
      const double a_virtual = sum - b_virtual;
      const double error = (q - a_virtual) + (terms[i] - b_virtual);
      q = sum;
      if (error != 0.0) terms[kept++] = error;
    }
    if (q != 0.0) terms[kept++] = q;
    count = kept;
  }

  // Adds the exact product a*b (two terms: the rounded product and its exact error, via fma).
  void add_product(double a, double b) {
    const double p = a * b;
    add(std::fma(a, b, -p));
    add(p);
  }

  // Adds the exact product a*b*c (four terms).
  void add_product(double a, double b, double c) {
    const double p = a * b;
    const double e = std::fma(a, b, -p);
    add_product(p, c);
    add_product(e, c);
  }

  // The largest term is last and decides the sign.
  int sign() const {
    if (count == 0) return 0;
    return terms[count - 1] > 0.0 ? 1 : -1;
  }
};

int sign_of(double v) { return (v > 0.0) - (v < 0.0); }

// Exact sign of det3(b - a, c - a, d - a) = -det4 of the rows (point, 1): expanding the 4x4
// determinant into triple products of input coordinates avoids rounding the differences.
int orient3d_exact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const std::array<const Vec3*, 4> rows{&a, &b, &c, &d};
  Expansion det4;
  // det4 = sum over i of (-1)^(i+3) * minor_i, minor_i = det3 of the other three rows (x, y, z).
  for (int i = 0; i < 4; ++i) {
    std::array<const Vec3*, 3> m{};
    int k = 0;
    for (int j = 0; j < 4; ++j) {
      if (j != i) m[k++] = rows[j];
    }
    const double s = ((i + 3) % 2 == 0) ? 1.0 : -1.0;
    const Vec3& u = *m[0];
    const Vec3& v = *m[1];
    const Vec3& w = *m[2];
    // u . (v x w) as six signed triple products; negating a factor is exact.
    det4.add_product(s * u.x, v.y, w.z);
    det4.add_product(-s * u.x, v.z, w.y);
    det4.add_product(s * u.y, v.z, w.x);
    det4.add_product(-s * u.y, v.x, w.z);
    det4.add_product(s * u.z, v.x, w.y);
    det4.add_product(-s * u.z, v.y, w.x);
  }
  return -det4.sign();
}

// ---- Coplanar and degenerate cases -----------------------------------------------------------

struct Point2 {
  double x;
  double y;
};

int orient2(const Point2& a, const Point2& b, const Point2& c) {
  return orient2d(a.x, a.y, b.x, b.y, c.x, c.y);
}


// Closed segments [a, b] and [c, d] in the plane.
bool segments_intersect_2d(const Point2& a, const Point2& b, const Point2& c, const Point2& d) {
  const int o1 = orient2(a, b, c);
  const int o2 = orient2(a, b, d);
  const int o3 = orient2(c, d, a);
  const int o4 = orient2(c, d, b);
  if (o1 * o2 > 0 || o3 * o4 > 0) return false;
  if (o1 == 0 && o2 == 0) {  // collinear: overlapping extents along the line
    const auto overlap = [](double a0, double a1, double b0, double b1) {
      return std::max(std::min(a0, a1), std::min(b0, b1)) <= std::min(std::max(a0, a1), std::max(b0, b1));
    };
    return overlap(a.x, b.x, c.x, d.x) && overlap(a.y, b.y, c.y, d.y);
  }
  return true;
}

// Closed point-in-triangle in the plane, either winding; the triangle may be degenerate only if
// the caller also tests its edges.
bool point_in_triangle_2d(const Point2& p, const Point2& a, const Point2& b, const Point2& c) {
  const int o1 = orient2(a, b, p);
  const int o2 = orient2(b, c, p);
  const int o3 = orient2(c, a, p);
  const bool has_negative = o1 < 0 || o2 < 0 || o3 < 0;
  const bool has_positive = o1 > 0 || o2 > 0 || o3 > 0;
  return !(has_negative && has_positive);
}

// Drops the coordinate along which the plane's normal is largest: the projection of a plane onto
// the other two axes is one-to-one (dropping a coordinate is exact, so the predicates stay exact).
int dominant_axis(const Vec3& normal) {
  const Vec3 n = glm::abs(normal);
  if (n.x >= n.y && n.x >= n.z) return 0;
  return n.y >= n.z ? 1 : 2;
}

Point2 project(const Vec3& p, int drop) {
  if (drop == 0) return {p.y, p.z};
  if (drop == 1) return {p.z, p.x};
  return {p.x, p.y};
}

bool coplanar_triangles_intersect(const std::array<Point2, 3>& p, const std::array<Point2, 3>& q) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (segments_intersect_2d(p[i], p[(i + 1) % 3], q[j], q[(j + 1) % 3])) return true;
    }
  }
  // No edges cross: either one triangle holds the other or they are apart.
  return point_in_triangle_2d(p[0], q[0], q[1], q[2]) || point_in_triangle_2d(q[0], p[0], p[1], p[2]);
}

bool is_degenerate(const Vec3& a, const Vec3& b, const Vec3& c) {
  return orient2d(a.x, a.y, b.x, b.y, c.x, c.y) == 0 && orient2d(a.y, a.z, b.y, b.z, c.y, c.z) == 0 &&
         orient2d(a.z, a.x, b.z, b.x, c.z, c.x) == 0;
}

// A zero-area triangle against one with area: its three edges cover it.
bool degenerate_intersects(const Vec3& d0, const Vec3& d1, const Vec3& d2, const Vec3& a,
                           const Vec3& b, const Vec3& c) {
  return segment_intersects_triangle(d0, d1, a, b, c) || segment_intersects_triangle(d1, d2, a, b, c) ||
         segment_intersects_triangle(d2, d0, a, b, c);
}

// The vertex of a triangle alone on its side of the other's plane, and the side it counts as.
// Returns the rotation r (vertex r becomes vertex 0) and sets `side` to +1 or -1.
int lone_vertex(const std::array<int, 3>& s, int& side) {
  for (int i = 0; i < 3; ++i) {
    const int a = s[(i + 1) % 3];
    const int b = s[(i + 2) % 3];
    if (s[i] != 0 && a != s[i] && b != s[i]) {
      side = s[i];
      return i;
    }
  }
  // Pattern (0, s, s) up to rotation: the triangle touches the plane at one vertex; that vertex
  // counts as lying on the other side so the interval on the planes' line is the single point.
  for (int i = 0; i < 3; ++i) {
    if (s[i] == 0) {
      side = -s[(i + 1) % 3];
      return i;
    }
  }
  side = 1;  // unreachable for a pattern that straddles and is not all zero
  return 0;
}

// orient3d against one fixed triangle (a, b, c) for several points d: the triangle's products are
// formed once. Bit for bit the same filter as orient3d below, so the same signs.
struct PlaneOrient {
  Vec3 a;
  double m1, m2, m3, m4, m5, m6;
  const Vec3* b;
  const Vec3* c;

  PlaneOrient(const Vec3& a_in, const Vec3& b_in, const Vec3& c_in) : a(a_in), b(&b_in), c(&c_in) {
    const Vec3 ba = b_in - a_in;
    const Vec3 ca = c_in - a_in;
    m1 = ba.y * ca.z;
    m2 = ba.z * ca.y;
    m3 = ba.z * ca.x;
    m4 = ba.x * ca.z;
    m5 = ba.x * ca.y;
    m6 = ba.y * ca.x;
  }

  int operator()(const Vec3& d) const {
    const Vec3 da = d - a;
    const double det = da.x * (m1 - m2) + da.y * (m3 - m4) + da.z * (m5 - m6);
    const double permanent = std::abs(da.x) * (std::abs(m1) + std::abs(m2)) +
                             std::abs(da.y) * (std::abs(m3) + std::abs(m4)) +
                             std::abs(da.z) * (std::abs(m5) + std::abs(m6));
    const double bound = kOrient3dBound * permanent;
    if (det > bound || -det > bound) return sign_of(det);
    return orient3d_exact(a, *b, *c, d);
  }
};

}  // namespace

int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) { return PlaneOrient(a, b, c)(d); }

int orient2d(double ax, double ay, double bx, double by, double cx, double cy) {
  const double left = (bx - ax) * (cy - ay);
  const double right = (by - ay) * (cx - ax);
  const double det = left - right;
  const double bound = kOrient2dBound * (std::abs(left) + std::abs(right));
  if (det > bound || -det > bound) return sign_of(det);
  // det2 = -det3 of the rows (point, 1), expanded into products of input coordinates.
  Expansion e;
  e.add_product(ax, by);
  e.add_product(-ax, cy);
  e.add_product(-ay, bx);
  e.add_product(ay, cx);
  e.add_product(bx, cy);
  e.add_product(-by, cx);
  return e.sign();
}

bool segment_intersects_triangle(const Vec3& s, const Vec3& t, const Vec3& a, const Vec3& b,
                                 const Vec3& c) {
  const int os = orient3d(a, b, c, s);
  const int ot = orient3d(a, b, c, t);
  if (os * ot > 0) return false;
  if (os == 0 && ot == 0) {  // the segment lies in the triangle's plane
    const int drop = dominant_axis(cross(b - a, c - a));
    const Point2 s2 = project(s, drop);
    const Point2 t2 = project(t, drop);
    const Point2 a2 = project(a, drop);
    const Point2 b2 = project(b, drop);
    const Point2 c2 = project(c, drop);
    return point_in_triangle_2d(s2, a2, b2, c2) || segments_intersect_2d(s2, t2, a2, b2) ||
           segments_intersect_2d(s2, t2, b2, c2) || segments_intersect_2d(s2, t2, c2, a2);
  }
  // The segment meets the plane in one point; it lies in the closed triangle when the line s->t
  // passes on the same side (or on) all three edges.
  const int e0 = orient3d(s, t, a, b);
  const int e1 = orient3d(s, t, b, c);
  const int e2 = orient3d(s, t, c, a);
  const bool has_negative = e0 < 0 || e1 < 0 || e2 < 0;
  const bool has_positive = e0 > 0 || e1 > 0 || e2 > 0;
  return !(has_negative && has_positive);
}

bool triangles_intersect(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& q0,
                         const Vec3& q1, const Vec3& q2) {
  // Where does P lie relative to Q's plane?
  const PlaneOrient q_plane(q0, q1, q2);
  std::array<int, 3> dp{q_plane(p0), q_plane(p1), q_plane(p2)};
  if (dp[0] == dp[1] && dp[1] == dp[2] && dp[0] != 0) return false;
  const PlaneOrient p_plane(p0, p1, p2);
  std::array<int, 3> dq{p_plane(q0), p_plane(q1), p_plane(q2)};
  if (dq[0] == dq[1] && dq[1] == dq[2] && dq[0] != 0) return false;

  const bool p_flat = dq[0] == 0 && dq[1] == 0 && dq[2] == 0;
  const bool q_flat = dp[0] == 0 && dp[1] == 0 && dp[2] == 0;
  if (p_flat || q_flat) {
    // Coplanar, or one triangle has no area (its "plane" gives all-zero orientations).
    const bool p_degenerate = is_degenerate(p0, p1, p2);
    const bool q_degenerate = is_degenerate(q0, q1, q2);
    if (p_degenerate && q_degenerate) return false;
    if (p_degenerate) return degenerate_intersects(p0, p1, p2, q0, q1, q2);
    if (q_degenerate) return degenerate_intersects(q0, q1, q2, p0, p1, p2);
    const int drop = dominant_axis(cross(p1 - p0, p2 - p0));
    return coplanar_triangles_intersect({project(p0, drop), project(p1, drop), project(p2, drop)},
                                        {project(q0, drop), project(q1, drop), project(q2, drop)});
  }

  // Rotate P so p0 is alone on its side of Q's plane; if that side is negative, reverse Q
  // (swap q1, q2), which flips Q's normal and so the side. Then the same for Q against P's plane.
  std::array<Vec3, 3> p{p0, p1, p2};
  std::array<Vec3, 3> q{q0, q1, q2};
  int side = 1;
  const int rp = lone_vertex(dp, side);
  p = {p[rp], p[(rp + 1) % 3], p[(rp + 2) % 3]};
  if (side < 0) {
    std::swap(q[1], q[2]);
    std::swap(dq[1], dq[2]);
  }
  const int rq = lone_vertex(dq, side);
  q = {q[rq], q[(rq + 1) % 3], q[(rq + 2) % 3]};
  if (side < 0) std::swap(p[1], p[2]);
  // Now p0 and q0 lie on the positive sides; both triangles cross the planes' common line in an
  // interval, and the intervals overlap iff these two orientations are both non-positive.
  return orient3d(p[0], p[1], q[0], q[1]) <= 0 && orient3d(p[0], p[2], q[2], q[0]) <= 0;
}

}  // namespace resecto

// Scoring: what the tracker accumulates at each collision step, the lobe order and the heat map.
#include "rtcore/metrics/score.h"

#include <algorithm>
#include <cmath>

#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/base/units.h"

namespace resecto {
namespace {

constexpr const char* kLobeLandmarks[kLobeCount] = {"median_lobe", "lateral_lobe_left", "lateral_lobe_right"};
// A lobe counts as reached when a quarter of what the procedure took from it had gone: a stray stroke
// grazing a neighbour does not reorder the lobes.
constexpr double kLobeReachedFraction = 0.25;
// The heat map's grid: about 2 mm cells across the gland, six axial slices apex to bladder neck.
constexpr int kGridXY = 26, kGridZ = 6;
// Until the device reports, the core parks the tool a metre away (withdrawn_pose()); a sheath tip
// further than this from the gland's origin is parked, and its jump in and out is not path.
constexpr double kParkedBeyondM = 0.5;
// The path counts the wire's moves of at least this from where it was last counted: the device's
// filtered sensor noise (~0.02 mm RMS at the wire) summed step by step made a still tool travel
// 47 mm a minute (audit 10, finding 2). A deliberate move is counted in 0.5 mm chords.
constexpr double kPathDeadbandM = 0.5e-3;

std::size_t cell_of(const ResectionHeatMap& grid, const Vec3& p) {
  auto index = [](double v, double o, double c, int n) { return std::clamp(static_cast<int>(std::floor((v - o) / c)), 0, n - 1); };
  const int i = index(p.x, grid.origin.x, grid.cell.x, grid.nx), j = index(p.y, grid.origin.y, grid.cell.y, grid.ny),
            k = index(p.z, grid.origin.z, grid.cell.z, grid.nz);
  return (static_cast<std::size_t>(k) * static_cast<std::size_t>(grid.ny) + static_cast<std::size_t>(j)) * static_cast<std::size_t>(grid.nx) +
         static_cast<std::size_t>(i);
}

}  // namespace

/// Adds `volume` to the cells of the tetrahedron (a, b, c, d) as its red refinement `depth` levels
/// down would hold it: Bey's eight equal children (four corners, the octahedron's four around its
/// m02-m13 diagonal), each binned at its centroid at the last level.
void spread_tetrahedron(const ResectionHeatMap& grid, std::vector<double>& cells, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d,
                        double volume, int depth) {
  if (depth == 0) {
    cells[cell_of(grid, 0.25 * (a + b + c + d))] += volume;
    return;
  }
  const Vec3 ab = 0.5 * (a + b), ac = 0.5 * (a + c), ad = 0.5 * (a + d), bc = 0.5 * (b + c), bd = 0.5 * (b + d), cd = 0.5 * (c + d);
  const double eighth = 0.125 * volume;
  spread_tetrahedron(grid, cells, a, ab, ac, ad, eighth, depth - 1);
  spread_tetrahedron(grid, cells, ab, b, bc, bd, eighth, depth - 1);
  spread_tetrahedron(grid, cells, ac, bc, c, cd, eighth, depth - 1);
  spread_tetrahedron(grid, cells, ad, bd, cd, d, eighth, depth - 1);
  const Vec3 equator[4] = {ab, ad, cd, bc};
  for (int k = 0; k < 4; ++k) spread_tetrahedron(grid, cells, ac, bd, equator[k], equator[(k + 1) % 4], eighth, depth - 1);
}

void rasterize_tissue(const MassSpringTissue& tissue, const ResectionHeatMap& grid, std::vector<double>& adenoma_m3, std::vector<double>& capsule_m3) {
  // Each tetrahedron spread as two levels of red refinement would split it (64 equal parts), so the
  // refinement near the loop, which splits the same way down to two levels, moves almost nothing
  // between cells, where one point per tetrahedron would move whole coarse tetrahedra.
  constexpr int kSpreadDepth = 2;
  const TetTopology& topology = tissue.topology();
  const std::span<const Vec3> rest = tissue.rest_positions();
  for (std::uint32_t t = 0; t < topology.slot_count(); ++t) {
    if (!topology.alive(t)) continue;
    const Tetrahedron& tet = topology.tetrahedron(t);
    std::vector<double>& cells = topology.region(t) == TissueRegion::kAdenoma ? adenoma_m3 : capsule_m3;
    spread_tetrahedron(grid, cells, rest[tet[0]], rest[tet[1]], rest[tet[2]], rest[tet[3]], tissue.rest_volume_m3(t), kSpreadDepth);
  }
}

ScoreTracker::ScoreTracker(const Simulation& sim) {
  const std::vector<Vec3> arc = loop_cutting_arc();
  if (!arc.empty()) wire_middle_tool_ = arc[arc.size() / 2];
  for (const Landmark& l : sim.prostate().landmarks) {
    for (int lobe = 0; lobe < kLobeCount; ++lobe) {
      if (l.name == kLobeLandmarks[lobe]) {
        lobes_[static_cast<std::size_t>(lobe)] = l.position;
        lobe_present_[lobe] = true;
      }
    }
  }
  tick_s_ = sim.config().tick_s();
  period_ticks_ = static_cast<std::uint64_t>(sim.config().physics_per_collision);
  last_adenoma_g_ = sim.metrics().resected_adenoma_g;
  last_cut_pedal_s_ = sim.metrics().cut_pedal_time_s;
  // The grid spans the tissue at rest, with half a cell of room.
  const std::span<const Vec3> rest = sim.tissue().rest_positions();
  Vec3 lo(1e30), hi(-1e30);
  for (const Vec3& p : rest) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  if (rest.empty()) lo = hi = Vec3(0.0);
  initial_.nx = initial_.ny = kGridXY;
  initial_.nz = kGridZ;
  const Vec3 extent = glm::max(hi - lo, Vec3(1e-6));
  initial_.cell = Vec3(extent.x / (kGridXY - 1), extent.y / (kGridXY - 1), extent.z / kGridZ * (1.0 + 1e-9));
  initial_.origin = lo - Vec3(0.5 * initial_.cell.x, 0.5 * initial_.cell.y, 0.0);
  const std::size_t cells = static_cast<std::size_t>(kGridXY) * kGridXY * kGridZ;
  initial_.initial_adenoma_m3.assign(cells, 0.0);
  initial_.initial_capsule_m3.assign(cells, 0.0);
  rasterize_tissue(sim.tissue(), initial_, initial_.initial_adenoma_m3, initial_.initial_capsule_m3);
}

void ScoreTracker::reserve(std::size_t steps) {
  series_.reserve(steps);
  lobe_history_.reserve(steps);
}

int ScoreTracker::nearest_lobe(const Vec3& wire) const {
  const double theta = std::atan2(wire.y, wire.x);
  int nearest = -1;
  double best = 0.0;
  for (int lobe = 0; lobe < kLobeCount; ++lobe) {
    if (!lobe_present_[lobe]) continue;
    const Vec3& crest = lobes_[static_cast<std::size_t>(lobe)];
    const double d = std::abs(std::remainder(theta - std::atan2(crest.y, crest.x), 2.0 * 3.141592653589793));
    if (nearest < 0 || d < best) nearest = lobe, best = d;
  }
  return nearest;
}

void ScoreTracker::observe(const Simulation& sim) {
  const ProcedureMetrics& m = sim.metrics();
  const double time_s = static_cast<double>(sim.tick()) * tick_s_;
  const ToolPoses& poses = sim.tool_poses();
  const Vec3 tip = poses.loop.apply_point(wire_middle_tool_);
  const bool placed = length(poses.sheath.translation) < kParkedBeyondM;
  if (!placed) {
    have_tip_ = false;
  } else if (!have_tip_) {
    counted_tip_ = tip;
    have_tip_ = true;
  } else if (const double moved = length(tip - counted_tip_); moved >= kPathDeadbandM) {
    path_m_ += moved;
    counted_tip_ = tip;
  }

  // Adenoma removed in this step goes to the lobe whose crest lies nearest the wire in angle around the
  // channel axis (the lobes differ by side: median posterior, laterals left and right; along the
  // channel they overlap, so distance in space would hand lateral cuts near the neck to the median lobe).
  const double removed_g = m.resected_adenoma_g - last_adenoma_g_;
  last_adenoma_g_ = m.resected_adenoma_g;
  if (removed_g > 0.0) {
    if (const int nearest = nearest_lobe(tip); nearest >= 0) lobe_g_[static_cast<std::size_t>(nearest)] += removed_g;
  }
  lobe_history_.push_back(lobe_g_);

  ScoreSample s;
  s.time_s = time_s;
  s.force_n = sim.largest_reaction_force_n_of_step();
  s.tool_placed = placed;
  s.insertion_mm = placed ? units::m_to_mm(poses.sheath.translation.z) : 0.0;
  s.resected_g = m.resected_total_g;
  s.cutting = m.cut_pedal_time_s > last_cut_pedal_s_;
  s.contact = sim.tissue().tool().stats().penetrating > 0;
  last_cut_pedal_s_ = m.cut_pedal_time_s;
  series_.push_back(s);
}

ProcedureScore ScoreTracker::finish(const Simulation& sim) const {
  ProcedureScore score;
  const ProcedureMetrics& m = sim.metrics();
  ScoreMetrics& out = score.metrics;
  out.procedure_time_s = static_cast<double>(sim.tick()) * tick_s_;
  out.resected_total_g = m.resected_total_g;
  out.resected_adenoma_g = m.resected_adenoma_g;
  out.resected_capsule_g = m.resected_capsule_g;
  out.remaining_adenoma_fraction = m.remaining_adenoma_fraction;
  out.grams_per_minute = out.procedure_time_s > 0.0 ? m.resected_total_g / (out.procedure_time_s / 60.0) : 0.0;
  out.cuts = m.cuts;
  out.grams_per_cut = m.cuts > 0 ? m.resected_total_g / static_cast<double>(m.cuts) : 0.0;
  out.chips = m.chips;
  out.perforations = m.perforations;
  out.sphincter_zone_violations = m.sphincter_zone_violations;
  out.sphincter_zone_cut_s = m.sphincter_zone_cut_s;
  out.loop_on_idle_s = m.loop_on_idle_s;
  out.tool_path_mm = units::m_to_mm(path_m_);
  out.tool_mean_speed_mm_s = out.procedure_time_s > 0.0 ? out.tool_path_mm / out.procedure_time_s : 0.0;
  out.contact_time_s = m.contact_time_s;
  out.peak_force_n = m.peak_reaction_force_n;
  out.mean_contact_force_n = m.mean_contact_force_n;
  out.cut_pedal_time_s = m.cut_pedal_time_s;
  // What the last steps removed after the last observation (the collision job a run's end collects,
  // Simulation::settle) goes to a lobe by the same rule, from where the wire is now: the lobes always
  // add up to the adenoma resected (audit 25, F2: a procedure ending in a stroke left 27% to none).
  std::array<double, kLobeCount> lobe_g = lobe_g_;
  if (const double tail_g = m.resected_adenoma_g - last_adenoma_g_; tail_g > 0.0) {
    if (const int nearest = nearest_lobe(sim.tool_poses().loop.apply_point(wire_middle_tool_)); nearest >= 0) {
      lobe_g[static_cast<std::size_t>(nearest)] += tail_g;
    }
  }
  out.lobe_adenoma_g = lobe_g;
  // The order lobes were reached in: the first step each had lost a quarter of its final total.
  std::array<std::size_t, kLobeCount> reached{};
  for (int lobe = 0; lobe < kLobeCount; ++lobe) {
    const auto l = static_cast<std::size_t>(lobe);
    reached[l] = lobe_history_.size();
    if (lobe_g[l] <= 0.0) continue;
    for (std::size_t step = 0; step < lobe_history_.size(); ++step) {
      if (lobe_history_[step][l] >= kLobeReachedFraction * lobe_g[l]) {
        reached[l] = step;
        break;
      }
    }
    out.lobe_order.push_back(lobe);
  }
  std::stable_sort(out.lobe_order.begin(), out.lobe_order.end(),
                   [&](int a, int b) { return reached[static_cast<std::size_t>(a)] < reached[static_cast<std::size_t>(b)]; });
  score.series = series_;
  // The heat map: what was there at the start minus what is there now, by cell and region.
  ResectionHeatMap& map = score.heat_map;
  map = initial_;
  std::vector<double> adenoma(map.initial_adenoma_m3.size(), 0.0), capsule(map.initial_capsule_m3.size(), 0.0);
  rasterize_tissue(sim.tissue(), map, adenoma, capsule);
  map.removed_adenoma_m3.resize(adenoma.size());
  map.removed_capsule_m3.resize(capsule.size());
  // Refinement keeps volume but moves centroids a little: a cell can gain a sliver from its neighbour.
  for (std::size_t c = 0; c < adenoma.size(); ++c) {
    map.removed_adenoma_m3[c] = std::max(0.0, map.initial_adenoma_m3[c] - adenoma[c]);
    map.removed_capsule_m3[c] = std::max(0.0, map.initial_capsule_m3[c] - capsule[c]);
  }
  return score;
}

}  // namespace resecto

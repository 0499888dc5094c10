// Scoring: the validity-study metrics of a procedure, computed by one module both live (the headless
// run feeds it the core at every collision step) and by re-simulation of a recording (`resecto
// score`), so a metric added here applies to every old recording. The core's running totals
// (ProcedureMetrics: grams by region, cuts, perforations, sphincter zone, loop on idle, force) are
// read as they are; this module adds what is measured across steps: the tool tip's path and speed,
// the rates per minute and per cut, the lobe order, time series for plots and a resection heat map.
// Each metric's unit and literature source are in docs/commands.md ("Scoring and debrief").
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "rtcore/core/simulation.h"

namespace resecto {

/// The lobes a TURP resects, in the order of the prostate's landmarks (median_lobe, lateral_lobe_left,
/// lateral_lobe_right).
inline constexpr int kLobeCount = 3;
inline constexpr const char* kLobeNames[kLobeCount] = {"median", "left_lateral", "right_lateral"};

/// One collision step's sample for the debrief's plots.
struct ScoreSample {
  double time_s = 0.0;
  double force_n = 0.0;         ///< the largest reaction force of the tissue on the tool over the step's ticks
  double insertion_mm = 0.0;    ///< sheath tip past the apex along the channel (negative: outside the gland); 0 while withdrawn
  bool tool_placed = false;     ///< the device had placed the tool (else it waits withdrawn, far from the gland)
  double resected_g = 0.0;      ///< total removed so far
  bool cutting = false;         ///< the cutting pedal was down during the step
  bool contact = false;         ///< some tool part pressed into tissue
};

/// Resected tissue on an axial grid (x, y in slices along z), rest positions: volumes per cell by
/// region, at the start and removed. Cells index as (k * ny + j) * nx + i.
struct ResectionHeatMap {
  int nx = 0, ny = 0, nz = 0;
  Vec3 origin{0.0};      ///< the grid's lower corner, metres
  Vec3 cell{0.0};        ///< cell size, metres
  std::vector<double> initial_adenoma_m3, initial_capsule_m3, removed_adenoma_m3, removed_capsule_m3;
};

/// Every metric of a procedure. Values in the units their names carry.
struct ScoreMetrics {
  double procedure_time_s = 0.0;
  double resected_total_g = 0.0;
  double resected_adenoma_g = 0.0;
  double resected_capsule_g = 0.0;
  double remaining_adenoma_fraction = 1.0;
  double grams_per_minute = 0.0;
  double grams_per_cut = 0.0;           ///< 0 with no cut, where it has no value (has_grams_per_cut)
  std::uint64_t cuts = 0;
  std::uint64_t chips = 0;
  std::uint64_t perforations = 0;
  std::uint64_t sphincter_zone_violations = 0;
  double sphincter_zone_cut_s = 0.0;
  double loop_on_idle_s = 0.0;
  double tool_path_mm = 0.0;            ///< the loop wire's middle point, summed over collision steps
  double tool_mean_speed_mm_s = 0.0;    ///< path over the time the tool was placed
  double contact_time_s = 0.0;
  double peak_force_n = 0.0;
  double mean_contact_force_n = 0.0;
  double cut_pedal_time_s = 0.0;
  /// Adenoma removed attributed to each lobe (kLobeNames order), grams.
  std::array<double, kLobeCount> lobe_adenoma_g{};
  /// Lobes in the order resection reached them (indices into kLobeNames); lobes never reached are absent.
  std::vector<int> lobe_order;
  // Named by the validity study, not measurable until bleeding and irrigation are simulated.
  static constexpr bool kBloodLossAvailable = false;
  static constexpr bool kIrrigantAvailable = false;
};

/// Whether grams per cut has a value: without a cut it has none (0 would read as cuts that removed
/// nothing); the reports write null, the CSV an empty cell, the debrief "n/a".
inline bool has_grams_per_cut(const ScoreMetrics& m) { return m.cuts > 0; }

/// The whole score of one procedure: metrics, plots, heat map.
struct ProcedureScore {
  ScoreMetrics metrics;
  std::vector<ScoreSample> series;
  ResectionHeatMap heat_map;
};

/// Follows a Simulation from its first tick; observe() after every collision step.
class ScoreTracker {
 public:
  /// Reads the landmarks and the tissue at rest (the heat map's "before"); `sim` has run no tick yet
  /// or none that cut. Allocates here and in observe() (the series grows: not for the core's step).
  explicit ScoreTracker(const Simulation& sim);

  /// Room for `steps` observations, so observe() on a real-time thread does not allocate.
  void reserve(std::size_t steps);
  /// After the collision step that sim.tick() - 1 was.
  void observe(const Simulation& sim);
  /// The score so far (the heat map is rasterized here: O(tetrahedra)).
  ProcedureScore finish(const Simulation& sim) const;

  const std::vector<ScoreSample>& series() const { return series_; }

 private:
  /// The lobe whose crest lies nearest the wire in angle around the channel axis (-1: no landmarks).
  int nearest_lobe(const Vec3& wire) const;
  Vec3 wire_middle_tool_{0.0};           // the cutting wire's middle point in the loop's frame
  std::array<Vec3, kLobeCount> lobes_{};  // landmark positions
  bool lobe_present_[kLobeCount] = {false, false, false};
  double verumontanum_z_m_ = 0.0;
  double tick_s_ = 0.0;
  std::uint64_t period_ticks_ = 1;
  Vec3 counted_tip_{0.0};  // where the wire was when its path last grew
  bool have_tip_ = false;
  double path_m_ = 0.0;
  double last_adenoma_g_ = 0.0;
  double last_cut_pedal_s_ = 0.0;
  std::array<double, kLobeCount> lobe_g_{};
  std::array<double, kLobeCount> lobe_first_s_{};  // when each lobe first lost adenoma (time order)
  std::vector<std::array<double, kLobeCount>> lobe_history_;  // cumulative per lobe at each step
  std::vector<ScoreSample> series_;
  ResectionHeatMap initial_;
};

/// Rasterizes the live tetrahedra's rest volumes by region into `map`'s grid (adds to the two arrays).
void rasterize_tissue(const MassSpringTissue& tissue, const ResectionHeatMap& grid, std::vector<double>& adenoma_m3,
                      std::vector<double>& capsule_m3);

}  // namespace resecto

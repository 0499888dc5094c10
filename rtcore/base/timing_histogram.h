// TimingHistogram: a running distribution of durations in fixed memory, for every timing the project
// reports (the profiler's stages, the device link's latency): log-spaced bins 1% wide from 10 ns to
// 100 s, so percentiles are within 1% and adding a sample never allocates.
#pragma once

#include <cstdint>
#include <vector>

namespace resecto {

class TimingHistogram {
 public:
  TimingHistogram();
  /// Adds one duration; negative values count as zero.
  void add(double microseconds);
  /// The q-quantile (0..1) in microseconds, nearest rank, at its bin's upper edge (never above the
  /// largest sample); 0 when empty.
  double quantile(double q) const;
  double max() const { return max_us_; }
  std::uint64_t count() const { return count_; }
  void clear();

 private:
  std::vector<std::uint32_t> bins_;
  std::uint64_t count_ = 0;
  double max_us_ = 0.0;
};

}  // namespace resecto

// The timing histogram's log-spaced bins.
#include "rtcore/base/timing_histogram.h"

#include <algorithm>
#include <cmath>

namespace resecto {
namespace {

constexpr double kSmallestUs = 0.01;     // 10 ns
constexpr double kLargestUs = 1e8;       // 100 s
constexpr double kBinGrowth = 1.01;      // 1% wide bins
const double kLogGrowth = std::log(kBinGrowth);
const int kBinCount = static_cast<int>(std::ceil(std::log(kLargestUs / kSmallestUs) / std::log(kBinGrowth))) + 2;

int bin_of(double us) {
  if (!(us > kSmallestUs)) return 0;
  return std::min(kBinCount - 1, 1 + static_cast<int>(std::log(us / kSmallestUs) / kLogGrowth));
}

/// The upper edge of a bin, the value a quantile falling into it reports.
double bin_upper_us(int bin) { return bin == 0 ? kSmallestUs : kSmallestUs * std::pow(kBinGrowth, bin); }

}  // namespace

TimingHistogram::TimingHistogram() : bins_(static_cast<std::size_t>(kBinCount), 0) {}

void TimingHistogram::add(double microseconds) {
  ++bins_[static_cast<std::size_t>(bin_of(microseconds))];
  ++count_;
  max_us_ = std::max(max_us_, microseconds);
}

double TimingHistogram::quantile(double q) const {
  if (count_ == 0) return 0.0;
  const auto rank = static_cast<std::uint64_t>(std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(count_)));
  std::uint64_t seen = 0;
  for (int b = 0; b < kBinCount; ++b) {
    seen += bins_[static_cast<std::size_t>(b)];
    if (seen >= std::max<std::uint64_t>(rank, 1)) return std::min(bin_upper_us(b), max_us_);
  }
  return max_us_;
}

void TimingHistogram::clear() {
  std::fill(bins_.begin(), bins_.end(), 0u);
  count_ = 0;
  max_us_ = 0.0;
}

}  // namespace resecto

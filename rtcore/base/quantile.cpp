// Nearest-rank quantiles.
#include "rtcore/base/quantile.h"

#include <algorithm>
#include <cmath>

namespace resecto {

double sorted_quantile(std::span<const double> sorted, double q) {
  if (sorted.empty()) return 0.0;
  const double rank = std::ceil(q * static_cast<double>(sorted.size()));
  // Clamped as a double: a q outside [0, 1] (or NaN) cannot wrap an unsigned rank.
  const double clamped = std::clamp(std::isnan(rank) ? 1.0 : rank, 1.0, static_cast<double>(sorted.size()));
  return sorted[static_cast<std::size_t>(clamped) - 1];
}

double quantile(std::vector<double> samples, double q) {
  std::sort(samples.begin(), samples.end());
  return sorted_quantile(samples, q);
}

}  // namespace resecto

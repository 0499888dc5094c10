// Quantiles of a list of samples by nearest rank: the one definition every report, command and
// benchmark uses for a median or a p99 of exact samples (TimingHistogram's is the same rank, read
// from bins, for a running record that must not allocate).
#pragma once

#include <span>
#include <vector>

namespace resecto {

/// The q-quantile (q in 0..1) of samples sorted ascending, by nearest rank: the sample at rank
/// ceil(q * n), counted from 1, clamped to [1, n]. 0 when empty.
double sorted_quantile(std::span<const double> sorted, double q);

/// The same of samples in any order (sorts its copy).
double quantile(std::vector<double> samples, double q);

}  // namespace resecto

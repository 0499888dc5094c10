// Spring forces: the incidence list built once, and the rare compressed-spring and linearisation
// passes (the per-spring pass is spring_kernel.cpp); they form a spring's length and direction with
// the kernel's operations, so they see the same lengths.
#include "rtcore/tissue/spring_forces.h"

#include <algorithm>
#include <cmath>

namespace resecto {
namespace {

struct SpringGeometry {
  Vec3 d;  // x[j] - x[i]
  double length;
  double inverse_length;  // 0 for a spring of zero length (no direction, no force)
};

[[gnu::always_inline]] inline SpringGeometry spring_geometry(const Vec3* x, std::uint32_t i, std::uint32_t j) {
  const Vec3 d = x[j] - x[i];
  const double length = std::sqrt(glm::dot(d, d));
  return {d, length, length > 0.0 ? 1.0 / length : 0.0};
}

[[gnu::always_inline]] inline bool compressed_below_half(double length, double rest_m) { return length > 0.0 && 2.0 * length < rest_m; }

constexpr SpringForce kPlusZeroRow{0.0, 0.0, 0.0, 0.0};
constexpr SpringForce kMinusZeroRow{-0.0, -0.0, -0.0, -0.0};
constexpr std::size_t kPaddingRows = 2;

void add_padding_rows(std::vector<SpringForce>& f) {
  f.push_back(kPlusZeroRow);
  f.push_back(kMinusZeroRow);
}

/// The longest of group g's four lists.
std::uint32_t group_longest(const std::vector<std::uint32_t>& list_first, std::size_t g) {
  const std::size_t n = g * kSpringSumGroup;
  std::uint32_t longest = 0;
  for (std::size_t k = 0; k < kSpringSumGroup; ++k) longest = std::max(longest, list_first[n + k + 1] - list_first[n + k]);
  return longest;
}

/// Writes group g's four lists into its block at `group`, each padded to `longest` with `padding`.
template <class SpringAt>
void write_group(const std::vector<std::uint32_t>& list_first, SpringAt spring_at, std::uint32_t padding, std::size_t g, std::uint32_t longest,
                 std::uint32_t* group) {
  for (std::size_t k = 0; k < kSpringSumGroup; ++k) {
    const std::size_t n = g * kSpringSumGroup + k;
    const std::uint32_t first = list_first[n], count = list_first[n + 1] - first;
    std::uint32_t e = 0;
    for (; e < count; ++e) group[kSpringSumGroup * e + k] = spring_at(first + e);
    for (; e < longest; ++e) group[kSpringSumGroup * e + k] = padding;
  }
}

/// A node list of every group, padded to the group's longest and interleaved (SpringIncidence).
/// `spring_at(p)` is the spring at position p of `list_first`'s lists. Offsets first, then each
/// node's list copied into its lane and padded: no test per entry (this runs once per batch of edits
/// on the collision job, where the topology update's time counts).
template <class SpringAt>
void interleave_groups(const std::vector<std::uint32_t>& list_first, SpringAt spring_at, std::uint32_t padding, std::vector<std::uint32_t>& offsets,
                       std::vector<std::uint32_t>& entries) {
  const std::size_t groups = (list_first.size() - 1) / kSpringSumGroup;
  offsets.resize(groups + 1);
  offsets[0] = 0;
  for (std::size_t g = 0; g < groups; ++g) offsets[g + 1] = offsets[g] + group_longest(list_first, g);
  entries.resize(kSpringSumGroup * offsets[groups]);  // within the reserved room
  std::uint32_t* out = entries.data();
  for (std::size_t g = 0; g < groups; ++g) write_group(list_first, spring_at, padding, g, offsets[g + 1] - offsets[g], out + kSpringSumGroup * offsets[g]);
}

/// interleave_groups() again after lists have only grown: the lists of the groups flagged in
/// `changed` (one byte per group; groups past the old count are new) are written afresh, every other
/// group's block is moved, whole runs at a time, to where the longer groups before it put it. The
/// result is the one interleave_groups() makes, for a copy of the blocks instead of a pass per entry.
template <class SpringAt>
void regroup_grown(const std::vector<std::uint32_t>& list_first, SpringAt spring_at, std::uint32_t padding, const std::vector<std::uint8_t>& changed,
                   std::vector<std::uint32_t>& offsets, std::vector<std::uint32_t>& entries, std::vector<std::uint32_t>& new_offsets) {
  const std::size_t groups = (list_first.size() - 1) / kSpringSumGroup;
  const std::size_t old_groups = offsets.size() - 1;
  new_offsets.resize(groups + 1);
  new_offsets[0] = 0;
  for (std::size_t g = 0; g < groups; ++g) {
    const bool kept = g < old_groups && !changed[g];
    new_offsets[g + 1] = new_offsets[g] + (kept ? offsets[g + 1] - offsets[g] : group_longest(list_first, g));
  }
  entries.resize(kSpringSumGroup * new_offsets[groups]);  // within the reserved room; only grows
  // Back to front: every block moves up (lists only grow), never onto one not yet moved.
  std::size_t g = groups;
  while (g > 0) {
    --g;
    if (g < old_groups && !changed[g]) {
      const std::size_t run_end = g + 1;
      while (g > 0 && !changed[g - 1]) --g;  // the run of unchanged groups [g, run_end): one shift
      if (new_offsets[g] != offsets[g]) {
        std::copy_backward(entries.begin() + kSpringSumGroup * offsets[g], entries.begin() + kSpringSumGroup * offsets[run_end],
                           entries.begin() + kSpringSumGroup * new_offsets[run_end]);
      }
      continue;
    }
    write_group(list_first, spring_at, padding, g, new_offsets[g + 1] - new_offsets[g], entries.data() + kSpringSumGroup * new_offsets[g]);
  }
  offsets.swap(new_offsets);
}

}  // namespace

SpringForces::SpringForces(const SpringNetwork& network) {
  const std::size_t count = network.spring_count();
  const std::size_t nodes = network.node_volume_m3.size();
  arrays_.i.resize(count);
  arrays_.j.resize(count);
  arrays_.rest_m = network.rest_length_m;
  arrays_.k.assign(count, 0.0);
  arrays_.c.assign(count, 0.0);
  arrays_.f.assign(count, SpringForce{});
  add_padding_rows(arrays_.f);
  padding_row_ = count;
  arrays_.compressed.assign(count, 0);
  for (std::size_t s = 0; s < count; ++s) {
    arrays_.i[s] = network.spring_nodes[2 * s];
    arrays_.j[s] = network.spring_nodes[2 * s + 1];
  }
  rebuild_incidence(nodes);
  refresh_groups();
}

void SpringForces::reserve(std::size_t spring_capacity, std::size_t node_capacity) {
  arrays_.i.reserve(spring_capacity);
  arrays_.j.reserve(spring_capacity);
  arrays_.rest_m.reserve(spring_capacity);
  arrays_.k.reserve(spring_capacity);
  arrays_.c.reserve(spring_capacity);
  // The padding rows go past the room for springs, where appends never move them: the groups'
  // padding entries then stay valid, and an edit relists only the groups whose lists grew.
  if (spring_capacity > padding_row_) {
    arrays_.f.resize(padding_row_);
    arrays_.f.resize(spring_capacity, SpringForce{});
    add_padding_rows(arrays_.f);
    padding_row_ = spring_capacity;
    groups_stale_ = true;
  }
  arrays_.compressed.reserve(spring_capacity);
  incidence_.second_springs.reserve(spring_capacity);
  incidence_.second_first.reserve(node_capacity + 1);
  incidence_.first_first.reserve(node_capacity + 1);
  if (spring_sums_in_groups()) {
    // A group's padded list is no longer than its four lists together: at most four entries a spring.
    incidence_.group_second.reserve(kSpringSumGroup * spring_capacity);
    incidence_.group_first.reserve(kSpringSumGroup * spring_capacity);
    incidence_.group_second_first.reserve(node_capacity / kSpringSumGroup + 1);
    incidence_.group_first_first.reserve(node_capacity / kSpringSumGroup + 1);
    new_group_offsets_.reserve(node_capacity / kSpringSumGroup + 1);
    group_grew_.reserve(node_capacity / kSpringSumGroup + 1);
  }
  grown_nodes_.reserve(2 * spring_capacity);
  fill_.reserve(node_capacity + 1);
  listed_per_chunk_.reserve(chunks_covering(spring_capacity, kSpringsPerChunk));
  chunk_first_.reserve(chunks_covering(spring_capacity, kSpringsPerChunk));
}

std::size_t SpringForces::compute(const Vec3* x, const Vec3* v, LoopHelper* helper, SideTask alongside) {
  refresh_groups();  // normally done by the edits' end already (MassSpringTissue): then free
  const std::size_t count = spring_count();
  const std::uint32_t chunks = chunks_covering(count, kSpringsPerChunk);
  listed_per_chunk_.resize(chunks);  // within the reserved room
  chunk_first_.resize(chunks);
  auto chunk_pass = [&](std::uint32_t chunk) {
    const std::size_t begin = chunk * kSpringsPerChunk, end = std::min(count, begin + kSpringsPerChunk);
    chunk_first_[chunk] = static_cast<std::uint32_t>(begin);
    listed_per_chunk_[chunk] = static_cast<std::uint32_t>(compute_range(x, v, begin, end));
  };
  for_each_chunk(helper, chunks, chunk_pass, alongside);
  return gather_compressed(chunk_first_, listed_per_chunk_);
}

std::size_t SpringForces::gather_compressed(std::span<const std::uint32_t> range_first, std::span<const std::uint32_t> listed) {
  // Each range listed its springs at its own start; close the gaps, in range order (so ascending).
  std::uint32_t* compressed = arrays_.compressed.data();
  std::size_t gathered = 0;
  for (std::size_t r = 0; r < range_first.size(); ++r) {
    const std::uint32_t* first = compressed + range_first[r];
    std::copy(first, first + listed[r], compressed + gathered);
    gathered += listed[r];
  }
  return gathered;
}

void SpringForces::append(std::uint32_t i, std::uint32_t j, double rest_m) {
  const std::size_t s = arrays_.i.size();
  arrays_.i.push_back(i);
  arrays_.j.push_back(j);
  arrays_.rest_m.push_back(rest_m);
  arrays_.k.push_back(0.0);
  arrays_.c.push_back(0.0);
  if (s < padding_row_) {
    arrays_.f[s] = SpringForce{};
  } else {  // past the reserved room: the padding rows move up, and every group's padding with them
    arrays_.f.insert(arrays_.f.end() - kPaddingRows, SpringForce{});
    padding_row_ = s + 1;
    groups_stale_ = true;
  }
  arrays_.compressed.push_back(0);
}

void SpringForces::rebuild_incidence(std::size_t nodes) {
  // Counting sort by node, springs visited in ascending order: each node's list is ascending.
  const std::size_t count = arrays_.i.size();
  SpringIncidence& in = incidence_;
  in.second_first.assign(nodes + 1, 0);
  in.first_first.assign(nodes + 1, 0);
  for (std::size_t s = 0; s < count; ++s) {
    ++in.first_first[arrays_.i[s] + 1];
    ++in.second_first[arrays_.j[s] + 1];
  }
  for (std::size_t n = 0; n < nodes; ++n) {
    in.first_first[n + 1] += in.first_first[n];
    in.second_first[n + 1] += in.second_first[n];
  }
  in.second_springs.resize(count);
  fill_.assign(in.second_first.begin(), in.second_first.end() - 1);
  for (std::size_t s = 0; s < count; ++s) in.second_springs[fill_[arrays_.j[s]]++] = static_cast<std::uint32_t>(s);
  groups_stale_ = true;
}

void SpringForces::refresh_groups() {
  if (groups_stale_) {
    rebuild_groups();
  } else if (!grown_nodes_.empty() || groups_behind_nodes()) {
    regroup_grown_nodes();
  }
  groups_stale_ = false;
  grown_nodes_.clear();
}

bool SpringForces::groups_behind_nodes() const {
  // Nodes added since the groups were listed may have completed a group of four.
  return spring_sums_in_groups() && incidence_.group_second_first.size() < (incidence_.first_first.size() - 1) / kSpringSumGroup + 1;
}

void SpringForces::regroup_grown_nodes() {
  SpringIncidence& in = incidence_;
  if (!spring_sums_in_groups()) return;  // no groups to keep (rebuild_groups)
  const std::size_t old_groups = in.group_second_first.size() - 1;
  group_grew_.assign(std::max(old_groups, (in.first_first.size() - 1) / kSpringSumGroup), 0);
  for (std::uint32_t n : grown_nodes_) {
    const std::size_t g = n / kSpringSumGroup;
    if (g < group_grew_.size()) group_grew_[g] = 1;
  }
  const auto plus_zero = static_cast<std::uint32_t>(padding_row_);
  regroup_grown(in.second_first, [&](std::uint32_t at) { return in.second_springs[at]; }, plus_zero, group_grew_, in.group_second_first, in.group_second,
                new_group_offsets_);
  regroup_grown(in.first_first, [](std::uint32_t at) { return at; }, plus_zero + 1, group_grew_, in.group_first_first, in.group_first, new_group_offsets_);
}

void SpringForces::rebuild_groups() {
  SpringIncidence& in = incidence_;
  if (!spring_sums_in_groups()) {  // the node pass goes node by node: no groups to keep
    in.group_second_first.clear();
    in.group_first_first.clear();
    in.group_second.clear();
    in.group_first.clear();
    return;
  }
  const auto plus_zero = static_cast<std::uint32_t>(padding_row_);
  interleave_groups(in.second_first, [&](std::uint32_t at) { return in.second_springs[at]; }, plus_zero, in.group_second_first, in.group_second);
  interleave_groups(in.first_first, [](std::uint32_t at) { return at; }, plus_zero + 1, in.group_first_first, in.group_first);
}

void SpringForces::keep(std::span<const std::uint32_t> kept, std::size_t node_count) {
  // Forward, in place: position k is read from kept[k] >= k, never from a place already written.
  auto compact = [&](auto& values) {
    for (std::size_t k = 0; k < kept.size(); ++k) values[k] = values[kept[k]];
    values.resize(kept.size());
  };
  compact(arrays_.i);
  compact(arrays_.j);
  compact(arrays_.rest_m);
  compact(arrays_.k);
  compact(arrays_.c);
  // The forces' rows in place: the padding rows stay past the reserved room.
  for (std::size_t k = 0; k < kept.size(); ++k) arrays_.f[k] = arrays_.f[kept[k]];
  arrays_.compressed.resize(kept.size());
  rebuild_incidence(node_count);
}

void SpringForces::add_nodes(std::size_t count) {
  // A new node holds no spring yet: empty ranges at the end (a group they complete is listed at the
  // next refresh: groups_behind_nodes).
  for (std::size_t k = 0; k < count; ++k) {
    incidence_.first_first.push_back(incidence_.first_first.back());
    incidence_.second_first.push_back(incidence_.second_first.back());
  }
}

void SpringForces::add_appended_to_incidence(std::size_t first_new) {
  // Every appended spring's index exceeds every listed one, so it goes at the end of its nodes'
  // lists and each list stays ascending: the same lists rebuild_incidence would make, formed by
  // moving each node's block of the second lists once, back to front (no scattered writes).
  SpringIncidence& in = incidence_;
  const std::size_t count = arrays_.i.size();
  const std::size_t nodes = in.first_first.size() - 1;
  if (first_new >= count) return;
  // First lists: the appended springs hold node i's above every earlier one's (append()).
  std::size_t s = in.first_first[arrays_.i[first_new]];
  for (std::size_t n = arrays_.i[first_new]; n < nodes; ++n) {
    while (s < count && arrays_.i[s] == n) ++s;
    in.first_first[n + 1] = static_cast<std::uint32_t>(s);
  }
  // Second lists: each node's block moves up by the appended springs of the nodes before it.
  fill_.assign(nodes, 0);
  for (std::size_t t = first_new; t < count; ++t) ++fill_[arrays_.j[t]];
  const std::size_t old_total = in.second_springs.size();
  in.second_springs.resize(old_total + (count - first_new));
  std::size_t shift = count - first_new;
  for (std::size_t n = nodes; n-- > 0 && shift > 0;) {
    shift -= fill_[n];  // the appended springs of nodes [0, n)
    const std::uint32_t begin = in.second_first[n], end = in.second_first[n + 1];
    std::copy_backward(in.second_springs.begin() + begin, in.second_springs.begin() + end, in.second_springs.begin() + end + shift);
    in.second_first[n + 1] = static_cast<std::uint32_t>(end + shift + fill_[n]);
    fill_[n] = static_cast<std::uint32_t>(end + shift);  // where n's appended springs go
  }
  for (std::size_t t = first_new; t < count; ++t) in.second_springs[fill_[arrays_.j[t]]++] = static_cast<std::uint32_t>(t);
  // Only the appended springs' nodes' lists grew: their groups are relisted at the next refresh.
  for (std::size_t t = first_new; t < count && !groups_stale_; ++t) {
    if (grown_nodes_.size() + 2 > grown_nodes_.capacity()) {
      groups_stale_ = true;  // past the reserved room: relist every group instead
      break;
    }
    grown_nodes_.push_back(arrays_.i[t]);
    grown_nodes_.push_back(arrays_.j[t]);
  }
}

void SpringForces::add_compression_bounds(const Vec3* x, double* stiffness_bound, std::size_t count) const {
  // Spring order: each node's bound sums its springs' excesses in the same order every run.
  for (std::size_t listed = 0; listed < count; ++listed) {
    const std::uint32_t s = arrays_.compressed[listed];
    const SpringGeometry g = spring_geometry(x, arrays_.i[s], arrays_.j[s]);
    if (!compressed_below_half(g.length, arrays_.rest_m[s])) continue;
    const double excess = 2.0 * arrays_.k[s] * (arrays_.rest_m[s] * g.inverse_length - 2.0);
    stiffness_bound[arrays_.i[s]] += excess;
    stiffness_bound[arrays_.j[s]] += excess;
  }
}

void SpringForces::linearise(const Vec3* x, Vec3* direction, double* transverse_k) const {
  for (std::size_t s = 0; s < spring_count(); ++s) {
    const SpringGeometry g = spring_geometry(x, arrays_.i[s], arrays_.j[s]);
    direction[s] = g.d * g.inverse_length;
    const double stretch = g.length - arrays_.rest_m[s];
    transverse_k[s] = arrays_.k[s] * std::max(0.0, stretch * g.inverse_length);  // tension only: keeps K >= 0
  }
}

}  // namespace resecto

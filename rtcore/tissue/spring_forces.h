// The springs' forces in two passes: one over springs that writes each spring's force into its own
// slot (independent iterations over structure-of-arrays data, so they pipeline and vectorise), then
// one over nodes that sums each node's spring forces through a fixed-order incidence list. The second
// pass replaces a scatter `force[i] += f; force[j] -= f` whose stores chained through memory.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "rtcore/concurrency/loop_helper.h"
#include "rtcore/geometry/vec3.h"
#include "rtcore/tissue/spring_kernel.h"
#include "rtcore/tissue/springs.h"

namespace resecto {

class SpringForces {
 public:
  explicit SpringForces(const SpringNetwork& network);

  std::size_t spring_count() const { return arrays_.i.size(); }
  const SpringArrays& arrays() const { return arrays_; }
  /// Sets a spring's stiffness and damping (between steps).
  void set_material(std::size_t s, double k_n_m, double c_ns_m) {
    arrays_.k[s] = k_n_m;
    arrays_.c[s] = c_ns_m;
  }

  /// The springs one chunk of the per-spring pass covers (a multiple of the AVX2 kernel's four).
  static constexpr std::size_t kSpringsPerChunk = 2048;

  /// The per-spring pass at positions x and velocities v (spring_kernel.h), in chunks shared with
  /// `helper` where there is one: every spring's force is its own, so the chunking changes no bit.
  /// Returns how many springs are compressed below half their rest length, listed ascending
  /// (add_compression_bounds handles those; usually none). `alongside` runs on this thread while
  /// the helper starts on the chunks (LoopHelper::for_each_chunk).
  std::size_t compute(const Vec3* x, const Vec3* v, LoopHelper* helper = nullptr, SideTask alongside = {});
  /// The per-spring pass over springs [begin, end) on this thread, one share of compute()'s work for
  /// a caller that chunks the springs itself (any thread, disjoint ranges; refresh_groups() first).
  /// Lists the compressed springs ascending from arrays().compressed[begin]; returns how many.
  std::size_t compute_range(const Vec3* x, const Vec3* v, std::size_t begin, std::size_t end) {
    return spring_forces(arrays_, x, v, incidence_.first_first.size() - 1, begin, end, arrays_.compressed.data() + begin);
  }
  /// Moves the lists compute_range() left at the starts of consecutive ranges (range r begins at
  /// range_first[r] and listed listed[r] springs) into one list from arrays().compressed[0], in
  /// range order (so ascending); returns its length.
  std::size_t gather_compressed(std::span<const std::uint32_t> range_first, std::span<const std::uint32_t> listed);

  /// The per-node pass: adds to each force[n] (n in [begin, end)) n's spring forces of the last
  /// compute(), in a fixed order (its springs as node j ascending, then as node i ascending). Each
  /// node's sum is its own, so node ranges may run on different threads.
  void add_sums(Vec3* force, std::size_t begin, std::size_t end) const { add_spring_sums(incidence_, arrays_.f.data(), force, begin, end); }
  void add_sums(Vec3* force) const { add_sums(force, 0, incidence_.first_first.size() - 1); }
  const SpringIncidence& incidence() const { return incidence_; }

  // Resection's edits (between steps). A removed spring stays in place with k = c = 0 (it then
  // forms no force), so the order the node pass relies on never breaks.
  /// Reserves room for this many springs and nodes, so appends and recounts allocate nothing.
  void reserve(std::size_t spring_capacity, std::size_t node_capacity);
  /// Appends a spring with k = c = 0. Its node i must be at least every earlier spring's node i
  /// (refinement's springs all hold a node newer than any before, so i is that node); then the
  /// springs stay sorted by i and each node's i-range stays contiguous.
  void append(std::uint32_t i, std::uint32_t j, double rest_m);
  /// Recounts the incidence over `node_count` nodes (counting sort, no allocation within the
  /// reserved room).
  void rebuild_incidence(std::size_t node_count);
  /// Keeps only the springs listed in `kept` (ascending), in their order, and relists the incidence
  /// over `node_count` nodes: spring s becomes the position of s in `kept`.
  void keep(std::span<const std::uint32_t> kept, std::size_t node_count);
  /// Extends the incidence by `count` new nodes that hold no spring yet.
  void add_nodes(std::size_t count);
  /// Lists springs [first_new, spring_count()), appended since the incidence was last complete, in
  /// their nodes' lists: the incidence rebuild_incidence would make, at the cost of moving the
  /// second lists once rather than recounting every spring.
  void add_appended_to_incidence(std::size_t first_new);

  /// Adds, in spring order, the Hessian-norm excess of each spring compressed below half its rest
  /// length to both its nodes' stiffness bounds (k |1 - L0/L| exceeds the k already counted): the
  /// `count` springs the last compute() listed.
  void add_compression_bounds(const Vec3* x, double* stiffness_bound, std::size_t count) const;

  /// Relists the incidence's interleaved groups if an edit has changed the lists or the spring count
  /// since: once per batch of edits (a refinement adds nodes, then springs), not once per edit.
  /// compute() does it too, so the node pass never reads stale groups; the editor calls it at the
  /// end of its edits so that the cost falls on the edit, not on a physics step.
  void refresh_groups();

  /// Implicit Euler's linearisation: each spring's unit direction and transverse stiffness.
  void linearise(const Vec3* x, Vec3* direction, double* transverse_k) const;

 private:
  void rebuild_groups();
  /// Relists only the groups of grown_nodes_ and of nodes added since (the others' blocks move).
  void regroup_grown_nodes();
  /// Whether nodes added since the groups were listed make a group the lists do not have yet.
  bool groups_behind_nodes() const;

  SpringArrays arrays_;
  SpringIncidence incidence_;
  std::size_t padding_row_ = 0;  // the +0 padding row of arrays_.f (the -0 one follows it)
  bool groups_stale_ = false;    // every group must be relisted (the padding moved, or a recount)
  std::vector<std::uint32_t> grown_nodes_;  // nodes whose lists grew since the groups were listed
  std::vector<std::uint8_t> group_grew_;    // scratch of regroup_grown_nodes(): per group
  std::vector<std::uint32_t> new_group_offsets_;  // scratch of regroup_grown_nodes()
  std::vector<std::uint32_t> fill_;  // scratch of rebuild_incidence
  std::vector<std::uint32_t> listed_per_chunk_;  // compute(): compressed springs each chunk listed
  std::vector<std::uint32_t> chunk_first_;       // compute(): each chunk's first spring
};

}  // namespace resecto

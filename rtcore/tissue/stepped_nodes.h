// Which nodes a physics step's node loops visit. Resection leaves orphans behind (nodes no
// tetrahedron holds any more: still, forceless, never held again) and after a full resection they
// are about as many as the live nodes (5,666 of 12,620 after `turp` at 8640 triangles), yet each
// cost the step its force sum, its bounds and its integration. The loops walk spans of whole groups
// of four nodes instead, skipping the groups with no node to step: the groups keep the four-wide
// kernels aligned (the spring sums' interleaved groups, the AVX2 integration), and a node inside a
// visited group is stepped exactly as before, so no stepped node's bits change.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace resecto {

struct NodeSpan {
  std::uint32_t begin = 0;  ///< a multiple of kGroup
  std::uint32_t end = 0;
};

class SteppedNodes {
 public:
  static constexpr std::size_t kGroup = 4;

  /// Room for `node_capacity` nodes in chunks of `nodes_per_chunk` (a multiple of kGroup), so a
  /// rebuild within them allocates nothing.
  void reserve(std::size_t node_capacity, std::size_t nodes_per_chunk);

  /// Lists the groups of [0, node_count) holding a node for which `needed(node)` is true, as
  /// ascending spans packed into chunks of `nodes_per_chunk` listed nodes each (the last one fewer):
  /// a chunk is a share of the loop's work for the loop helper, as a range of nodes was.
  template <typename Needed>
  void rebuild(std::size_t node_count, std::size_t nodes_per_chunk, Needed&& needed) {
    spans_.clear();
    chunk_first_.clear();
    chunk_first_.push_back(0);
    listed_ = 0;
    std::size_t in_chunk = 0;
    for (std::size_t group = 0; group < node_count; group += kGroup) {
      const std::size_t group_end = group + kGroup < node_count ? group + kGroup : node_count;
      bool any = false;
      for (std::size_t n = group; n < group_end && !any; ++n) any = needed(static_cast<std::uint32_t>(n));
      if (!any) continue;
      if (in_chunk == nodes_per_chunk) {
        chunk_first_.push_back(static_cast<std::uint32_t>(spans_.size()));
        in_chunk = 0;
      }
      const bool extends = !spans_.empty() && spans_.back().end == group && in_chunk > 0;
      if (extends) {
        spans_.back().end = static_cast<std::uint32_t>(group_end);
      } else {
        spans_.push_back({static_cast<std::uint32_t>(group), static_cast<std::uint32_t>(group_end)});
      }
      in_chunk += group_end - group;
      listed_ += group_end - group;
    }
    if (!spans_.empty()) chunk_first_.push_back(static_cast<std::uint32_t>(spans_.size()));
  }

  std::uint32_t chunk_count() const { return static_cast<std::uint32_t>(chunk_first_.size() - 1); }
  std::span<const NodeSpan> chunk(std::uint32_t c) const {
    return std::span<const NodeSpan>(spans_).subspan(chunk_first_[c], chunk_first_[c + 1] - chunk_first_[c]);
  }
  std::span<const NodeSpan> spans() const { return spans_; }
  /// Nodes the spans cover (the needed ones and their groups' others).
  std::size_t listed_nodes() const { return listed_; }

 private:
  std::vector<NodeSpan> spans_;
  std::vector<std::uint32_t> chunk_first_ = {0};  // chunk c: spans_[chunk_first_[c], chunk_first_[c + 1])
  std::size_t listed_ = 0;
};

}  // namespace resecto

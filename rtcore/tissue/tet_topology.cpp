// The live tetrahedral topology: slots, face neighbours found through the nodes' lists, and the
// lists kept as tetrahedra come and go. Every list is walked in its stored order, which follows from
// the order of the edits alone, so the same edits give the same topology on every run.
#include "rtcore/tissue/tet_topology.h"

#include <algorithm>
#include <cassert>

namespace resecto {

TetTopology::TetTopology(std::span<const Tetrahedron> tetrahedra, std::span<const TissueRegion> regions, std::size_t node_count,
                         std::size_t tetrahedron_capacity, std::size_t node_capacity)
    : tetrahedron_capacity_(std::max(tetrahedron_capacity, tetrahedra.size())), node_capacity_(std::max(node_capacity, node_count)) {
  tetrahedra_.reserve(tetrahedron_capacity_);
  regions_.reserve(tetrahedron_capacity_);
  alive_.reserve(tetrahedron_capacity_);
  neighbors_.reserve(4 * tetrahedron_capacity_);
  free_.reserve(tetrahedron_capacity_);
  entry_next_.reserve(4 * tetrahedron_capacity_);
  entry_prev_.reserve(4 * tetrahedron_capacity_);
  node_head_.reserve(node_capacity_);
  node_valence_.reserve(node_capacity_);
  node_head_.assign(node_count, kNone);
  node_valence_.assign(node_count, 0);
  for (std::size_t t = 0; t < tetrahedra.size(); ++t) add(tetrahedra[t], regions[t]);
}

void TetTopology::add_node() {
  assert(node_head_.size() < node_capacity_);
  node_head_.push_back(kNone);
  node_valence_.push_back(0);
}

std::uint32_t TetTopology::add(const Tetrahedron& tet, TissueRegion region) {
  std::uint32_t t;
  if (!free_.empty()) {
    t = free_.back();
    free_.pop_back();
    tetrahedra_[t] = tet;
    regions_[t] = region;
    alive_[t] = 1;
  } else {
    assert(tetrahedra_.size() < tetrahedron_capacity_);
    t = static_cast<std::uint32_t>(tetrahedra_.size());
    tetrahedra_.push_back(tet);
    regions_.push_back(region);
    alive_.push_back(1);
    for (int f = 0; f < 4; ++f) {
      neighbors_.push_back(kNone);
      entry_next_.push_back(kNone);
      entry_prev_.push_back(kNone);
    }
  }
  ++live_;
  link(t);
  // Into each corner's list, at its head.
  for (int c = 0; c < 4; ++c) {
    const std::uint32_t node = tet[static_cast<std::size_t>(c)];
    const auto e = static_cast<std::int32_t>(4 * t + static_cast<std::uint32_t>(c));
    entry_prev_[static_cast<std::size_t>(e)] = kNone;
    entry_next_[static_cast<std::size_t>(e)] = node_head_[node];
    if (node_head_[node] != kNone) entry_prev_[static_cast<std::size_t>(node_head_[node])] = e;
    node_head_[node] = e;
    ++node_valence_[node];
  }
  return t;
}

void TetTopology::link(std::uint32_t t) {
  // A face's neighbour is the other live tetrahedron holding its three corners: among the first
  // corner's tetrahedra (before t joins that list), the one that also holds the other two.
  for (int f = 0; f < 4; ++f) {
    const Triangle corners = face(t, f);
    std::int32_t found = kNone;
    for_each_tetrahedron_of(corners[0], [&](std::uint32_t u) {
      if (found != kNone) return;
      const Tetrahedron& other = tetrahedra_[u];
      const bool has1 = std::find(other.begin(), other.end(), corners[1]) != other.end();
      const bool has2 = std::find(other.begin(), other.end(), corners[2]) != other.end();
      if (has1 && has2) found = static_cast<std::int32_t>(u);
    });
    neighbors_[4 * t + static_cast<std::uint32_t>(f)] = found;
    if (found == kNone) continue;
    const auto u = static_cast<std::uint32_t>(found);
    // The corner of u not on the face names the face of u that t sits across.
    for (int g = 0; g < 4; ++g) {
      const std::uint32_t apex = tetrahedra_[u][static_cast<std::size_t>(g)];
      if (apex != corners[0] && apex != corners[1] && apex != corners[2]) {
        assert(neighbors_[4 * u + static_cast<std::uint32_t>(g)] == kNone && "a face shared by three tetrahedra");
        neighbors_[4 * u + static_cast<std::uint32_t>(g)] = static_cast<std::int32_t>(t);
      }
    }
  }
}

void TetTopology::remove(std::uint32_t t) {
  assert(alive_[t]);
  for (int f = 0; f < 4; ++f) {
    const std::int32_t n = neighbors_[4 * t + static_cast<std::uint32_t>(f)];
    if (n == kNone) continue;
    for (int g = 0; g < 4; ++g) {
      std::int32_t& back = neighbors_[4 * static_cast<std::uint32_t>(n) + static_cast<std::uint32_t>(g)];
      if (back == static_cast<std::int32_t>(t)) back = kNone;
    }
    neighbors_[4 * t + static_cast<std::uint32_t>(f)] = kNone;
  }
  for (int c = 0; c < 4; ++c) {
    const std::uint32_t node = tetrahedra_[t][static_cast<std::size_t>(c)];
    const std::size_t e = 4 * t + static_cast<std::uint32_t>(c);
    const std::int32_t prev = entry_prev_[e], next = entry_next_[e];
    if (prev != kNone) {
      entry_next_[static_cast<std::size_t>(prev)] = next;
    } else {
      node_head_[node] = next;
    }
    if (next != kNone) entry_prev_[static_cast<std::size_t>(next)] = prev;
    entry_next_[e] = entry_prev_[e] = kNone;
    --node_valence_[node];
  }
  alive_[t] = 0;
  --live_;
  free_.push_back(t);
}

}  // namespace resecto

// Reverse Cuthill-McKee over the tetrahedra's edges, from a pseudo-peripheral start per component.
#include "rtcore/tissue/node_order.h"

#include <algorithm>
#include <array>

namespace resecto {
namespace {

/// Each node's neighbours, ascending, as a compressed row list.
struct Adjacency {
  std::vector<std::uint32_t> first;  // per node + 1
  std::vector<std::uint32_t> neighbours;
  std::uint32_t degree(std::uint32_t n) const { return first[n + 1] - first[n]; }
};

Adjacency edge_graph(const TetMesh& mesh) {
  const std::size_t n = mesh.node_count();
  std::vector<std::uint64_t> edges;
  edges.reserve(12 * mesh.tetrahedron_count());
  for (const Tetrahedron& tet : mesh.tetrahedra) {
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) {
        if (a != b) edges.push_back(std::uint64_t{tet[a]} << 32 | tet[b]);
      }
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  Adjacency graph;
  graph.first.assign(n + 1, 0);
  graph.neighbours.reserve(edges.size());
  for (std::uint64_t e : edges) {
    ++graph.first[(e >> 32) + 1];
    graph.neighbours.push_back(static_cast<std::uint32_t>(e & 0xffffffffu));
  }
  for (std::size_t i = 0; i < n; ++i) graph.first[i + 1] += graph.first[i];
  return graph;
}

/// Breadth-first levels from `start` over unvisited nodes (marks nothing): the last level's
/// lowest-degree node and the number of levels.
struct FarEnd {
  std::uint32_t node;
  std::size_t levels;
};
FarEnd farthest(const Adjacency& graph, std::uint32_t start, std::vector<std::uint32_t>& level) {
  std::fill(level.begin(), level.end(), 0u);
  std::vector<std::uint32_t> frontier{start}, next;
  level[start] = 1;
  std::size_t levels = 1;
  for (;;) {
    next.clear();
    for (std::uint32_t u : frontier) {
      for (std::uint32_t e = graph.first[u]; e < graph.first[u + 1]; ++e) {
        const std::uint32_t w = graph.neighbours[e];
        if (level[w] == 0) {
          level[w] = static_cast<std::uint32_t>(levels + 1);
          next.push_back(w);
        }
      }
    }
    if (next.empty()) break;
    frontier.swap(next);
    ++levels;
  }
  std::uint32_t best = frontier.front();
  for (std::uint32_t u : frontier) {
    if (graph.degree(u) < graph.degree(best) || (graph.degree(u) == graph.degree(best) && u < best)) best = u;
  }
  return {best, levels};
}

/// A start far from the rest of its component (George and Liu): repeat the search from the far end
/// while the component's depth grows.
std::uint32_t pseudo_peripheral(const Adjacency& graph, std::uint32_t seed, std::vector<std::uint32_t>& level) {
  FarEnd current = farthest(graph, seed, level);
  std::uint32_t start = seed;
  for (int round = 0; round < 8; ++round) {
    const FarEnd next = farthest(graph, current.node, level);
    if (next.levels <= current.levels) break;
    start = current.node;
    current = next;
  }
  return current.levels > 1 ? current.node : start;
}

}  // namespace

std::vector<std::uint32_t> locality_order(const TetMesh& mesh) {
  const std::size_t n = mesh.node_count();
  const Adjacency graph = edge_graph(mesh);
  std::vector<std::uint8_t> placed(n, 0);
  std::vector<std::uint32_t> level(n, 0);
  std::vector<std::uint32_t> order;
  order.reserve(n);
  std::vector<std::uint32_t> children;
  // Components in the order of their lowest mesh index; within one, Cuthill-McKee's queue.
  for (std::uint32_t seed = 0; seed < n; ++seed) {
    if (placed[seed]) continue;
    const std::uint32_t start = pseudo_peripheral(graph, seed, level);
    std::size_t head = order.size();
    order.push_back(start);
    placed[start] = 1;
    for (; head < order.size(); ++head) {
      const std::uint32_t u = order[head];
      children.clear();
      for (std::uint32_t e = graph.first[u]; e < graph.first[u + 1]; ++e) {
        const std::uint32_t w = graph.neighbours[e];
        if (!placed[w]) {
          placed[w] = 1;
          children.push_back(w);
        }
      }
      std::sort(children.begin(), children.end(), [&](std::uint32_t a, std::uint32_t b) {
        return graph.degree(a) != graph.degree(b) ? graph.degree(a) < graph.degree(b) : a < b;
      });
      order.insert(order.end(), children.begin(), children.end());
    }
  }
  std::reverse(order.begin(), order.end());
  return order;
}

TetMesh renumbered(const TetMesh& mesh, std::span<const std::uint32_t> order) {
  std::vector<std::uint32_t> new_index(mesh.node_count(), 0);
  for (std::size_t k = 0; k < order.size(); ++k) new_index[order[k]] = static_cast<std::uint32_t>(k);
  TetMesh out;
  out.positions.resize(mesh.node_count());
  for (std::size_t k = 0; k < order.size(); ++k) out.positions[k] = mesh.positions[order[k]];
  out.tetrahedra = mesh.tetrahedra;
  for (Tetrahedron& tet : out.tetrahedra) {
    for (std::uint32_t& corner : tet) corner = new_index[corner];
  }
  out.regions = mesh.regions;
  return out;
}

EdgeSpan edge_span(const TetMesh& mesh) {
  std::vector<std::uint32_t> spans;
  spans.reserve(6 * mesh.tetrahedron_count());
  for (const Tetrahedron& tet : mesh.tetrahedra) {
    for (int a = 0; a < 4; ++a) {
      for (int b = a + 1; b < 4; ++b) spans.push_back(tet[a] > tet[b] ? tet[a] - tet[b] : tet[b] - tet[a]);
    }
  }
  if (spans.empty()) return {};
  std::sort(spans.begin(), spans.end());
  return {spans.back(), spans[spans.size() / 2]};
}

}  // namespace resecto

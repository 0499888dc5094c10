// A cache-friendly numbering of the tetrahedral mesh's nodes. TetGen numbers its nodes in insertion
// order, so a spring's two nodes sit hundreds of entries apart and every force pass misses the cache;
// the tissue steps a renumbered copy instead and maps back only where the mesh's numbering is public.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "rtcore/tissue/tet_mesh.h"

namespace resecto {

/// Reverse Cuthill-McKee order of the mesh's edge graph: entry k is the mesh node that becomes node k.
/// Neighbours are close in the new numbering (a small bandwidth), so each pass over springs or nodes
/// walks a narrow window of memory. Deterministic: ties go by degree, then by mesh index.
std::vector<std::uint32_t> locality_order(const TetMesh& mesh);

/// The mesh with node k = mesh node order[k]: positions moved, tetrahedra's corners renamed (their
/// order, orientation and regions unchanged).
TetMesh renumbered(const TetMesh& mesh, std::span<const std::uint32_t> order);

/// Largest and median |a - b| over the mesh's tetrahedron edges (a, b): how far apart a spring's nodes
/// sit in memory.
struct EdgeSpan {
  std::uint32_t max = 0;
  std::uint32_t median = 0;
};
EdgeSpan edge_span(const TetMesh& mesh);

}  // namespace resecto

// A block of tetrahedra (cubes of `cell_m` split six ways along their diagonal), the geometry oracle's
// specimen: simple enough that what a straight cut through it removes is known analytically.
#pragma once

#include <algorithm>
#include <array>

#include "rtcore/tissue/tet_mesh.h"

namespace resecto {

inline TetMesh block_mesh(int cells_x, int cells_y, int cells_z, double cell_m, TissueRegion region = TissueRegion::kCapsule) {
  TetMesh mesh;
  auto id = [&](int i, int j, int k) { return static_cast<std::uint32_t>((k * (cells_y + 1) + j) * (cells_x + 1) + i); };
  for (int k = 0; k <= cells_z; ++k) {
    for (int j = 0; j <= cells_y; ++j) {
      for (int i = 0; i <= cells_x; ++i) mesh.positions.push_back(Vec3(i, j, k) * cell_m);
    }
  }
  // Kuhn's six tetrahedra around the cube's diagonal 0-7 (corner bits: x 1, y 2, z 4).
  constexpr int kTets[6][4] = {{0, 1, 3, 7}, {0, 3, 2, 7}, {0, 2, 6, 7}, {0, 6, 4, 7}, {0, 4, 5, 7}, {0, 5, 1, 7}};
  for (int k = 0; k < cells_z; ++k) {
    for (int j = 0; j < cells_y; ++j) {
      for (int i = 0; i < cells_x; ++i) {
        for (const auto& t : kTets) {
          Tetrahedron tet;
          for (int c = 0; c < 4; ++c) tet[c] = id(i + (t[c] & 1), j + ((t[c] >> 1) & 1), k + ((t[c] >> 2) & 1));
          mesh.tetrahedra.push_back(tet);
          if (tetrahedron_volume(mesh, mesh.tetrahedra.size() - 1) < 0.0) std::swap(mesh.tetrahedra.back()[2], mesh.tetrahedra.back()[3]);
          mesh.regions.push_back(region);
        }
      }
    }
  }
  return mesh;
}

}  // namespace resecto

// The spring network of a tetrahedral mesh: one spring and damper per unique tetrahedron edge, the
// volume each node and edge stands for, and the capsule's outer nodes that anchor the gland.
#pragma once

#include <cstdint>
#include <vector>

#include "rtcore/tissue/tet_mesh.h"

namespace resecto {

/// Topology and rest geometry; material parameters are applied on top (see MassSpringTissue).
struct SpringNetwork {
  std::vector<std::uint32_t> spring_nodes;   ///< 2 per spring, smaller index first, sorted
  std::vector<double> rest_length_m;         ///< per spring
  std::vector<double> volume_share_m3;       ///< per spring: a sixth of each tetrahedron around it
  std::vector<double> node_volume_m3;        ///< per node: a quarter of each tetrahedron around it
  std::vector<std::uint32_t> anchor_nodes;   ///< capsule's outer nodes, ascending
  std::vector<double> anchor_area_m2;        ///< per anchor: a third of each outer face around it
  std::size_t spring_count() const { return rest_length_m.size(); }
};

/// Builds the network. Anchors are the boundary nodes of capsule tetrahedra: the outer surface, not
/// the channel wall (which borders adenoma).
SpringNetwork build_spring_network(const TetMesh& mesh);

/// The edge-spring rule: k = E * volume_share / rest_length^2. For a uniform strain e along every
/// edge the springs store sum(k (e L)^2 / 2) = E e^2 V / 2, the continuum's energy for that strain.
/// The same rule turns a viscosity into a damper.
inline double edge_spring_constant(double modulus_pa, double volume_share_m3, double rest_length_m) {
  return modulus_pa * volume_share_m3 / (rest_length_m * rest_length_m);
}

}  // namespace resecto

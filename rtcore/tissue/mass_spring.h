// MassSpringTissue: the deformable gland (paper sections 3.3-3.4). Nodes of the tetrahedral mesh with
// lumped masses, a spring and damper per tetrahedron edge, anchor springs on the capsule, penalty
// contact with the tool; hot state in flat arrays sized once, so a physics step allocates nothing.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "rtcore/collision/sphere_tree.h"
#include "rtcore/tissue/spring_forces.h"
#include "rtcore/tissue/springs.h"
#include "rtcore/tissue/tet_mesh.h"
#include "rtcore/tissue/tissue_parameters.h"
#include "rtcore/tissue/tool_contact.h"

namespace resecto {

/// How a physics step advances the nodes (README: the measured comparison behind the default).
enum class TissueIntegrator : std::uint8_t {
  /// Symplectic Euler whose per-node mass is raised by a Gershgorin bound of the step's stiffness
  /// and damping (D = m + h^2 R_K / 2 + h R_C): stable for every stiffness, one force pass a step,
  /// statics exact; fast modes are slowed instead of exploding. D follows the state, so a rise of D
  /// keeps each node's momentum and a fall keeps its velocity (no parametric pumping). The default.
  kBoundedSymplectic,
  /// Plain symplectic Euler split into as many sub-steps as the same bound demands: exact dynamics,
  /// cost that grows with sqrt(stiffness) and with resolution.
  kSubsteppedSymplectic,
  /// Linearised implicit Euler (Baraff-Witkin) with a Jacobi-preconditioned conjugate-gradient solve
  /// bounded to `max_cg_iterations`.
  kImplicitEuler,
};

/// Fixed choices of a tissue instance (not live parameters).
struct TissueConfig {
  TissueIntegrator integrator = TissueIntegrator::kBoundedSymplectic;
  int max_cg_iterations = 20;
  double cg_tolerance = 1e-4;          ///< relative residual at which CG stops
  int max_substeps = 4096;             ///< cap of kSubsteppedSymplectic; hitting it is flagged
  double contact_margin_m = 0.0015;
  ToolContactCapacity contact_capacity;
  /// Steps the nodes in locality order (node_order.h) rather than the mesh's; off only to measure
  /// what the order buys.
  bool locality_order = true;
  /// Lets the contact skip points whose clearance certificate holds (ToolContacts); off only for
  /// the brute-force reference, which gives the same forces.
  bool clearance_certificates = true;
};

/// Faults of the last step, counted rather than thrown (STYLE.md "Errors").
struct TissueFaults {
  std::int64_t non_finite_steps = 0;  ///< steps after which a position or velocity was NaN/inf
  std::int64_t first_non_finite_node = -1;
  std::int64_t substep_cap_hits = 0;
  std::int64_t contact_overflows = 0;
};

class MassSpringTissue {
 public:
  /// Builds the model from a tetrahedral mesh (metres). Allocates every array here. The nodes are
  /// renumbered for locality (TissueConfig::locality_order): positions(), velocities(), surface() and
  /// network() use the tissue's own numbering; mesh_node() and copy_mesh_positions() map back.
  MassSpringTissue(const TetMesh& mesh, const TissueParameters& parameters = {}, const TissueConfig& config = {});

  /// Applies a parameter command; call only between steps (the tick boundary). Allocates nothing.
  void apply(const ParameterCommand& command);
  /// Replaces every parameter at once (same rule).
  void set_parameters(const TissueParameters& parameters);
  const TissueParameters& parameters() const { return parameters_; }

  /// The tool's rigid parts and their poses; set the poses before each physics step.
  ToolContacts& tool() { return tool_; }
  const ToolContacts& tool() const { return tool_; }

  /// The 60 Hz collision step: copies the node positions into the surface, refits its sphere tree,
  /// and lets the tool find its candidate pairs, which the following physics steps use.
  void collision_step();

  // The same step in parts, for the core's pipeline: the refit and search may run on another thread
  // while physics steps go on with the candidates already published.
  /// Takes the node positions and the tool's poses the refit and search will use. Call between
  /// physics steps while no refit or search runs.
  void begin_collision_step();
  /// Refits the surface's sphere tree to the positions taken by begin_collision_step(). Reads and
  /// writes nothing a physics step touches.
  void refit_surface_tree();
  /// Finds the tool's candidate pairs against the refitted tree, into the tool's back buffer.
  void search_contact_candidates();
  /// Publishes the search's candidates to the physics steps; call between physics steps once the
  /// search has finished.
  void end_collision_step();
  /// One physics step of h_s seconds (default 1/960 s). Returns the reaction on the tool.
  ToolReaction physics_step(double h_s);

  /// 64-bit hash of positions, velocities and topology, bytes in index order. The topology's part is
  /// hashed once (about half the bytes at 8640 triangles); whatever changes the topology must renew it.
  std::uint64_t state_hash() const;

  std::size_t node_count() const { return x_.size(); }
  /// The mesh's index of the tissue's node `node`.
  std::uint32_t mesh_node(std::size_t node) const { return mesh_node_[node]; }
  /// out[m] = position of the mesh's node m, for m < out.size() (e.g. the anatomy surface's nodes,
  /// which are the mesh's first ones). Allocates nothing.
  void copy_mesh_positions(std::span<Vec3> out) const;
  std::span<const Vec3> positions() const { return x_; }
  std::span<const Vec3> velocities() const { return v_; }
  std::span<const Vec3> rest_positions() const { return rest_; }
  const TriangleMesh& surface() const { return surface_; }
  const SphereTree& surface_tree() const { return surface_tree_; }
  const SpringNetwork& network() const { return network_; }
  double total_mass_kg() const;
  double kinetic_energy_j() const;
  /// Largest distance of a node from its rest position.
  double max_displacement_m() const;
  const TissueFaults& faults() const { return faults_; }
  /// A bound on how far any node has moved since construction: the sum over steps of the step's
  /// largest node displacement (infinite once a step went non-finite). The tool contact's clearance
  /// certificates measure against it.
  double travel_m() const { return travel_m_; }
  /// Sub-steps the last physics step took (1 except for kSubsteppedSymplectic) and CG iterations.
  int last_substeps() const { return last_substeps_; }
  int last_cg_iterations() const { return last_cg_iterations_; }

 private:
  struct OrderedMesh {
    std::vector<std::uint32_t> mesh_node;  // per tissue node, its mesh index
    TetMesh mesh;                          // renumbered
  };
  static OrderedMesh ordered(const TetMesh& mesh, bool locality);
  MassSpringTissue(OrderedMesh&& ordered, const TissueParameters& parameters, const TissueConfig& config);

  void update_material();
  void accumulate_forces(double h_s);
  void step_bounded_symplectic(double h_s);
  void step_substepped_symplectic(double h_s);
  void step_implicit_euler(double h_s);
  void apply_system(double mass_coefficient, double damping_coefficient, double stiffness_coefficient,
                    std::span<const Vec3> p, std::span<Vec3> out) const;
  void check_finite();
  std::uint64_t topology_hash() const;
  void note_non_finite(std::size_t node);
  /// Adds a step's largest node displacement to travel_m_, with room for the positions' rounding.
  void add_travel(double largest_step_m);

  TissueParameters parameters_;
  TissueConfig config_;
  std::vector<std::uint32_t> mesh_node_, tissue_node_;  // tissue -> mesh numbering, and back
  SpringNetwork network_;
  std::vector<Tetrahedron> tetrahedra_;

  // Hot, per node.
  std::vector<Vec3> x_, v_, rest_, force_;
  std::vector<double> mass_, stiffness_bound_, damping_bound_;
  std::vector<double> step_mass_;  // D of the last bounded symplectic step (0 before the first)
  // Hot, per spring, in network_ order.
  SpringForces springs_;
  // The parameters' part of the per-node bounds (springs at rest, dampers, anchors, viscous).
  std::vector<double> base_stiffness_bound_, base_damping_bound_;
  // Per anchor (network_.anchor_nodes).
  std::vector<double> anchor_k_;
  // Implicit Euler only: per-spring linearisation and CG vectors.
  std::vector<Vec3> spring_direction_;
  std::vector<double> spring_transverse_k_;
  std::vector<Vec3> cg_r_, cg_z_, cg_p_, cg_q_, cg_dv_;

  TriangleMesh surface_;
  SphereTree surface_tree_;
  std::uint64_t topology_hash_ = 0;  // of the springs' nodes and the surface's triangles
  ToolContacts tool_;
  ToolReaction reaction_;
  TissueFaults faults_;
  int last_substeps_ = 1;
  int last_cg_iterations_ = 0;
  double travel_m_ = 0.0;
};

}  // namespace resecto

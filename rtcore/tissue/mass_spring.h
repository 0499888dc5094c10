// MassSpringTissue: the deformable gland (paper sections 3.3-3.4). Nodes of the tetrahedral mesh with
// lumped masses, a spring and damper per tetrahedron edge, anchor springs on the capsule, penalty
// contact with the tool; hot state in flat arrays sized once, so a physics step allocates nothing.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "rtcore/collision/sphere_tree.h"
#include "rtcore/concurrency/loop_helper.h"
#include "rtcore/tissue/spring_forces.h"
#include "rtcore/tissue/spring_sum_schedule.h"
#include "rtcore/tissue/springs.h"
#include "rtcore/tissue/stepped_nodes.h"
#include "rtcore/tissue/tissue_edit_log.h"
#include "rtcore/tissue/tet_mesh.h"
#include "rtcore/tissue/tet_topology.h"
#include "rtcore/tissue/tissue_parameters.h"
#include "rtcore/tissue/tool_contact.h"

namespace resecto {

/// How a physics step advances the nodes (benchmarks/results/README.md: the measured comparison behind the default).
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
  /// The contact margin's range: the command line's --contact-margin-mm and a recording's header.
  static constexpr double kMinContactMarginM = 1e-4, kMaxContactMarginM = 0.010;
  /// Temporal coherence of the contact search: a collision step whose tool and tissue have moved at
  /// most this far together from where the published candidates were searched (the tool's vertices
  /// at most a third of it: contact_candidates_still_serve) keeps them instead of refitting and
  /// searching again, its margin short by that much. 0: every collision step searches.
  double contact_reuse_m = 0.0003;
  /// The contact tree's refit leaves a face's sphere as it is while each of its corners stays within
  /// this distance of where it was fitted (SphereTree::set_refit_slack): under a tool only the
  /// pressed region moves that far between collision steps. Every sphere is that much larger, so the
  /// search's descent reaches a little further. 0: every sphere refitted every step.
  double surface_refit_slack_m = 0.0003;
  ToolContactCapacity contact_capacity;
  /// Steps the nodes in locality order (node_order.h) rather than the mesh's; off only to measure
  /// what the order buys.
  bool locality_order = true;
  /// Leaves the orphans resection leaves behind out of the physics step's node loops
  /// (stepped_nodes.h); off only to check that this changes no bit and to measure what it buys.
  bool skip_orphans = true;
  /// Sums each chunk of nodes' spring forces inside the spring pass, once the chunks holding its
  /// springs are computed (spring_sum_schedule.h), rather than in a pass of its own; off only to
  /// check that this changes no bit and to measure what it buys.
  bool fuse_spring_sums = true;
  /// Lets the contact skip points whose clearance certificate holds (ToolContacts); off only for
  /// the brute-force reference, which gives the same forces.
  bool clearance_certificates = true;
  /// Room reserved at construction for resection's edits, as a multiple of the model's own node,
  /// tetrahedron, spring and surface-face counts (local refinement adds all four). An edit that would
  /// pass a capacity is refused and counted (TissueFaults::topology_capacity_refusals).
  double topology_capacity_factor = 3.0;
  /// Floors of that room, whatever the model's size: refinement near the loop turns a coarse model's
  /// tetrahedra into many small ones (a 4 mm tetrahedron into ~20 of 1.5 mm), so a coarse gland
  /// needs far more room than a multiple of its own counts. About 20 MB in all.
  static constexpr std::size_t kMinTetrahedronCapacity = 160000;
  static constexpr std::size_t kMinNodeCapacity = 40000;
};

/// Faults of the last step, counted rather than thrown (STYLE.md "Errors").
struct TissueFaults {
  std::int64_t non_finite_steps = 0;  ///< steps after which a position or velocity was NaN/inf
  std::int64_t first_non_finite_node = -1;
  std::int64_t substep_cap_hits = 0;
  std::int64_t contact_overflows = 0;
  std::int64_t topology_capacity_refusals = 0;  ///< topology edits refused for want of reserved room
};

/// What one topology edit changed (MassSpringTissue::edit_tetrahedra).
struct TopologyChange {
  std::int32_t removed_tetrahedra = 0;
  std::int32_t added_tetrahedra = 0;
  std::int32_t surface_faces_removed = 0;
  std::int32_t surface_faces_added = 0;
  std::int32_t springs_removed = 0;
  std::int32_t springs_added = 0;
  std::int32_t nodes_orphaned = 0;
  bool refused = false;  ///< the capacities could not take it; nothing changed
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
  /// When refit_surface_tree() rebuilds a sphere tree that edits have decayed.
  enum class TreeRebuild {
    kWhenDue,          ///< as soon as SphereTree::should_rebuild()
    kOnlyWhenOverdue,  ///< only past SphereTree::must_rebuild(): the step is busy with edits already
  };
  /// Refits the surface's sphere tree to the positions taken by begin_collision_step(), after
  /// rebuilding it when edits have decayed it, as `rebuild` says: an overdue tree
  /// (SphereTree::must_rebuild) is rebuilt whole at once; with kWhenDue a decayed one
  /// (should_rebuild) is rebuilt in stages, a few levels of the build per collision step, beside it
  /// in a spare tree that takes its place once whole (an edit drops a staged rebuild begun before it,
  /// so under edits at every step only the overdue bound rebuilds). Returns whether it did
  /// rebuilding work. Reads and writes nothing a physics step touches. The tree's shape changes no
  /// result (the contact search finds exact sets, in point order), so when it is rebuilt is only a
  /// matter of time spent.
  bool refit_surface_tree(TreeRebuild rebuild = TreeRebuild::kWhenDue);
  /// Begins, or takes a stage further, the staged rebuild of a tree that edits have decayed
  /// (SphereTree::should_rebuild), at the surface's current positions; the next refit brings it to
  /// the search's positions. For the copy of the tissue the physics is not stepping, in a collision
  /// step with time to spare. Returns whether it did rebuilding work.
  bool rebuild_surface_tree_if_due();
  /// Levels of the staged rebuild (in leaf visits: a level visits each leaf once) a collision step
  /// takes: a build of the 8640 gland's ~17 levels then spreads over five collision steps.
  static constexpr int kStagedRebuildLevels = 4;
  /// Finds the tool's candidate pairs against the refitted tree, into the tool's back buffer.
  void search_contact_candidates();
  /// Publishes the search's candidates to the physics steps; call between physics steps once the
  /// search has finished.
  void end_collision_step();
  /// Whether the published candidates still serve the query begin_collision_step() latched, so the
  /// collision step may skip its refit and search (TissueConfig::contact_reuse_m). May run beside
  /// physics steps, like the search.
  bool contact_candidates_still_serve() const;
  /// One physics step of h_s seconds (default 1/960 s). Returns the reaction on the tool.
  ToolReaction physics_step(double h_s);
  /// Shares the physics step's spring and node loops with `helper` (nullptr: this thread alone).
  /// The state is the same bit for bit either way; the helper must outlive its use here.
  /// With `call_in` false the step does not call the helper in: it takes part only if its owner has
  /// it called in during the step (LoopHelper::call_in_when: the collision job ending; Simulation::step).
  void share_loops_with(LoopHelper* helper, bool call_in = true) {
    helper_ = helper;
    call_in_helper_ = call_in;
  }

  /// 64-bit hash of positions, velocities and topology, bytes in index order. The topology's part is
  /// hashed once (about half the bytes at 8640 triangles); whatever changes the topology must renew it.
  std::uint64_t state_hash() const;

  // ---- Topology edits (resection). Call while no physics step, refit or search uses this tissue (the
  // core's collision job edits the copy the physics is not stepping, before refitting and searching it).
  /// The live tetrahedra, their neighbours and each node's tetrahedra, in the tissue's numbering.
  const TetTopology& topology() const { return topology_; }
  /// Whether an edit adding `nodes` nodes and `added` tetrahedra, removing `removed`, fits the room
  /// reserved at construction.
  bool can_edit(std::size_t nodes, std::size_t added, std::size_t removed) const;
  /// Appends one node per pair at the pair's midpoint: rest position, position and velocity are the
  /// parents' averages. New node ids follow the existing ones in the tissue's and the mesh's
  /// numbering alike. The nodes stay orphans (massless, still) until a tetrahedron holds them.
  void add_midpoint_nodes(std::span<const std::array<std::uint32_t, 2>> parents);
  /// Removes the live slots `removed`, then adds `added` (with their regions): springs whose edge no
  /// live tetrahedron holds go, new edges get springs, masses, spring constants and bounds are
  /// recomputed at the touched nodes and springs, faces leave and join the surface and its sphere
  /// tree (insert/remove; the next search rebuilds it if that decayed it), contact candidates on changed faces and
  /// orphaned nodes are dropped and every clearance certificate voided, the topology hash renewed.
  /// Refused (nothing changes) when it does not fit the capacities. The added slots are listed by
  /// added_slots() until the next edit.
  TopologyChange edit_tetrahedra(std::span<const std::uint32_t> removed, std::span<const Tetrahedron> added,
                                 std::span<const TissueRegion> added_regions);
  std::span<const std::uint32_t> added_slots() const { return added_slots_; }
  /// Springs no live tetrahedron holds any more: they stay in place with k = c = 0 (forming no
  /// force, but still costing the physics step their share of its passes) until compact_springs().
  std::size_t dead_spring_count() const { return dead_springs_; }
  /// Drops the dead springs from every per-spring array, keeping the others' order: a pass over
  /// the springs (about a millisecond at 100,000), so the caller picks a moment nothing is cut. It
  /// changes no force and no state (a dead spring adds exactly zero), and frees their room.
  void compact_springs();
  std::int64_t spring_compactions() const { return spring_compactions_; }

  // ---- The second copy (tissue_edit_log.h): the core steps one copy while the collision thread
  // edits the other, which then takes over.
  /// Records every edit made from now on (add_midpoint_nodes, edit_tetrahedra, compact_springs) into
  /// `log`; null stops recording.
  void set_edit_log(TissueEditLog* log) { edit_log_ = log; }
  /// Makes the logged edits, in order, on this copy, which must hold the topology the logged copy
  /// held before them: it ends with the same topology, springs and surface.
  void replay(const TissueEditLog& log);
  /// Sets the parameters if they differ from this copy's (a pass over the material when they do).
  void match_parameters(const TissueParameters& parameters);
  /// Overwrites the first positions.size() node positions (the front copy's, taken at a collision
  /// tick), where the edits read them (a cut's centroids).
  void set_positions(std::span<const Vec3> positions);
  /// The search's positions become this copy's own (begin_collision_step without latching the tool,
  /// whose query state is copied from the front's: ToolContacts::copy_query_state).
  void take_search_positions();
  /// Takes over `front`'s motion after this copy was edited ahead of it: positions, velocities and the
  /// integrator's state of every node both hold; each node the edits added (`new_node_parents`, in
  /// order, from front.node_count() on) gets its parents' averages of the current ones; `orphans`
  /// stop; the tool's poses, the tissue's travel and the faults carry over, and the parameters if a
  /// command changed them meanwhile. Allocates nothing.
  void adopt_motion(const MassSpringTissue& front, std::span<const std::array<std::uint32_t, 2>> new_node_parents,
                    std::span<const std::uint32_t> orphans);
  /// Rest volume of live slot t (m^3).
  double rest_volume_m3(std::uint32_t t) const;
  /// Whether `node` is held by a capsule anchor spring (and still by a tetrahedron).
  bool anchored(std::uint32_t node) const { return anchor_of_node_[node] >= 0 && topology_.valence(node) > 0; }
  /// The tetrahedron slot and face (4 t + f) behind surface face slot s, or -1 for a free slot.
  std::int64_t surface_face_owner(std::size_t s) const { return face_owner_[s]; }
  std::size_t surface_face_count() const { return surface_faces_; }
  std::size_t surface_face_capacity() const { return surface_face_capacity_; }
  std::size_t node_capacity() const { return topology_.node_capacity(); }
  /// Rebuilds of the surface's sphere tree after edits decayed it (SphereTree::should_rebuild), done
  /// by the search (refit_surface_tree), so on the collision thread where there is one; counted when
  /// the new tree takes the old one's place. Read it while no search runs.
  std::int64_t surface_tree_rebuilds() const { return surface_tree_rebuilds_; }
  /// Bumped by every edit that changed the surface.
  std::uint64_t topology_version() const { return topology_version_; }
  /// The live surface, compacted (free slots skipped, in slot order) over the tissue's nodes.
  TriangleMesh live_surface(bool rest_positions) const;
  /// The live surface as a snapshot shows it: the faces in slot order over mesh node ids, each with
  /// its tetrahedron's region, as of topology version `version`. Sized once to the surface's capacity.
  struct MeshSurface {
    std::vector<Triangle> triangles;
    std::vector<TissueRegion> regions;
    std::size_t count = 0;
    std::uint64_t version = ~std::uint64_t{0};  ///< none listed yet
  };
  const MeshSurface& mesh_surface() const { return mesh_surface_; }
  /// Lists the live faces and their regions as MeshSurface does into `triangles` and `regions`, as many
  /// as fit in both; returns how many it listed.
  std::size_t list_mesh_surface(std::span<Triangle> triangles, std::span<TissueRegion> regions) const;
  /// Relists the nodes the physics step's loops visit, and plans when their spring sums run, if an
  /// edit changed them since (a pass over the nodes and the springs): the editor calls it after its
  /// edits, so that the cost falls on the edit; a physics step that finds the list stale relists it
  /// first. Allocates nothing.
  void refresh_stepped_nodes();
  /// Nodes the physics step's loops visit: every one a tetrahedron or an anchor holds, and the others
  /// of their groups of four (stepped_nodes.h).
  std::size_t stepped_node_count() const { return stepped_.listed_nodes(); }
  /// How many of those have their spring forces summed after the spring pass rather than inside it
  /// (spring_sum_schedule.h: refinement's springs reach them from a later chunk).
  std::size_t deferred_sum_node_count() const { return sum_schedule_.deferred().listed_nodes(); }
  /// Relists mesh_surface() if an edit changed the surface since (a pass over the surface, about 0.1 ms
  /// at 8640 triangles). The editor calls it after its edits, so that the core's publish at the
  /// collision tick that takes this copy in only copies the list. Allocates nothing.
  void refresh_mesh_surface();

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
  /// Largest distance of a tissue node (one some tetrahedron still holds) from its rest position.
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
  /// Rebuilds the surface's sphere tree over its present faces; counts it.
  void rebuild_surface_tree();
  /// Takes a staged rebuild a stage further, and puts the new tree in place once whole; returns
  /// whether one was under way.
  bool continue_staged_rebuild();
  struct OrderedMesh {
    std::vector<std::uint32_t> mesh_node;  // per tissue node, its mesh index
    TetMesh mesh;                          // renumbered
  };
  static OrderedMesh ordered(const TetMesh& mesh, bool locality);
  MassSpringTissue(OrderedMesh&& ordered, const TissueParameters& parameters, const TissueConfig& config);

  void update_material();
  /// A node's mass and the parameters' part of its bounds from its volume, springs and anchor.
  void update_node_material(std::uint32_t node, double density, double viscous_rate);
  void update_spring_material(std::size_t s, double modulus, double viscosity);
  // Topology edit parts (tissue_topology.cpp).
  void reserve_topology(std::size_t node_capacity, std::size_t tetrahedron_capacity);
  void map_initial_surface();
  std::int32_t find_spring(std::uint32_t a, std::uint32_t b) const;
  void insert_spring_key(std::uint32_t a, std::uint32_t b, std::uint32_t s);
  /// Recomputes a spring's volume share from the live tetrahedra holding its edge; returns how many do.
  int recompute_spring_share(std::size_t s);
  void add_surface_face(std::uint32_t t, int f);
  void remove_surface_face(std::uint32_t t, int f);
  std::uint64_t tetrahedron_hash(std::uint32_t t) const;
  /// How many faces an edit can add to the surface at most (removed slots stamped with stamp_).
  std::size_t surface_growth_bound(std::span<const std::uint32_t> removed, std::span<const Tetrahedron> added);
  std::uint64_t face_hash(std::size_t s) const;
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

  // Hot, per node.
  std::vector<Vec3> x_, v_, rest_, force_;
  // The positions the last contact search read (the surface's, taken by begin_collision_step, which
  // the next one overwrites): how far the tissue has moved since decides whether its candidates serve on.
  std::vector<Vec3> searched_positions_;
  // The physics step's node loops run in chunks of this many listed nodes (stepped_), shared with
  // helper_ if set.
  static constexpr std::size_t kNodesPerChunk = 512;
  LoopHelper* helper_ = nullptr;
  bool call_in_helper_ = true;  // physics_step() calls helper_ in (share_loops_with)
  // The nodes those loops visit (stepped_nodes.h), relisted after edits by refresh_stepped_nodes().
  SteppedNodes stepped_;
  bool stepped_stale_ = true;
  // When each chunk's spring sums run in the spring pass (spring_sum_schedule.h), planned with stepped_.
  SpringSumSchedule sum_schedule_;
  std::vector<std::uint32_t> compressed_per_chunk_;  // springs compressed below half their rest length, per chunk
  std::vector<double> fastest2_per_chunk_;
  std::vector<std::size_t> first_non_finite_per_chunk_;
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
  // Where a staged rebuild of surface_tree_ grows (refit_surface_tree); swapped in once whole.
  SphereTree spare_tree_;
  std::uint64_t topology_hash_ = 0;  // of the live tetrahedra and the surface's faces, kept per edit
  std::uint64_t topology_version_ = 0;
  MeshSurface mesh_surface_;
  std::int64_t surface_tree_rebuilds_ = 0;
  bool surface_tree_edited_ = false;  // an edit since the tree was last judged (or a rebuild deferred)
  TetTopology topology_;
  // Surface bookkeeping: per face slot, its owner 4 t + f (-1 free); per tetrahedron face, its slot.
  std::vector<std::int64_t> face_owner_;
  std::vector<std::int32_t> face_of_tetrahedron_;
  std::vector<std::uint32_t> free_faces_;
  std::size_t surface_faces_ = 0, surface_face_capacity_ = 0;
  std::vector<std::int32_t> anchor_of_node_;  // per node: its anchor index, -1 if none
  // Springs by edge: open addressing over (smaller << 32 | larger) -> spring index.
  std::vector<std::uint64_t> spring_keys_;
  std::vector<std::uint32_t> spring_values_;
  std::size_t spring_capacity_ = 0;
  std::size_t dead_springs_ = 0;  // springs with no live tetrahedron (volume share 0)
  std::int64_t spring_compactions_ = 0;
  // Edit scratch, reserved at construction.
  std::vector<std::uint32_t> node_stamp_, spring_stamp_, touched_nodes_, touched_springs_, added_slots_;
  std::vector<std::uint32_t> slot_stamp_, changed_faces_;
  std::vector<std::uint8_t> changed_face_, dead_node_;
  std::vector<std::int64_t> exposed_faces_;
  std::vector<std::array<std::uint32_t, 3>> face_keys_;
  struct NewSpring {
    std::uint32_t i, j;  // i the newer node
  };
  std::vector<NewSpring> new_springs_;
  std::uint32_t stamp_ = 0;
  TissueEditLog* edit_log_ = nullptr;
  ToolContacts tool_;
  ToolReaction reaction_;
  TissueFaults faults_;
  int last_substeps_ = 1;
  int last_cg_iterations_ = 0;
  double travel_m_ = 0.0;
};

}  // namespace resecto

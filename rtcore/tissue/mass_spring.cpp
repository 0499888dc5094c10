// The mass-spring tissue: material from the live parameters, forces, the three integrators, faults.
// Loops over springs run in spring index order and loops over nodes in node index order, so every
// sum is formed in the same order on every run (determinism).
#include "rtcore/tissue/mass_spring.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "rtcore/tissue/node_order.h"
#include "rtcore/tissue/node_step_kernel.h"
#include "rtcore/base/state_hash.h"

namespace resecto {
namespace {

std::size_t capacity_for(std::size_t count, double factor) {
  return static_cast<std::size_t>(std::ceil(static_cast<double>(count) * std::max(1.0, factor)));
}

}  // namespace

MassSpringTissue::OrderedMesh MassSpringTissue::ordered(const TetMesh& mesh, bool locality) {
  OrderedMesh out;
  if (locality) {
    out.mesh_node = locality_order(mesh);
    out.mesh = renumbered(mesh, out.mesh_node);
  } else {
    out.mesh_node.resize(mesh.node_count());
    for (std::size_t n = 0; n < mesh.node_count(); ++n) out.mesh_node[n] = static_cast<std::uint32_t>(n);
    out.mesh = mesh;
  }
  return out;
}

MassSpringTissue::MassSpringTissue(const TetMesh& mesh, const TissueParameters& parameters, const TissueConfig& config)
    : MassSpringTissue(ordered(mesh, config.locality_order), parameters, config) {}

MassSpringTissue::MassSpringTissue(OrderedMesh&& ordered_mesh, const TissueParameters& parameters, const TissueConfig& config)
    : parameters_(parameters),
      config_(config),
      mesh_node_(std::move(ordered_mesh.mesh_node)),
      network_(build_spring_network(ordered_mesh.mesh)),
      springs_(network_),
      topology_(ordered_mesh.mesh.tetrahedra, ordered_mesh.mesh.regions, ordered_mesh.mesh.node_count(),
                std::max(TissueConfig::kMinTetrahedronCapacity, capacity_for(ordered_mesh.mesh.tetrahedron_count(), config.topology_capacity_factor)),
                std::max(TissueConfig::kMinNodeCapacity, capacity_for(ordered_mesh.mesh.node_count(), config.topology_capacity_factor))),
      tool_(config.contact_margin_m, config.contact_capacity) {
  const TetMesh& mesh = ordered_mesh.mesh;
  const std::size_t n = mesh.node_count();
  const std::size_t s = network_.spring_count();
  tissue_node_.assign(n, 0);
  for (std::size_t k = 0; k < n; ++k) tissue_node_[mesh_node_[k]] = static_cast<std::uint32_t>(k);
  x_ = mesh.positions;
  rest_ = mesh.positions;
  v_.assign(n, Vec3(0.0));
  force_.assign(n, Vec3(0.0));
  mass_.assign(n, 0.0);
  stiffness_bound_.assign(n, 0.0);
  damping_bound_.assign(n, 0.0);
  step_mass_.assign(n, 0.0);
  base_stiffness_bound_.assign(n, 0.0);
  base_damping_bound_.assign(n, 0.0);
  anchor_k_.assign(network_.anchor_nodes.size(), 0.0);
  if (config_.integrator == TissueIntegrator::kImplicitEuler) {
    spring_direction_.assign(s, Vec3(0.0));
    spring_transverse_k_.assign(s, 0.0);
    for (auto* vec : {&cg_r_, &cg_z_, &cg_p_, &cg_q_, &cg_dv_}) vec->assign(n, Vec3(0.0));
  }
  tool_.set_clearance_skipping(config_.clearance_certificates);
  surface_ = boundary_surface(mesh);
  for (SphereTree* tree : {&surface_tree_, &spare_tree_}) {
    tree->set_slabs(false);  // its one query is the contact's, on spheres (ToolContacts)
    tree->set_refit_slack(config_.surface_refit_slack_m);
  }
  surface_tree_.build(surface_);
  reserve_topology(topology_.node_capacity(), topology_.tetrahedron_capacity());
  map_initial_surface();
  refresh_mesh_surface();
  refresh_stepped_nodes();
  topology_hash_ = topology_hash();
  update_material();
}

void MassSpringTissue::update_material() {
  const double modulus = parameters_.si(TissueParameter::kStiffness);
  const double viscosity = parameters_.si(TissueParameter::kSpringDamping);
  const double density = parameters_.si(TissueParameter::kDensity);
  const double anchor = parameters_.si(TissueParameter::kAnchorStiffness);
  const double viscous_rate = parameters_.si(TissueParameter::kViscousDamping);
  for (std::size_t s = 0; s < springs_.spring_count(); ++s) update_spring_material(s, modulus, viscosity);
  for (std::size_t a = 0; a < anchor_k_.size(); ++a) {
    const std::uint32_t node = network_.anchor_nodes[a];
    anchor_k_[a] = topology_.valence(node) > 0 ? anchor * network_.anchor_area_m2[a] : 0.0;
  }
  for (std::uint32_t i = 0; i < x_.size(); ++i) update_node_material(i, density, viscous_rate);
}

void MassSpringTissue::update_spring_material(std::size_t s, double modulus, double viscosity) {
  // A spring no tetrahedron holds any more (share 0) forms no force.
  const double share = network_.volume_share_m3[s];
  const double k = share > 0.0 ? edge_spring_constant(modulus, share, network_.rest_length_m[s]) : 0.0;
  const double c = share > 0.0 ? edge_spring_constant(viscosity, share, network_.rest_length_m[s]) : 0.0;
  springs_.set_material(s, k, c);
}

void MassSpringTissue::update_node_material(std::uint32_t node, double density, double viscous_rate) {
  // An orphan (no tetrahedron left) keeps a nominal mass so its step stays finite; it has no force
  // and no speed, so it stays where it is, out of every sum that matters (total_mass_kg skips it).
  const bool orphan = topology_.valence(node) == 0;
  mass_[node] = orphan ? 1.0 : density * network_.node_volume_m3[node];
  // Gershgorin rows at rest: each spring's Hessian blocks have norm k (more only when compressed
  // below half its length, added per step) and each row holds two of them; likewise the dampers.
  // Gathered through the incidence in its fixed order, so a local update forms the same sum.
  const SpringIncidence& in = springs_.incidence();
  const SpringArrays& arrays = springs_.arrays();
  double stiffness = 0.0, damping = viscous_rate * mass_[node];
  if (orphan) damping = 0.0;
  for (std::uint32_t e = in.second_first[node]; e < in.second_first[node + 1]; ++e) {
    stiffness += 2.0 * arrays.k[in.second_springs[e]];
    damping += 2.0 * arrays.c[in.second_springs[e]];
  }
  for (std::uint32_t s = in.first_first[node]; s < in.first_first[node + 1]; ++s) {
    stiffness += 2.0 * arrays.k[s];
    damping += 2.0 * arrays.c[s];
  }
  if (anchor_of_node_[node] >= 0) stiffness += anchor_k_[static_cast<std::size_t>(anchor_of_node_[node])];
  base_stiffness_bound_[node] = stiffness;
  base_damping_bound_[node] = damping;
}

void MassSpringTissue::apply(const ParameterCommand& command) {
  parameters_.values[static_cast<std::size_t>(command.id)] = command.value;
  update_material();
}

void MassSpringTissue::set_parameters(const TissueParameters& parameters) {
  parameters_ = parameters;
  update_material();
}

void MassSpringTissue::match_parameters(const TissueParameters& parameters) {
  if (parameters.values != parameters_.values) set_parameters(parameters);
}

void MassSpringTissue::collision_step() {
  begin_collision_step();
  refit_surface_tree();
  search_contact_candidates();
  end_collision_step();
}

void MassSpringTissue::begin_collision_step() {
  // The surface shares the tetrahedral mesh's node indices; its positions are the nodes' at this
  // moment, a copy the refit and search may read while the physics steps move the nodes on.
  std::copy(x_.begin(), x_.end(), surface_.positions.begin());
  tool_.latch_query_poses(travel_m_);
}

bool MassSpringTissue::refit_surface_tree(TreeRebuild rebuild) {
  // Edits insert and remove leaves in O(log n) each, which can unbalance the tree over many cuts;
  // judging that (a pass over the tree) and rebuilding belong here, off the core's tick, once per
  // collision step rather than once per edit. The refit after a rebuild makes every node's sphere
  // hold its children's (a build bounds the triangles below, which a child's sphere may exceed).
  bool rebuilding = false;
  if (surface_tree_edited_) {
    spare_tree_.abandon_build();  // its leaves are the tree's before these edits
    if (surface_tree_.must_rebuild()) {
      rebuild_surface_tree();
      rebuilding = true;
    } else if (rebuild == TreeRebuild::kWhenDue && surface_tree_.should_rebuild()) {
      spare_tree_.begin_build(surface_, surface_tree_);
      rebuilding = true;
    }
    // Judged (and rebuilt, or its rebuild begun, if due); a deferred one keeps the tree marked for a
    // quieter step.
    if (rebuild == TreeRebuild::kWhenDue) surface_tree_edited_ = false;
  }
  rebuilding = continue_staged_rebuild() || rebuilding;
  surface_tree_.refit(surface_);
  return rebuilding;
}

bool MassSpringTissue::rebuild_surface_tree_if_due() {
  if (surface_tree_edited_) {
    surface_tree_edited_ = false;
    spare_tree_.abandon_build();
    if (surface_tree_.should_rebuild()) spare_tree_.begin_build(surface_, surface_tree_);
  }
  return continue_staged_rebuild();
}

bool MassSpringTissue::continue_staged_rebuild() {
  // A whole rebuild beside the search overran the collision period (about 5 ms of processor at 8640
  // triangles, and the job shares its processor with the physics): the spare tree takes the build
  // kStagedRebuildLevels levels further a step, in leaf visits (the same count every run), and the
  // search keeps using the decayed tree, whose shape changes no result, until the new one is whole.
  if (!spare_tree_.build_pending()) return false;
  if (spare_tree_.continue_build(kStagedRebuildLevels * static_cast<std::int64_t>(spare_tree_.leaf_count()))) {
    std::swap(surface_tree_, spare_tree_);
    ++surface_tree_rebuilds_;
  }
  return true;
}

void MassSpringTissue::rebuild_surface_tree() {
  spare_tree_.abandon_build();
  surface_tree_.rebuild(surface_);
  ++surface_tree_rebuilds_;
  surface_tree_edited_ = false;
}

void MassSpringTissue::search_contact_candidates() {
  tool_.search_candidates(surface_tree_, surface_);
  // Kept only where a later step may ask whether these candidates still serve.
  if (config_.contact_reuse_m > 0.0) {
    searched_positions_.assign(surface_.positions.begin(), surface_.positions.begin() + static_cast<std::ptrdiff_t>(x_.size()));  // reserved
  }
}

bool MassSpringTissue::contact_candidates_still_serve() const {
  // The tool's shift first (a few hundred vertices); the tissue's, a pass over the nodes, only if needed.
  // The tool may take only a third of the allowance: a tool that moves needs the margin for its own
  // motion (at the turn of a fast stroke it is slow for a moment, and then fast again), while the
  // tissue's jitter under a resting tool is small and local.
  if (!(config_.contact_reuse_m > 0.0)) return false;
  const double tool_shift = tool_.tool_shift_since_search();
  if (!(3.0 * tool_shift <= config_.contact_reuse_m) || searched_positions_.size() != x_.size()) return false;
  double tissue_shift2 = 0.0;
  for (std::size_t n = 0; n < searched_positions_.size(); ++n) {
    const Vec3 d = surface_.positions[n] - searched_positions_[n];
    tissue_shift2 = std::max(tissue_shift2, glm::dot(d, d));
  }
  // Rounded up, as the tissue's travel is: the sum bounds how much nearer any pair can have come.
  return tool_shift + rounded_up(std::sqrt(tissue_shift2)) <= config_.contact_reuse_m;
}

void MassSpringTissue::end_collision_step() {
  tool_.publish_candidates();
  if (tool_.stats().overflowed) ++faults_.contact_overflows;
}

void MassSpringTissue::accumulate_forces(double h_s) {
  // Springs first, each into its own slot; then per node: viscous damping, its springs in ascending
  // spring order (SpringForces::add_sums), its anchor. Each node's force is thus the same sum in the
  // same order every run, and the bounds start from their constant part. The sums of a chunk of
  // nodes run as soon as the springs they read are computed (spring_sum_schedule.h), in chunks
  // shared with the loop helper; every value belongs to one spring or one node, so the threads
  // change no bit. The contact forces read only positions and velocities: this thread finds them
  // while the helper starts on the springs (with the tool in contact they were up to a fifth of the
  // step, run alone), and adds them last, as when they were found there.
  auto find_contact_forces = [&] {
    reaction_ = tool_.evaluate_forces(x_, v_, surface_.triangles, parameters_.si(TissueParameter::kPenaltyStiffness),
                                      parameters_.si(TissueParameter::kPenaltyDamping), h_s, travel_m_);
  };
  const double viscous_rate = parameters_.si(TissueParameter::kViscousDamping);
  // Viscous damping starts each node's force; springs, dampers, anchors and viscous damping bound
  // the same every step until a parameter changes (update_material), and what varies is added on top.
  auto start_node_forces = [&](NodeSpan span) {
    const std::size_t begin = span.begin, end = span.end;
    for (std::size_t i = begin; i < end; ++i) force_[i] = -viscous_rate * mass_[i] * v_[i];
    std::copy(base_stiffness_bound_.begin() + static_cast<std::ptrdiff_t>(begin), base_stiffness_bound_.begin() + static_cast<std::ptrdiff_t>(end),
              stiffness_bound_.begin() + static_cast<std::ptrdiff_t>(begin));
    std::copy(base_damping_bound_.begin() + static_cast<std::ptrdiff_t>(begin), base_damping_bound_.begin() + static_cast<std::ptrdiff_t>(end),
              damping_bound_.begin() + static_cast<std::ptrdiff_t>(begin));
  };
  auto add_spring_sums = [&](std::span<const NodeSpan> spans) {
    for (const NodeSpan span : spans) springs_.add_sums(force_.data(), span.begin, span.end);
  };
  std::size_t compressed = 0;
  if (config_.fuse_spring_sums && sum_schedule_.chunk_count() > 0) {
    // One pass: each chunk starts its nodes' forces and computes its springs, and whichever thread
    // completes the last chunk another waits for sums that one (spring_sum_schedule.h); the deferred
    // groups after it.
    springs_.refresh_groups();  // normally done by the edits' end already: then free
    sum_schedule_.arm();
    compressed_per_chunk_.resize(sum_schedule_.chunk_count());  // within the reserved room
    auto chunk_pass = [&](std::uint32_t chunk) {
      for (const NodeSpan span : stepped_.chunk(chunk)) start_node_forces(span);
      compressed_per_chunk_[chunk] = static_cast<std::uint32_t>(
          springs_.compute_range(x_.data(), v_.data(), sum_schedule_.spring_begin(chunk), sum_schedule_.spring_begin(chunk + 1)));
      sum_schedule_.finish(chunk, [&](std::uint32_t ready) { add_spring_sums(sum_schedule_.summed_spans(ready)); });
    };
    for_each_chunk(helper_, sum_schedule_.chunk_count(), chunk_pass, side_task(find_contact_forces));
    compressed = springs_.gather_compressed(sum_schedule_.spring_begins(), compressed_per_chunk_);
    const SteppedNodes& deferred = sum_schedule_.deferred();
    auto deferred_pass = [&](std::uint32_t chunk) { add_spring_sums(deferred.chunk(chunk)); };
    for_each_chunk(helper_, deferred.chunk_count(), deferred_pass);
  } else {
    compressed = springs_.compute(x_.data(), v_.data(), helper_, side_task(find_contact_forces));
    auto node_pass = [&](std::uint32_t chunk) {
      for (const NodeSpan span : stepped_.chunk(chunk)) {
        start_node_forces(span);
        springs_.add_sums(force_.data(), span.begin, span.end);
      }
    };
    for_each_chunk(helper_, stepped_.chunk_count(), node_pass);
  }
  for (std::size_t a = 0; a < anchor_k_.size(); ++a) {
    const std::uint32_t i = network_.anchor_nodes[a];
    force_[i] -= anchor_k_[a] * (x_[i] - rest_[i]);
  }
  if (compressed > 0) [[unlikely]] springs_.add_compression_bounds(x_.data(), stiffness_bound_.data(), compressed);
  if (config_.integrator == TissueIntegrator::kImplicitEuler) springs_.linearise(x_.data(), spring_direction_.data(), spring_transverse_k_.data());
  tool_.apply_forces(force_, stiffness_bound_, damping_bound_);
}

void MassSpringTissue::step_bounded_symplectic(double h_s) {
  accumulate_forces(h_s);
  // Gershgorin: every eigenvalue of D^-1 K is below max R_K / D and of D^-1 C below max R_C / D, so
  // with D = m + h^2 R_K / 2 + h R_C the step has h^2 lambda < 2 and h mu < 1, inside symplectic
  // Euler's region (h^2 lambda + 2 h mu < 4) for any stiffness, damping or resolution.
  // D follows the state (stretch, contacts), and an inertia that changes with the motion pumps
  // energy into it (parametric resonance: with no damping the stiffest and softest corners of the
  // ranges diverged). So a rise of D keeps the momentum D v and a fall keeps the velocity: both can
  // only lower the kinetic energy 1/2 D v^2, and the step stays symplectic while D holds still.
  // The finite check rides along: a node's sum is formed once it has moved.
  // Node by node, in chunks shared with the loop helper; each chunk keeps its own fastest speed and
  // first non-finite node, and the maximum and the minimum over chunks do not depend on the order.
  // The nodes the step leaves out (stepped_nodes.h) are orphans: still, so they add no speed, and finite.
  const std::size_t n = x_.size();
  const std::uint32_t chunks = stepped_.chunk_count();
  fastest2_per_chunk_.resize(chunks);  // within the reserved room
  first_non_finite_per_chunk_.resize(chunks);
  const NodeStepArrays nodes{mass_.data(), stiffness_bound_.data(), damping_bound_.data(), force_.data(), step_mass_.data(), v_.data(), x_.data()};
  auto integrate = [&](std::uint32_t chunk) {
    double fastest2 = 0.0;
    std::size_t first_non_finite = n;
    for (const NodeSpan span : stepped_.chunk(chunk)) {
      const NodeStepSummary summary = step_nodes(nodes, h_s, span.begin, span.end);
      fastest2 = std::max(fastest2, summary.fastest2);
      if (first_non_finite == n && summary.first_non_finite != NodeStepSummary::kNone) first_non_finite = summary.first_non_finite;
    }
    fastest2_per_chunk_[chunk] = fastest2;
    first_non_finite_per_chunk_[chunk] = first_non_finite;
  };
  for_each_chunk(helper_, chunks, integrate);
  const double fastest2 = chunks == 0 ? 0.0 : *std::max_element(fastest2_per_chunk_.begin(), fastest2_per_chunk_.end());
  const std::size_t first_non_finite = chunks == 0 ? n : *std::min_element(first_non_finite_per_chunk_.begin(), first_non_finite_per_chunk_.end());
  if (first_non_finite < n) [[unlikely]] note_non_finite(first_non_finite);
  add_travel(h_s * std::sqrt(fastest2));
  last_substeps_ = 1;
}

void MassSpringTissue::step_substepped_symplectic(double h_s) {
  // Sub-steps from the same bound with D = m: h_sub^2 R_K / m < 2 and h_sub R_C / m < 1 at every node,
  // measured at the start of the step (with 10% headroom for the stiffening within it).
  accumulate_forces(h_s);
  double rate = 0.0;
  for (std::size_t i = 0; i < x_.size(); ++i) {
    rate = std::max(rate, std::max(std::sqrt(stiffness_bound_[i] / (2.0 * mass_[i])), damping_bound_[i] / mass_[i]));
  }
  int substeps = std::max(1, static_cast<int>(std::ceil(1.1 * h_s * rate)));
  if (substeps > config_.max_substeps) {
    substeps = config_.max_substeps;
    ++faults_.substep_cap_hits;
  }
  const double h = h_s / substeps;
  ToolReaction total;
  for (int step = 0; step < substeps; ++step) {
    if (step > 0) accumulate_forces(h_s);
    total.force_n += reaction_.force_n;
    total.torque_nm += reaction_.torque_nm;
    double fastest2 = 0.0;
    for (std::size_t i = 0; i < x_.size(); ++i) {
      v_[i] += (h / mass_[i]) * force_[i];
      x_[i] += h * v_[i];
      fastest2 = std::max(fastest2, glm::dot(v_[i], v_[i]));
    }
    add_travel(h * std::sqrt(fastest2));
  }
  reaction_.force_n = total.force_n / static_cast<double>(substeps);
  reaction_.torque_nm = total.torque_nm / static_cast<double>(substeps);
  last_substeps_ = substeps;
}

void MassSpringTissue::apply_system(double mass_coefficient, double damping_coefficient, double stiffness_coefficient,
                                    std::span<const Vec3> p, std::span<Vec3> out) const {
  // out = (a M + b C + c K) p with the springs' linearisation from accumulate_forces; anchors enter
  // K, contacts only the preconditioner (they stay explicit).
  const double viscous_rate = parameters_.si(TissueParameter::kViscousDamping);
  for (std::size_t i = 0; i < p.size(); ++i) out[i] = mass_[i] * (mass_coefficient + damping_coefficient * viscous_rate) * p[i];
  for (std::size_t a = 0; a < anchor_k_.size(); ++a) {
    const std::uint32_t i = network_.anchor_nodes[a];
    out[i] += stiffness_coefficient * anchor_k_[a] * p[i];
  }
  const SpringArrays& springs = springs_.arrays();
  for (std::size_t s = 0; s < springs_.spring_count(); ++s) {
    const std::uint32_t i = springs.i[s], j = springs.j[s];
    const Vec3& u = spring_direction_[s];
    const Vec3 dp = p[j] - p[i];
    const double along = glm::dot(u, dp);
    const Vec3 value = (stiffness_coefficient * springs.k[s] + damping_coefficient * springs.c[s]) * along * u +
                       (stiffness_coefficient * spring_transverse_k_[s]) * (dp - along * u);
    out[i] -= value;
    out[j] += value;
  }
}

void MassSpringTissue::step_implicit_euler(double h_s) {
  accumulate_forces(h_s);
  const std::size_t n = x_.size();
  // Right-hand side h (f - h K v) with K = -df/dx (Baraff-Witkin).
  apply_system(0.0, 0.0, 1.0, v_, cg_q_);
  for (std::size_t i = 0; i < n; ++i) cg_r_[i] = h_s * (force_[i] - h_s * cg_q_[i]);
  // Jacobi-preconditioned CG from dv = 0, bounded.
  double rr0 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    cg_dv_[i] = Vec3(0.0);
    const double diagonal = mass_[i] + 0.5 * h_s * h_s * stiffness_bound_[i] + h_s * damping_bound_[i];
    cg_z_[i] = cg_r_[i] / diagonal;
    cg_p_[i] = cg_z_[i];
    rr0 += glm::dot(cg_r_[i], cg_z_[i]);
  }
  double rz = rr0;
  int iteration = 0;
  for (; iteration < config_.max_cg_iterations && rz > config_.cg_tolerance * config_.cg_tolerance * rr0 && rz > 0.0; ++iteration) {
    apply_system(1.0, h_s, h_s * h_s, cg_p_, cg_q_);
    double pq = 0.0;
    for (std::size_t i = 0; i < n; ++i) pq += glm::dot(cg_p_[i], cg_q_[i]);
    if (!(pq > 0.0)) break;
    const double alpha = rz / pq;
    double rz_next = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      cg_dv_[i] += alpha * cg_p_[i];
      cg_r_[i] -= alpha * cg_q_[i];
      const double diagonal = mass_[i] + 0.5 * h_s * h_s * stiffness_bound_[i] + h_s * damping_bound_[i];
      cg_z_[i] = cg_r_[i] / diagonal;
      rz_next += glm::dot(cg_r_[i], cg_z_[i]);
    }
    const double beta = rz_next / rz;
    rz = rz_next;
    for (std::size_t i = 0; i < n; ++i) cg_p_[i] = cg_z_[i] + beta * cg_p_[i];
  }
  double fastest2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    v_[i] += cg_dv_[i];
    x_[i] += h_s * v_[i];
    fastest2 = std::max(fastest2, glm::dot(v_[i], v_[i]));
  }
  add_travel(h_s * std::sqrt(fastest2));
  last_cg_iterations_ = iteration;
  last_substeps_ = 1;
}

ToolReaction MassSpringTissue::physics_step(double h_s) {
  refresh_stepped_nodes();  // normally done by the editor already
  if (helper_ != nullptr && call_in_helper_) helper_->call_in();
  switch (config_.integrator) {
    case TissueIntegrator::kBoundedSymplectic: step_bounded_symplectic(h_s); break;  // checks finiteness itself
    case TissueIntegrator::kSubsteppedSymplectic:
      step_substepped_symplectic(h_s);
      check_finite();
      break;
    case TissueIntegrator::kImplicitEuler:
      step_implicit_euler(h_s);
      check_finite();
      break;
  }
  if (helper_ != nullptr) helper_->send_home();
  return reaction_;
}

void MassSpringTissue::check_finite() {
  for (std::size_t i = 0; i < x_.size(); ++i) {
    const double sum = x_[i].x + x_[i].y + x_[i].z + v_[i].x + v_[i].y + v_[i].z;
    if (!std::isfinite(sum)) {
      note_non_finite(i);
      return;
    }
  }
}

void MassSpringTissue::add_travel(double largest_step_m) {
  // The positions' own rounding (x += h v, ~1e-17 m a step at the gland's coordinates) can carry a
  // node a hair further than the sum of h |v|; a femtometre a step and a relative part cover it, so
  // the travel bounds every node's displacement outright (about 4 nm of slack after an hour).
  travel_m_ += rounded_up(largest_step_m);
}

void MassSpringTissue::note_non_finite(std::size_t node) {
  if (faults_.first_non_finite_node < 0) faults_.first_non_finite_node = static_cast<std::int64_t>(node);
  ++faults_.non_finite_steps;
  // A NaN speed drops out of the steps' largest displacement; no clearance can be trusted after it.
  travel_m_ = std::numeric_limits<double>::infinity();
}

std::uint64_t MassSpringTissue::topology_hash() const {
  // A sum of per-element hashes, so an edit renews it by subtracting what left and adding what came
  // (tissue_topology.cpp): live tetrahedra by slot (they define the springs) and surface faces by slot.
  std::uint64_t hash = 0;
  for (std::uint32_t t = 0; t < topology_.slot_count(); ++t) {
    if (topology_.alive(t)) hash += tetrahedron_hash(t);
  }
  for (std::size_t s = 0; s < surface_.triangles.size(); ++s) {
    if (face_owner_[s] >= 0) hash += face_hash(s);
  }
  return hash;
}

std::uint64_t MassSpringTissue::state_hash() const {
  StateHasher hasher;
  hasher.add(std::span<const Vec3>(x_));
  hasher.add(std::span<const Vec3>(v_));
  hasher.add(std::span<const std::uint64_t>(&topology_hash_, 1));
  return hasher.value();
}

void MassSpringTissue::copy_mesh_positions(std::span<Vec3> out) const {
  const std::size_t count = std::min(out.size(), x_.size());
  for (std::size_t m = 0; m < count; ++m) out[m] = x_[tissue_node_[m]];
}

double MassSpringTissue::total_mass_kg() const {
  double total = 0.0;
  for (std::uint32_t i = 0; i < mass_.size(); ++i) {
    if (topology_.valence(i) > 0) total += mass_[i];
  }
  return total;
}

double MassSpringTissue::kinetic_energy_j() const {
  double energy = 0.0;
  for (std::size_t i = 0; i < v_.size(); ++i) energy += 0.5 * mass_[i] * glm::dot(v_[i], v_[i]);
  return energy;
}

double MassSpringTissue::max_displacement_m() const {
  double largest2 = 0.0;
  for (std::size_t i = 0; i < x_.size(); ++i) {
    // A node whose tetrahedra have all gone (cut, torn) is no tissue, wherever it was left.
    if (topology().valence(mesh_node_[i]) == 0) continue;
    largest2 = std::max(largest2, glm::dot(x_[i] - rest_[i], x_[i] - rest_[i]));
  }
  return std::sqrt(largest2);
}

}  // namespace resecto

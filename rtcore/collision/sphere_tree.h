// SphereTree: the paper's bounding-sphere hierarchy (section 3) over a triangle surface. Small leaf
// spheres cover every triangle (a long thin triangle gets a row of them), nodes live in one flat
// array with children by index, and the tree refits after deformation and takes insertions and
// removals of triangles for cutting, each O(log n).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "rtcore/mesh/triangle_mesh.h"

namespace resecto {

/// A bounding sphere, in the units of the mesh it covers.
struct Sphere {
  Vec3 center{0.0};
  double radius = 0.0;
};

/// A second bound per node, intersected with its sphere: every point of the node's triangles lies
/// between the planes normal . x = lo and normal . x = hi (normal unit). A leaf's slab is its
/// triangle's plane (lo == hi up to rounding), an internal node's is as thin as its children allow
/// along the mean of their normals. Two nearly parallel surfaces a fraction of a millimetre apart,
/// which spheres cannot tell apart, are separated by it (Collider's leaf and node tests).
struct Slab {
  Vec3 normal{0.0, 0.0, 1.0};
  double lo = 0.0;
  double hi = 0.0;
};

/// How a unit `normal` leans off a unit `axis`: their cosine k and an upper bound on their sine
/// (rounded up).
struct Lean {
  double k = 1.0;
  double sine = 0.0;
};
inline Lean lean_of(const Vec3& axis, const Vec3& normal) {
  const double k = dot(axis, normal);
  return {k, std::sqrt(std::max(0.0, 1.0 - k * k) + 1e-15)};
}

/// Bounds the projection onto unit `axis` of the region inside both `sphere` and `slab` (the
/// region a node's triangles lie in), `lean` being the slab normal's against the axis: the slab
/// gives the part along its normal, the sphere the rest, scaled by the sine. Intersected with the
/// sphere's own projection. Rounding is left to the caller's pad.
inline void project_region(const Sphere& sphere, const Slab& slab, const Vec3& axis, const Lean& lean, double& lo,
                           double& hi) {
  const double along = dot(axis, sphere.center);
  const double rest = along - lean.k * dot(slab.normal, sphere.center);
  const double slab_lo = lean.k >= 0.0 ? lean.k * slab.lo : lean.k * slab.hi;
  const double slab_hi = lean.k >= 0.0 ? lean.k * slab.hi : lean.k * slab.lo;
  lo = std::max(slab_lo + rest - sphere.radius * lean.sine, along - sphere.radius);
  hi = std::min(slab_hi + rest + sphere.radius * lean.sine, along + sphere.radius);
}
inline void project_bound(const Sphere& sphere, const Slab& slab, const Vec3& axis, double& lo, double& hi) {
  project_region(sphere, slab, axis, lean_of(axis, slab.normal), lo, hi);
}

/// Which part of a triangle a leaf covers: the triangle is cut into `slices` slabs by lines
/// parallel to its shortest edge; the leaf covers slab `slice` (0 .. slices-1). `apex` is the local
/// index (0..2) of the vertex opposite that edge. Affine in the vertices, so it follows deformation.
struct LeafPiece {
  std::uint32_t triangle = 0;
  std::uint16_t slice = 0;
  std::uint16_t slices = 1;
  std::uint8_t apex = 0;
};

/// Links of one node. A leaf has left == kNoNode; freed nodes chain through `left` in the free list.
struct SphereTreeLinks {
  std::int32_t parent = -1;
  std::int32_t left = -1;
  std::int32_t right = -1;
  std::int32_t height = 0;  ///< 0 for a leaf, 1 + the taller child's height otherwise
};

/// An internal node's two children, as the refit's merges read them.
struct ChildPair {
  std::int32_t left = -1;
  std::int32_t right = -1;
};

/// A sliced leaf's operands, as the refit reads them: its triangle's corners from the piece's apex on
/// (the apex, then the two ends of the edge the slabs run along) and the slab's bounds as weights of
/// the apex (SphereTree::piece_sphere's t0 and t1).
struct SliceOperands {
  Triangle corners{};
  double t0 = 0.0;
  double t1 = 0.0;
};

/// A snapshot of a tree's shape for the rebuild policy.
struct SphereTreeQuality {
  std::int32_t leaves = 0;
  std::int32_t height = 0;          ///< of the root (0 for a single leaf, -1 when empty)
  double height_bound = 0.0;        ///< the height the policy tolerates for this many leaves
  double mean_internal_radius = 0;  ///< mean radius of the internal nodes
  double radius_growth = 1.0;       ///< mean_internal_radius over its value at the last build
};

/// The sphere tree of one object's surface. It does not own the mesh: build, refit and insert read
/// the mesh passed in, whose triangle indices the leaves refer to.
class SphereTree {
 public:
  static constexpr std::int32_t kNoNode = -1;
  /// A triangle whose slab across its shortest edge is longer than this many times that edge is
  /// split into more leaves (at most kMaxSlices). Compact triangles keep one tight leaf each; only
  /// genuinely long thin ones (the sheath's side strips) are cut, into slabs this elongated.
  static constexpr double kSliceAspect = 3.0;
  static constexpr int kMaxSlices = 256;
  /// A spheres-only tree of at most this many live nodes (1 MiB of spheres) is refitted a height at
  /// a time over the whole tree; a larger one in cache-sized subtrees first, then the heights above.
  static constexpr std::int32_t kRefitWholeTreeNodes = 32768;

  /// The slab aspect used by later builds and insertions (kSliceAspect unless changed; >= 0.25).
  void set_slice_aspect(double aspect) { slice_aspect_ = aspect < 0.25 ? 0.25 : aspect; }
  double slice_aspect() const { return slice_aspect_; }

  /// Whether the tree keeps a slab beside every sphere (the default). Off, build, refit, insert and
  /// remove skip them (a refit costs about half) and queries use the spheres alone: for a tree
  /// whose queries need the spheres' semantics anyway (the contact's margin search). Takes effect
  /// at the next build.
  void set_slabs(bool enabled) { slabs_wanted_ = enabled; }
  /// Whether slabs() holds current slabs (set_slabs(true) at the last build).
  bool has_slabs() const { return slabs_kept_; }

  /// Builds top-down over every triangle of `mesh`, splitting at the middle of the principal
  /// component of the leaf centres (median split when one side would be empty).
  void build(const TriangleMesh& mesh);

  /// The rebuild policy's action: builds afresh, top-down, over the triangles now in the tree.
  void rebuild(const TriangleMesh& mesh);

  /// The same build in stages, for a caller that must bound each call's work (the core's collision
  /// job, where a whole rebuild beside the search overran the collision period): begin_build() makes
  /// the leaves of the triangles `covered` now holds (this tree's own, or another's) from `mesh`'s
  /// positions, and each continue_build() goes on for about `work` leaf visits (a level of the build
  /// visits every leaf once) and returns true once the tree is whole. The result is the tree rebuild()
  /// would have made from those positions. Until then the tree must not be queried, refitted or
  /// edited. `mesh` must outlive the build; its positions may change between calls (they shape the
  /// tree only, and the refit after it measures them).
  void begin_build(const TriangleMesh& mesh, const SphereTree& covered);
  bool continue_build(std::int64_t work);
  /// Whether a build is under way (begun, not yet whole).
  bool build_pending() const { return build_mesh_ != nullptr; }
  /// Drops a build under way (the tree it was replacing changed); the tree is then empty until the
  /// next build.
  void abandon_build();

  /// Recomputes every sphere bottom-up from the mesh's current vertex positions (section 3.4).
  /// Allocates nothing once the tree's size has been seen before. The vertices may move; a triangle
  /// whose corners change must be removed and inserted again (the tree keeps its leaves' corners).
  /// With a refit slack (set_refit_slack), only the leaves with a corner that moved further than
  /// the slack since they were last fitted are fitted again, with their ancestors.
  void refit(const TriangleMesh& mesh);

  /// Lets refit() leave a leaf alone while none of its corners has moved further than `slack`
  /// (mesh units) since it was fitted: every leaf sphere is fitted to its corners as they were then
  /// and grown by `slack`, which holds the triangle as long as each corner stays within `slack` of
  /// where it was (a triangle's point is a weighted mean of its corners). Spheres-only trees (the
  /// contact's search); 0, the default, refits every sphere every time. A refit after a build or an
  /// edit fits every leaf without slack; the first one after it without an edit fits every leaf with
  /// the slack and records the positions, and the ones after that spare what stayed within it.
  void set_refit_slack(double slack);
  double refit_slack() const { return refit_slack_; }
  /// The leaves the last refit() fitted (every one unless the slack spared some).
  std::int32_t last_refit_leaves() const { return last_refit_leaves_; }

  /// Adds the leaves of triangle `t` of `mesh`, each descending by the principal direction of the
  /// nodes it passes (the line between their children's centres), then refits the path (3.5).
  void insert_triangle(const TriangleMesh& mesh, std::uint32_t t);

  /// Removes every leaf of triangle `t`: each leaf's sibling takes its parent's place, the
  /// ancestors are refitted, and the two freed nodes go to the free list (3.5).
  void remove_triangle(std::uint32_t t);

  /// Reserves room for `max_nodes` nodes over up to `max_triangles` triangle slots and meshes of up
  /// to `max_vertices` vertices, so insertions and refits within it allocate nothing (a tissue that
  /// resection grows reserves its room at start).
  void reserve(std::int32_t max_nodes, std::uint32_t max_triangles, std::size_t max_vertices = 0);
  /// The current shape and how far it has drifted from the last build.
  SphereTreeQuality quality() const;
  /// True when the tree is taller than the policy tolerates (over 2 log2(n) + 4) or its internal
  /// spheres have grown on average to more than twice their size at the last build.
  bool should_rebuild() const;
  /// True when the tree has decayed twice as far as should_rebuild() tolerates (height over
  /// 2 (2 log2(n) + 4), or internal spheres four times their built size): a rebuild that a caller
  /// deferred to a quieter moment cannot wait any longer.
  bool must_rebuild() const;

  std::int32_t root() const { return root_; }
  bool empty() const { return root_ == kNoNode; }
  bool is_leaf(std::int32_t node) const { return links_[node].left == kNoNode; }
  /// Every slot of the node array, live or free; node indices are below this.
  std::int32_t node_capacity() const { return static_cast<std::int32_t>(links_.size()); }
  std::int32_t leaf_count() const { return leaf_count_; }
  std::int32_t live_node_count() const { return live_nodes_; }
  std::int32_t free_node_count() const;

  const std::vector<Sphere>& spheres() const { return spheres_; }
  const std::vector<SphereTreeLinks>& links() const { return links_; }
  /// Per node, the slab bound beside the sphere (kept by build, refit, insert and remove).
  const std::vector<Slab>& slabs() const { return slabs_; }
  /// Changes whenever the node structure changes (build, rebuild, insert, remove), never on refit:
  /// what a query caching node pairs between calls checks.
  std::uint64_t structure_version() const { return structure_version_; }
  const std::vector<LeafPiece>& pieces() const { return pieces_; }
  /// First leaf of triangle t (kNoNode if none); the rest follow through next_leaf_of_triangle().
  std::int32_t first_leaf_of_triangle(std::uint32_t t) const {
    return t < first_leaf_.size() ? first_leaf_[t] : kNoNode;
  }
  std::int32_t next_leaf_of_triangle(std::int32_t leaf) const { return next_leaf_[leaf]; }

  /// The sphere of one leaf piece of the mesh's current geometry (inflated a hair so rounding can
  /// never leave a point of the piece outside it).
  static Sphere piece_sphere(const TriangleMesh& mesh, const LeafPiece& piece);
  /// The sphere of the slab of triangle (b, x, y) between the lines at apex weights t0 and t1 (the
  /// lines run parallel to the edge x-y; b is the apex), as piece_sphere() gives it for a sliced piece.
  static Sphere slice_sphere(const Vec3& b, const Vec3& x, const Vec3& y, double t0, double t1);
  /// A sliced piece's operands for the refit (the corners' indices in the mesh and the weights).
  static SliceOperands slice_operands(const TriangleMesh& mesh, const LeafPiece& piece);
  /// The slab of a triangle: its plane, widened by rounding (a degenerate triangle gets the slab of
  /// its sphere along z).
  static Slab triangle_slab(const TriangleMesh& mesh, std::uint32_t t, const Sphere& sphere);
  /// The slab of a node along the mean normal of two children's bounds (sphere and slab each).
  static Slab merge_slabs(const Sphere& a, const Slab& sa, const Sphere& b, const Slab& sb);
  /// The pieces a triangle is covered by.
  static int slice_count(const TriangleMesh& mesh, std::uint32_t t, std::uint8_t& apex);
  /// The same for slabs of a given aspect (kSliceAspect above).
  static int slice_count(const TriangleMesh& mesh, std::uint32_t t, std::uint8_t& apex, double aspect);

 private:
  std::int32_t allocate_node();
  void free_node(std::int32_t node);
  /// A leaf waiting for its place in a build: its sphere, and its index among the records made.
  struct BuildLeaf {
    Sphere sphere;
    std::int32_t record = 0;
  };
  /// A step of the build: place the node of records [first, last) under `node` as its left or right
  /// child (the root: no parent), or finish `node` once its subtrees are built.
  struct BuildTask {
    enum Kind : std::int32_t { kLeftChild, kRightChild, kFinish };
    std::int32_t first = 0, last = 0;
    std::int32_t node = kNoNode;
    Kind kind = kLeftChild;
  };
  /// Makes the leaf records of build_triangles_ and sizes the node arrays; continue_build() builds.
  void start_build(const TriangleMesh& mesh);
  /// Numbers the task's node and links it; a leaf is done, an internal node is split and its
  /// subtrees and its finish become tasks.
  void start_node(const BuildTask& task, BuildLeaf* first, BuildLeaf* last);
  void finish_node(std::int32_t node, const BuildLeaf* first, const BuildLeaf* last);
  void cover_leaves(std::int32_t node, const Sphere& direct, const BuildLeaf* first, const BuildLeaf* last);
  void refit_node(std::int32_t node);
  void refit_leaf(const TriangleMesh& mesh, std::int32_t leaf);
  void refit_internal(const TriangleMesh& mesh, std::int32_t node);
  void set_child_leans(std::int32_t node);
  void refit_upward(std::int32_t node);
  void insert_leaf(std::int32_t leaf);
  void add_triangle_leaves(const TriangleMesh& mesh, std::uint32_t t, bool insert);
  void update_refit_order();
  void update_sphere_refit_blocks();
  /// Appends `nodes` (internal, none taller than `tallest`) to `out` by height, a counting sort;
  /// height_slots_[h] then ends height h's run in `out`.
  void append_by_height(std::span<const std::int32_t> nodes, std::int32_t tallest, std::vector<std::int32_t>& out);
  void refit_every_sphere(const TriangleMesh& mesh);
  /// The refit with slack: after a refit of every leaf, records the positions fitted and grows every
  /// sphere by the slack; between them, refit_moved_leaves() fits only the leaves of the corners that
  /// moved beyond it and the ancestors, and returns false (having done nothing the full refit must
  /// undo) when so many moved that a full refit is cheaper.
  void keep_fitted_positions(const TriangleMesh& mesh);
  bool refit_moved_leaves(const TriangleMesh& mesh);
  void update_vertex_slots(std::size_t vertex_count);
  void fit_moved_leaf(std::size_t slot);
  void merge_dirty_nodes();

  std::vector<Sphere> spheres_;         // hot: per node
  std::vector<SphereTreeLinks> links_;  // per node
  std::vector<Slab> slabs_;             // hot: per node
  std::vector<Lean> leans_;             // per node: its slab normal against its parent's
  std::vector<LeafPiece> pieces_;       // per node (leaves only)
  std::vector<std::int32_t> next_leaf_;   // per node: next leaf of the same triangle
  std::vector<std::int32_t> first_leaf_;  // per triangle
  // The refit's order with slabs (update_refit_order): every live leaf in node order, and the
  // internal nodes, children before parents.
  std::vector<std::int32_t> refit_leaves_;
  std::vector<std::int32_t> refit_internal_;
  // The spheres-only refit's order (update_sphere_refit_blocks): blocks of leaves, whole-triangle and
  // sliced, and of merge groups, each group of one height. A block begins where the one before ends.
  struct RefitBlock {
    std::size_t whole_end, sliced_end, groups_end;
  };
  std::vector<RefitBlock> refit_blocks_;
  std::vector<std::int32_t> whole_leaves_, sliced_leaves_, merge_order_;
  std::vector<std::size_t> merge_group_ends_;  // merge_order_'s end of each group
  // The same orders' operands in their order, so a refit follows no index chain: each whole leaf's
  // triangle corners and each sliced leaf's (taken from the mesh at the first refit after the order
  // changed), and each merge's children.
  std::vector<Triangle> whole_corners_;
  std::vector<SliceOperands> sliced_operands_;
  std::vector<ChildPair> merge_children_;
  bool corners_stale_ = true;
  std::vector<std::int32_t> block_top_, block_nodes_, block_walk_;  // scratch
  std::vector<std::size_t> height_slots_;                           // scratch
  std::vector<std::int32_t> stack_;        // scratch for update_refit_order and update_sphere_refit_blocks
  // The refit with slack (set_refit_slack): the positions the leaves were last fitted to, per mesh
  // vertex; each vertex's refit slots (an index into whole_leaves_, or whole_leaves_.size() plus one
  // into sliced_leaves_), from vertex_slot_begin_[v] to vertex_slot_begin_[v + 1]; the vertices with
  // any; a bit per slot and per node for the ones to fit again, read back in memory order; whether
  // every child is numbered after its parent (then the nodes backwards are children first).
  double refit_slack_ = 0.0;
  double applied_slack_ = 0.0;  // the slack the spheres now carry (0 after a build)
  bool fitted_ = false;         // fitted_positions_ hold every leaf's last fit
  bool vertex_slots_stale_ = true;
  bool preorder_ = false;
  std::vector<Vec3> fitted_positions_;
  std::vector<std::int32_t> vertex_slot_begin_, vertex_slots_, slack_vertices_;
  std::vector<std::uint64_t> moved_slot_bits_, dirty_node_bits_;
  std::vector<std::int32_t> dirty_nodes_, dirty_by_height_;
  std::int32_t last_refit_leaves_ = 0;
  std::int32_t root_ = kNoNode;
  std::int32_t free_list_ = kNoNode;
  std::int32_t leaf_count_ = 0;
  std::int32_t live_nodes_ = 0;
  // A build's scratch, kept so that a rebuild within reserve() allocates nothing: the triangles to
  // cover, the leaf records (partitioned in place) with each record's piece and slab, and the node
  // each record became.
  std::vector<std::uint32_t> build_triangles_;
  std::vector<BuildLeaf> build_leaves_;
  std::vector<LeafPiece> build_pieces_;
  std::vector<Slab> build_slabs_;
  std::vector<std::int32_t> build_leaf_nodes_;
  std::vector<BuildTask> build_tasks_;  // the build's stack, last out first
  std::int32_t next_build_node_ = 0;
  const TriangleMesh* build_mesh_ = nullptr;  // the mesh of the build under way, null when none is
  bool order_dirty_ = true;
  bool slabs_wanted_ = true;
  bool slabs_kept_ = false;
  std::uint64_t structure_version_ = 0;
  double slice_aspect_ = kSliceAspect;
  double built_mean_internal_radius_ = 0.0;
};

}  // namespace resecto

// What each face of the tissue's surface is, for its colour: the urethral lining and the capsule's
// outside of the uncut gland, or tissue the loop exposed (adenoma or capsule, by the region of the
// tetrahedron behind the face). Faces keep their look while they stay on the surface, and the pieces
// resection's refinement splits a face into keep that face's look, so the lining stays lining until
// it is cut. No GL here: the renderer turns looks into colours.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "rtcore/core/simulation.h"

namespace resecto::gui {

/// What a surface triangle is, for its colour.
enum class SurfaceLook : std::uint8_t {
  kMucosa,      ///< the urethral channel's lining (the original surface near the axis)
  kCapsuleOut,  ///< the gland's outer surface
  kAdenoma,     ///< cut hyperplastic tissue
  kCapsuleCut,  ///< cut capsule: resected too deep
};

/// Whether a look is the uncut gland's surface (lining or capsule outside) rather than a cut.
bool original_look(SurfaceLook look);

/// A surface face's nodes in ascending order, and the look it was given.
using FaceKey = std::array<std::uint32_t, 3>;
struct FaceLook {
  FaceKey key;
  SurfaceLook look;
};

class SurfaceLooks {
 public:
  /// Gives every face of `snapshot`'s surface its look; call it when the surface's connectivity
  /// changed, snapshots in time order (a replay's seek back is fine). The first call's surface is
  /// taken as the uncut gland: faces whose centroid is within `lining_radius_m` of the urethra's axis
  /// (world z) are lining, the others the capsule's outside. Every node the surface names must be
  /// below `snapshot.node_count`.
  void classify(const SimulationSnapshot& snapshot, double lining_radius_m);
  /// The look of each face of the last snapshot classified, in its order.
  const std::vector<SurfaceLook>& looks() const { return looks_; }

 private:
  /// Finds, for the new nodes on faces that just appeared, the edge refinement split to make them.
  void find_parents(const SimulationSnapshot& snapshot, const std::vector<std::uint32_t>& appeared);
  /// Whether `node` is a corner of `face` or made (within `depth` splits) from nodes on it.
  bool on_face(std::uint32_t node, const FaceKey& face, int depth) const;
  /// Whether `t` is a piece refinement split from the face `parent`.
  bool piece_of(const Triangle& t, const FaceKey& parent) const;

  std::vector<FaceLook> face_looks_;     ///< the surface's faces by key, with their looks
  std::vector<FaceLook> initial_looks_;  ///< the same for the first surface seen (the uncut gland)
  std::vector<SurfaceLook> looks_;       ///< per face of the last snapshot
  std::size_t initial_nodes_ = 0;        ///< nodes of the first snapshot: later ids are refinement's
  static constexpr std::array<std::uint32_t, 2> kNoParents{UINT32_MAX, UINT32_MAX};
  std::vector<std::array<std::uint32_t, 2>> node_parents_;  ///< per node: the edge split to make it
  std::vector<std::uint8_t> parents_checked_;               ///< per node: parents looked for
};

}  // namespace resecto::gui

// Draws the simulation's snapshot: the tissue's current surface (connectivity uploaded only when its
// topology version changes, normals recomputed from the deformed positions every frame), the sheath
// and loop at their poses, and the landmarks. Two looks: through the endoscope (lit from the tip,
// round image) and from outside (the gland translucent, the tool inside, landmark markers).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "console/gui/gl_resources.h"
#include "console/gui/view_cameras.h"
#include "rtcore/anatomy/prostate.h"
#include "rtcore/core/simulation.h"

namespace resecto::gui {

/// What the surface's triangles are, for their colour.
enum class SurfaceLook : std::uint8_t {
  kMucosa,      ///< the urethral channel's lining (the original surface near the axis)
  kCapsuleOut,  ///< the gland's outer surface
  kAdenoma,     ///< cut hyperplastic tissue
  kCapsuleCut,  ///< cut capsule: resected too deep
};

/// A surface face's nodes in ascending order, and the look it was given.
using FaceKey = std::array<std::uint32_t, 3>;
struct FaceLook {
  FaceKey key;
  SurfaceLook look;
};

/// Where a marker or label lands in an image: pixels from the top left, and whether it is in front.
struct ProjectedPoint {
  float x = 0.0f, y = 0.0f;
  bool visible = false;
};

class SceneRenderer {
 public:
  /// Compiles the shaders and uploads the tool and marker meshes.
  static Result<std::unique_ptr<SceneRenderer>> create(const ProstateModel& prostate);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  /// Takes a new snapshot's geometry: indices when its topology changed, positions and normals always.
  void update(const SimulationSnapshot& snapshot, bool cutting);
  /// Draws the endoscope's image into `target`.
  void draw_endoscope(RenderTarget& target, const CameraView& camera) const;
  /// Draws the outside view into `target`.
  void draw_outside(RenderTarget& target, const CameraView& camera) const;
  /// Where `world_m` appears in an image of `width` x `height` pixels.
  static ProjectedPoint project(const CameraView& camera, const Vec3& world_m, float width, float height);

  const std::vector<Landmark>& landmarks() const { return landmarks_; }
  std::uint64_t topology_uploads() const { return topology_uploads_; }

 private:
  SceneRenderer() = default;
  void draw_tool(bool endoscope) const;
  void classify_faces(const SimulationSnapshot& snapshot);
  /// Finds, for the new nodes on faces that just appeared, the edge refinement split to make them.
  void find_parents(const SimulationSnapshot& snapshot, const std::vector<std::uint32_t>& appeared);
  /// Whether `node` is a corner of `face` or made (within `depth` splits) from nodes on it.
  bool on_face(std::uint32_t node, const FaceKey& face, int depth) const;
  /// Whether `t` is a piece refinement split from the face `parent`.
  bool piece_of(const Triangle& t, const FaceKey& parent) const;

  ShaderProgram shader_;
  std::unique_ptr<MeshBuffers> tissue_, sheath_, loop_, marker_;
  GLuint noise_volume_ = 0;
  std::size_t sheath_wall_indices_ = 0;  ///< the sheath's side walls come first; the caps after
  std::vector<Landmark> landmarks_;
  ProstateShape shape_;

  // The tissue's surface as last uploaded.
  std::uint64_t topology_version_ = UINT64_MAX;
  std::uint32_t triangle_count_ = 0;
  std::uint64_t topology_uploads_ = 0;
  std::vector<FaceLook> face_looks_;     ///< the surface's faces by key, with their looks
  std::vector<FaceLook> initial_looks_;  ///< the same for the first surface seen (the uncut gland)
  std::vector<SurfaceLook> looks_;       ///< per face of the last snapshot
  std::size_t initial_nodes_ = 0;        ///< nodes of the first snapshot: later ids are refinement's
  static constexpr std::array<std::uint32_t, 2> kNoParents{UINT32_MAX, UINT32_MAX};
  std::vector<std::array<std::uint32_t, 2>> node_parents_;  ///< per node: the edge split to make it
  std::vector<std::uint8_t> parents_checked_;               ///< per node: parents looked for
  std::vector<Vec3> rest_;  ///< node positions in the first snapshot, where surface detail is painted
  std::vector<glm::vec3> node_color_;
  std::vector<float> node_lining_;  ///< 1 where all the node's faces are original surface, 0 where all are cut
  std::vector<glm::vec3> node_normal_;
  std::vector<MeshVertex> vertices_;
  std::vector<std::uint32_t> indices_;
  glm::mat4 sheath_model_{1.0f}, loop_model_{1.0f};
  bool cutting_ = false;
};

/// The model matrix of a rigid pose (single precision, for drawing only).
glm::mat4 model_matrix(const RigidPose& pose);

}  // namespace resecto::gui

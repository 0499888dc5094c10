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
#include "console/gui/surface_looks.h"
#include "console/gui/view_cameras.h"
#include "rtcore/anatomy/prostate.h"
#include "rtcore/core/simulation.h"

namespace resecto::gui {

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
  SurfaceLooks looks_;
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

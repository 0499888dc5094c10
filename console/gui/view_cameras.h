// The console's two cameras. The endoscope's lens sits in the sheath's tip and looks 30 degrees off
// the sheath's axis toward the loop, so it turns with the sheath: rolling the sheath rolls the image.
// The outside view orbits the gland under the mouse. Pure maths (no OpenGL), so tests check it.
#pragma once

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "rtcore/geometry/rigid_pose.h"

namespace resecto::gui {

/// The lens, in the tool frame (rtcore/anatomy/resectoscope.h: axis +z, loop below the axis, -y).
struct EndoscopeLens {
  double tilt_deg = 30.0;             ///< off the sheath axis, toward the loop
  double field_of_view_deg = 80.0;    ///< across the round image
  double lens_y_m = 0.0022;           ///< above the axis: the loop's working channel runs below it
  double lens_z_m = -0.0035;          ///< recessed in the sheath, so its open end shows at the image's edge
  double near_m = 0.0003;
  double far_m = 0.15;
};

/// A camera as the renderer needs it.
struct CameraView {
  glm::mat4 view{1.0f};
  glm::mat4 projection{1.0f};
  glm::vec3 eye{0.0f};
  glm::vec3 forward{0.0f, 0.0f, 1.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
};

/// The endoscope's camera for the sheath's pose; `aspect` is width / height of the image.
CameraView endoscope_camera(const RigidPose& sheath, const EndoscopeLens& lens, float aspect);

/// A camera circling a target: yaw about the world's z axis (the urethra), pitch above it, distance.
struct OrbitCamera {
  glm::vec3 target{0.0f, -0.004f, 0.0207f};  ///< the gland's middle
  float yaw_deg = -60.0f;
  float pitch_deg = 25.0f;
  float distance_m = 0.11f;
  float field_of_view_deg = 40.0f;

  /// Mouse drag in pixels: horizontal turns, vertical tilts (clamped short of the poles).
  void drag(float dx_pixels, float dy_pixels);
  /// Mouse wheel clicks: positive moves in.
  void zoom(float clicks);
  CameraView view(float aspect) const;
};

}  // namespace resecto::gui

// Endoscope and orbit cameras.
#include "console/gui/view_cameras.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace resecto::gui {

CameraView endoscope_camera(const RigidPose& sheath, const EndoscopeLens& lens, float aspect) {
  const double tilt = lens.tilt_deg * std::acos(-1.0) / 180.0;
  // In the tool frame the axis is +z and the loop hangs toward -y: tilt the view toward -y, and keep
  // the tool's +y as the image's up, so the loop appears at the bottom as surgeons expect.
  const Vec3 forward_tool(0.0, -std::sin(tilt), std::cos(tilt));
  const Vec3 up_tool(0.0, std::cos(tilt), std::sin(tilt));
  const Vec3 eye = sheath.apply_point(Vec3(0.0, lens.lens_y_m, lens.lens_z_m));
  const Vec3 forward = sheath.apply_vector(forward_tool);
  const Vec3 up = sheath.apply_vector(up_tool);
  CameraView camera;
  camera.eye = glm::vec3(eye);
  camera.forward = glm::vec3(forward);
  camera.up = glm::vec3(up);
  camera.view = glm::lookAt(camera.eye, camera.eye + camera.forward, camera.up);
  // The field of view spans the round image, which fits the narrower side of the view.
  const double half = 0.5 * lens.field_of_view_deg * std::acos(-1.0) / 180.0;
  const double fovy = 2.0 * std::atan(std::tan(half) / std::min(1.0, static_cast<double>(aspect)));
  camera.projection = glm::perspective(static_cast<float>(fovy), aspect, static_cast<float>(lens.near_m), static_cast<float>(lens.far_m));
  return camera;
}

void OrbitCamera::drag(float dx_pixels, float dy_pixels) {
  yaw_deg -= 0.4f * dx_pixels;
  pitch_deg = std::clamp(pitch_deg + 0.4f * dy_pixels, -85.0f, 85.0f);
}

void OrbitCamera::zoom(float clicks) { distance_m = std::clamp(distance_m * std::pow(0.9f, clicks), 0.03f, 0.6f); }

CameraView OrbitCamera::view(float aspect) const {
  // The urethra (world z) runs left to right across the screen; y (anterior) is up at zero pitch.
  const float yaw = glm::radians(yaw_deg);
  const float pitch = glm::radians(pitch_deg);
  const glm::vec3 offset(std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw));
  CameraView camera;
  camera.eye = target + distance_m * glm::vec3(offset.x, offset.y, offset.z);
  camera.forward = glm::normalize(target - camera.eye);
  camera.up = glm::vec3(0.0f, 1.0f, 0.0f);
  camera.view = glm::lookAt(camera.eye, target, camera.up);
  camera.projection = glm::perspective(glm::radians(field_of_view_deg), aspect, 0.002f, 2.0f);
  return camera;
}

}  // namespace resecto::gui

// glReadPixels to PNG.
#include "console/gui/screenshot.h"

#include <stb_image_write.h>

#include <cstdint>
#include <system_error>
#include <vector>

#include "console/gui/gl_api.h"

namespace resecto::gui {

Status save_framebuffer_png(const std::filesystem::path& path, int width, int height) {
  if (width <= 0 || height <= 0) return Error{path.string() + ": the window has no pixels to save"};
  std::vector<std::uint8_t> pixels(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data());
  for (std::size_t i = 3; i < pixels.size(); i += 4) pixels[i] = 255;  // the window is opaque
  const std::filesystem::path temporary = path.string() + ".tmp";
  stbi_flip_vertically_on_write(1);  // OpenGL's rows run bottom-up, PNG's top-down
  const int written = stbi_write_png(temporary.string().c_str(), width, height, 4, pixels.data(), width * 4);
  if (!written) return Error{path.string() + ": cannot write the screenshot"};
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) return Error{path.string() + ": cannot move the screenshot into place: " + error.message()};
  return Ok{};
}

}  // namespace resecto::gui

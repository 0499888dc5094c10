// glReadPixels to PNG.
#include "console/gui/screenshot.h"

#include <stb_image_write.h>

#include <cstdint>
#include <string>
#include <vector>

#include "console/gui/gl_api.h"
#include "rtcore/base/atomic_file.h"

namespace resecto::gui {

Status save_framebuffer_png(const std::filesystem::path& path, int width, int height) {
  if (width <= 0 || height <= 0) return Error{path.string() + ": the window has no pixels to save"};
  std::vector<std::uint8_t> pixels(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data());
  for (std::size_t i = 3; i < pixels.size(); i += 4) pixels[i] = 255;  // the window is opaque
  // Encoded in memory, then written by the one writer every output uses (rtcore/base/atomic_file.h):
  // only a regular file is ever replaced, and every write, the fsync and the close are checked.
  std::string png;
  stbi_flip_vertically_on_write(1);  // OpenGL's rows run bottom-up, PNG's top-down
  const auto append = [](void* context, void* data, int size) { static_cast<std::string*>(context)->append(static_cast<const char*>(data), static_cast<std::size_t>(size)); };
  if (!stbi_write_png_to_func(append, &png, width, height, 4, pixels.data(), width * 4)) return Error{path.string() + ": cannot encode the screenshot"};
  return write_file_atomically(path, png);
}

}  // namespace resecto::gui

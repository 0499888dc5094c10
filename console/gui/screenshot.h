// Saving the console's window as a PNG: the framebuffer read with glReadPixels after a frame is
// drawn, encoded with stb_image_write (Debian's libstb, already linked by Dear ImGui) and written
// through rtcore/base/atomic_file.h, so a reader never sees half a PNG and no device is replaced.
#pragma once

#include <filesystem>

#include "rtcore/base/result.h"

namespace resecto::gui {

/// Reads the current framebuffer's `width` x `height` pixels (the back buffer, before the swap).
Status save_framebuffer_png(const std::filesystem::path& path, int width, int height);

}  // namespace resecto::gui

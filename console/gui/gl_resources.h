// Small owners of OpenGL objects: a shader program, an offscreen render target (the endoscopic and
// outside views draw into these and ImGui shows their textures) and a mesh's vertex arrays.
#pragma once

#include <cstdint>
#include <string>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "console/gui/gl_api.h"
#include "rtcore/base/result.h"

namespace resecto::gui {

/// A linked vertex + fragment program.
class ShaderProgram {
 public:
  ShaderProgram() = default;
  ~ShaderProgram();
  ShaderProgram(const ShaderProgram&) = delete;
  ShaderProgram& operator=(const ShaderProgram&) = delete;

  /// Compiles and links; the error carries the driver's log and which stage failed.
  Status build(const char* name, const char* vertex_source, const char* fragment_source);
  void use() const { glUseProgram(program_); }
  void set(const char* uniform, const glm::mat4& value) const;
  void set(const char* uniform, const glm::vec2& value) const;
  void set(const char* uniform, const glm::vec3& value) const;
  void set(const char* uniform, const glm::vec4& value) const;
  void set(const char* uniform, float value) const;
  void set(const char* uniform, int value) const;

 private:
  GLuint program_ = 0;
};

/// A colour texture with a depth buffer, multisampled for smooth edges and resolved into the texture
/// ImGui shows. Resized when the panel that shows it changes size.
class RenderTarget {
 public:
  RenderTarget() = default;
  ~RenderTarget();
  RenderTarget(const RenderTarget&) = delete;
  RenderTarget& operator=(const RenderTarget&) = delete;

  /// (Re)allocates for `width` x `height` pixels when the size changed.
  void resize(int width, int height, int samples);
  /// Binds the multisampled framebuffer and sets the viewport to the whole target.
  void begin() const;
  /// Resolves into the texture and rebinds the window's framebuffer.
  void end() const;
  GLuint texture() const { return texture_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  void release();
  int width_ = 0, height_ = 0, samples_ = 0;
  GLuint msaa_fbo_ = 0, msaa_color_ = 0, msaa_depth_ = 0;
  GLuint resolve_fbo_ = 0, texture_ = 0;
};

/// Interleaved float vertices and 32-bit indices. `rest` is where the vertex was before any
/// deformation: surface detail is painted there, so it stays on the tissue as it moves.
struct MeshVertex {
  float position[3];
  float normal[3];
  float color[3];
  float rest[3];
  float lining;  ///< 1 on the original lining and capsule, 0 on cut faces: how much mucosal detail to paint
};

class MeshBuffers {
 public:
  MeshBuffers();
  ~MeshBuffers();
  MeshBuffers(const MeshBuffers&) = delete;
  MeshBuffers& operator=(const MeshBuffers&) = delete;

  /// Replaces every vertex (GL_STREAM_DRAW: the tissue's change every frame).
  void upload_vertices(const MeshVertex* vertices, std::size_t count);
  /// Replaces the index list (only when the topology changed).
  void upload_indices(const std::uint32_t* indices, std::size_t count);
  /// Draws `count` indices from `first` (defaults: all).
  void draw(std::size_t first = 0, std::size_t count = SIZE_MAX) const;
  std::size_t index_count() const { return index_count_; }

 private:
  GLuint vao_ = 0, vbo_ = 0, ebo_ = 0;
  std::size_t vertex_capacity_ = 0, index_capacity_ = 0, index_count_ = 0;
};

}  // namespace resecto::gui

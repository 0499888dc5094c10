// OpenGL object owners for the console's views.
#include "console/gui/gl_resources.h"

#include <algorithm>
#include <cstddef>
#include <vector>

#include <glm/gtc/type_ptr.hpp>

namespace resecto::gui {
namespace {

Result<GLuint> compile(GLenum stage, const char* source, const char* name) {
  const GLuint shader = glCreateShader(stage);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok == GL_TRUE) return shader;
  GLint length = 0;
  glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
  std::vector<char> log(static_cast<std::size_t>(std::max(length, 1)));
  glGetShaderInfoLog(shader, length, nullptr, log.data());
  glDeleteShader(shader);
  return Error{std::string("shader '") + name + "' (" + (stage == GL_VERTEX_SHADER ? "vertex" : "fragment") +
               " stage) does not compile: " + log.data()};
}

}  // namespace

ShaderProgram::~ShaderProgram() {
  if (program_) glDeleteProgram(program_);
}

Status ShaderProgram::build(const char* name, const char* vertex_source, const char* fragment_source) {
  Result<GLuint> vertex = compile(GL_VERTEX_SHADER, vertex_source, name);
  if (!vertex) return Error{vertex.error()};
  Result<GLuint> fragment = compile(GL_FRAGMENT_SHADER, fragment_source, name);
  if (!fragment) {
    glDeleteShader(*vertex);
    return Error{fragment.error()};
  }
  program_ = glCreateProgram();
  glAttachShader(program_, *vertex);
  glAttachShader(program_, *fragment);
  glBindAttribLocation(program_, 0, "in_position");
  glBindAttribLocation(program_, 1, "in_normal");
  glBindAttribLocation(program_, 2, "in_color");
  glBindAttribLocation(program_, 3, "in_rest");
  glBindAttribLocation(program_, 4, "in_lining");
  glLinkProgram(program_);
  glDeleteShader(*vertex);
  glDeleteShader(*fragment);
  GLint ok = GL_FALSE;
  glGetProgramiv(program_, GL_LINK_STATUS, &ok);
  if (ok == GL_TRUE) return Ok{};
  char log[2048] = {};
  glGetProgramInfoLog(program_, sizeof log, nullptr, log);
  return Error{std::string("shader '") + name + "' does not link: " + log};
}

void ShaderProgram::set(const char* uniform, const glm::mat4& value) const {
  glUniformMatrix4fv(glGetUniformLocation(program_, uniform), 1, GL_FALSE, glm::value_ptr(value));
}
void ShaderProgram::set(const char* uniform, const glm::vec2& value) const {
  glUniform2fv(glGetUniformLocation(program_, uniform), 1, glm::value_ptr(value));
}
void ShaderProgram::set(const char* uniform, const glm::vec3& value) const {
  glUniform3fv(glGetUniformLocation(program_, uniform), 1, glm::value_ptr(value));
}
void ShaderProgram::set(const char* uniform, const glm::vec4& value) const {
  glUniform4fv(glGetUniformLocation(program_, uniform), 1, glm::value_ptr(value));
}
void ShaderProgram::set(const char* uniform, float value) const { glUniform1f(glGetUniformLocation(program_, uniform), value); }
void ShaderProgram::set(const char* uniform, int value) const { glUniform1i(glGetUniformLocation(program_, uniform), value); }

RenderTarget::~RenderTarget() { release(); }

void RenderTarget::release() {
  if (msaa_fbo_) glDeleteFramebuffers(1, &msaa_fbo_);
  if (resolve_fbo_) glDeleteFramebuffers(1, &resolve_fbo_);
  if (msaa_color_) glDeleteRenderbuffers(1, &msaa_color_);
  if (msaa_depth_) glDeleteRenderbuffers(1, &msaa_depth_);
  if (texture_) glDeleteTextures(1, &texture_);
  msaa_fbo_ = resolve_fbo_ = msaa_color_ = msaa_depth_ = texture_ = 0;
}

void RenderTarget::resize(int width, int height, int samples) {
  width = std::max(width, 16);
  height = std::max(height, 16);
  if (width == width_ && height == height_ && samples == samples_ && texture_) return;
  release();
  width_ = width;
  height_ = height;
  samples_ = samples;
  glGenRenderbuffers(1, &msaa_color_);
  glBindRenderbuffer(GL_RENDERBUFFER, msaa_color_);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, width, height);
  glGenRenderbuffers(1, &msaa_depth_);
  glBindRenderbuffer(GL_RENDERBUFFER, msaa_depth_);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, width, height);
  glGenFramebuffers(1, &msaa_fbo_);
  glBindFramebuffer(GL_FRAMEBUFFER, msaa_fbo_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, msaa_color_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, msaa_depth_);

  glGenTextures(1, &texture_);
  glBindTexture(GL_TEXTURE_2D, texture_);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glGenFramebuffers(1, &resolve_fbo_);
  glBindFramebuffer(GL_FRAMEBUFFER, resolve_fbo_);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture_, 0);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void RenderTarget::begin() const {
  glBindFramebuffer(GL_FRAMEBUFFER, msaa_fbo_);
  glViewport(0, 0, width_, height_);
}

void RenderTarget::end() const {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, msaa_fbo_);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo_);
  glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

MeshBuffers::MeshBuffers() {
  glGenVertexArrays(1, &vao_);
  glGenBuffers(1, &vbo_);
  glGenBuffers(1, &ebo_);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ebo_);
  const auto stride = static_cast<GLsizei>(sizeof(MeshVertex));
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(offsetof(MeshVertex, position)));
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(offsetof(MeshVertex, normal)));
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(offsetof(MeshVertex, color)));
  glEnableVertexAttribArray(3);
  glVertexAttribPointer(3, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(offsetof(MeshVertex, rest)));
  glEnableVertexAttribArray(4);
  glVertexAttribPointer(4, 1, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(offsetof(MeshVertex, lining)));
  glBindVertexArray(0);
}

MeshBuffers::~MeshBuffers() {
  glDeleteBuffers(1, &ebo_);
  glDeleteBuffers(1, &vbo_);
  glDeleteVertexArrays(1, &vao_);
}

void MeshBuffers::upload_vertices(const MeshVertex* vertices, std::size_t count) {
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  const auto bytes = static_cast<GLsizeiptr>(count * sizeof(MeshVertex));
  if (count > vertex_capacity_) {
    glBufferData(GL_ARRAY_BUFFER, bytes, vertices, GL_STREAM_DRAW);
    vertex_capacity_ = count;
  } else {
    glBufferSubData(GL_ARRAY_BUFFER, 0, bytes, vertices);
  }
}

void MeshBuffers::upload_indices(const std::uint32_t* indices, std::size_t count) {
  glBindVertexArray(vao_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ebo_);
  const auto bytes = static_cast<GLsizeiptr>(count * sizeof(std::uint32_t));
  if (count > index_capacity_) {
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, bytes, indices, GL_DYNAMIC_DRAW);
    index_capacity_ = count;
  } else {
    glBufferSubData(GL_ELEMENT_ARRAY_BUFFER, 0, bytes, indices);
  }
  glBindVertexArray(0);
  index_count_ = count;
}

void MeshBuffers::draw(std::size_t first, std::size_t count) const {
  if (first >= index_count_) return;
  count = std::min(count, index_count_ - first);
  glBindVertexArray(vao_);
  glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(count), GL_UNSIGNED_INT,
                 reinterpret_cast<void*>(first * sizeof(std::uint32_t)));
  glBindVertexArray(0);
}

}  // namespace resecto::gui

// The console's 3-D drawing: one lit shader for tissue, tool and markers, two looks.
#include "console/gui/scene_renderer.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "rtcore/anatomy/resectoscope.h"

namespace resecto::gui {
namespace {

const char* kVertexShader = R"(#version 330 core
in vec3 in_position;
in vec3 in_normal;
in vec3 in_color;
in vec3 in_rest;
in float in_lining;
uniform mat4 model;
uniform mat4 view_projection;
out vec3 world_position;
out vec3 world_normal;
out vec3 base_color;
out vec3 rest_mm;
out float lining;
void main() {
  rest_mm = in_rest * 1000.0;
  lining = in_lining;
  vec4 world = model * vec4(in_position, 1.0);
  world_position = world.xyz;
  world_normal = mat3(model) * in_normal;
  base_color = in_color;
  gl_Position = view_projection * world;
}
)";

// Tissue surfaces carry procedural detail painted at their rest position (so it moves with the
// tissue): the lining a mottled colour and a net of fine vessels, as it looks through the lens; cut
// faces no vessels but a granular speckle, and the capsule (the whitest base colour) fine fibres that
// run around the urethra (across its axis, world z), the cue that the loop has gone too deep.
// A point light at `light_position` (the endoscope's tip, or the outside view's eye) with an
// inverse-square fall-off beyond `falloff_m`, a wet specular highlight, and for the endoscope a
// round image with a soft black edge, as a rod-lens telescope shows it.
const char* kFragmentShader = R"(#version 330 core
in vec3 world_position;
in vec3 world_normal;
in vec3 base_color;
in vec3 rest_mm;
in float lining;
uniform int mucosa_detail;
uniform sampler3D noise_volume;
uniform vec3 eye;
uniform vec3 light_position;
uniform float falloff_m;
uniform float ambient;
uniform float specular;
uniform float alpha;
uniform vec4 color_override;
uniform vec3 emissive;
uniform int round_image;
uniform vec2 viewport;
out vec4 out_color;
float value_noise(vec3 p) { return texture(noise_volume, p * (1.0 / 32.0)).r; }
vec3 mucosa(vec3 color, vec3 p) {
  float mottle = 0.5 * value_noise(p * 0.8) + 0.3 * value_noise(p * 2.1) + 0.2 * value_noise(p * 5.3);
  color *= 0.78 + 0.45 * mottle;
  float vessel = 1.0 - smoothstep(0.0, 0.035, abs(value_noise(p * 0.9) - 0.5));
  float fine = 1.0 - smoothstep(0.0, 0.03, abs(value_noise(p * 2.7 + 17.0) - 0.5));
  return mix(color, vec3(0.50, 0.06, 0.07), 0.65 * vessel + 0.35 * fine);
}
vec3 cut_surface(vec3 color, vec3 p) {
  color *= 0.86 + 0.28 * value_noise(p * 3.1);
  float capsule = smoothstep(0.70, 0.80, color.b / max(color.r, 1e-3));
  float fibre = value_noise(vec3(p.x * 0.35, p.y * 0.35, p.z * 4.5));
  return color * (1.0 - capsule * 0.22 * smoothstep(0.45, 0.7, fibre));
}
void main() {
  if (round_image == 1) {
    float r = length(gl_FragCoord.xy - 0.5 * viewport) / (0.5 * min(viewport.x, viewport.y));
    if (r > 1.0) discard;
  }
  vec3 color = color_override.a > 0.0 ? color_override.rgb : base_color;
  if (mucosa_detail == 1) color = mix(cut_surface(color, rest_mm), mucosa(color, rest_mm), lining);
  vec3 n = normalize(world_normal);
  if (!gl_FrontFacing) n = -n;
  vec3 to_light = light_position - world_position;
  float d = length(to_light);
  vec3 l = to_light / max(d, 1e-6);
  vec3 v = normalize(eye - world_position);
  float diffuse = max(dot(n, l), 0.0);
  float highlight = pow(max(dot(n, normalize(l + v)), 0.0), 60.0) * specular;
  float attenuation = falloff_m > 0.0 ? 1.0 / (1.0 + (d / falloff_m) * (d / falloff_m)) : 1.0;
  vec3 lit = color * (ambient + diffuse * attenuation) + vec3(highlight * attenuation) + emissive;
  if (round_image == 1) {
    float r = length(gl_FragCoord.xy - 0.5 * viewport) / (0.5 * min(viewport.x, viewport.y));
    lit *= 1.0 - smoothstep(0.9, 1.0, r);
  }
  out_color = vec4(pow(clamp(lit, 0.0, 1.0), vec3(1.0 / 1.6)), alpha);
}
)";

glm::vec3 look_color(SurfaceLook look) {
  switch (look) {
    case SurfaceLook::kMucosa: return {0.80f, 0.36f, 0.30f};      // pink-red urethral lining
    case SurfaceLook::kCapsuleOut: return {0.78f, 0.55f, 0.48f};  // the gland from outside
    // Cut tissue, told apart by hue as well as by texture: the adenoma a pale salmon-tan (yellower than
    // the lining, whose green and blue are nearly equal, and pinker than the capsule), the capsule's
    // fibres cream-white (green a little below red, unlike the loop's and sheath's neutral metal).
    case SurfaceLook::kAdenoma: return {0.92f, 0.66f, 0.52f};
    case SurfaceLook::kCapsuleCut: return {0.94f, 0.90f, 0.78f};
  }
  return {1.0f, 0.0f, 1.0f};
}

/// A tileable 32^3 lattice of hashed values, filtered by the texture unit: the mucosa's noise for a
/// few texture reads per pixel instead of dozens of hashes (software rasterisers feel the difference).
GLuint make_noise_volume() {
  constexpr int n = 32;
  std::vector<std::uint8_t> values(static_cast<std::size_t>(n) * n * n);
  std::uint32_t state = 0x9e3779b9u;  // fixed: the same tissue every session
  for (std::uint8_t& v : values) {
    state ^= state << 13;
    state ^= state >> 17;
    state ^= state << 5;
    v = static_cast<std::uint8_t>(state >> 24);
  }
  GLuint texture = 0;
  glGenTextures(1, &texture);
  glBindTexture(GL_TEXTURE_3D, texture);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage3D(GL_TEXTURE_3D, 0, GL_R8, n, n, n, 0, GL_RED, GL_UNSIGNED_BYTE, values.data());
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  for (GLenum wrap : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R}) glTexParameteri(GL_TEXTURE_3D, wrap, GL_REPEAT);
  glBindTexture(GL_TEXTURE_3D, 0);
  return texture;
}

std::unique_ptr<MeshBuffers> upload_mesh(const TriangleMesh& mesh, glm::vec3 color) {
  // Flat normals: the tool's facets should read as machined metal.
  std::vector<MeshVertex> vertices;
  std::vector<std::uint32_t> indices;
  for (const Triangle& t : mesh.triangles) {
    const Vec3 a = mesh.positions[t[0]], b = mesh.positions[t[1]], c = mesh.positions[t[2]];
    const Vec3 n = glm::normalize(glm::cross(b - a, c - a));
    for (int k = 0; k < 3; ++k) {
      const Vec3& p = mesh.positions[t[k]];
      indices.push_back(static_cast<std::uint32_t>(vertices.size()));
      vertices.push_back({{float(p.x), float(p.y), float(p.z)}, {float(n.x), float(n.y), float(n.z)}, {color.r, color.g, color.b},
                          {float(p.x), float(p.y), float(p.z)}, 0.0f});
    }
  }
  auto buffers = std::make_unique<MeshBuffers>();
  buffers->upload_vertices(vertices.data(), vertices.size());
  buffers->upload_indices(indices.data(), indices.size());
  return buffers;
}

TriangleMesh octahedron() {
  TriangleMesh mesh;
  mesh.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  mesh.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  return mesh;
}

glm::vec3 landmark_color(const std::string& name) {
  if (name == "verumontanum") return {1.0f, 0.85f, 0.1f};
  if (name == "bladder_neck") return {0.2f, 0.8f, 1.0f};
  return {1.0f, 0.3f, 0.9f};  // external sphincter: the line never to cross
}

}  // namespace

SceneRenderer::~SceneRenderer() {
  if (noise_volume_) glDeleteTextures(1, &noise_volume_);
}

glm::mat4 model_matrix(const RigidPose& pose) {
  glm::mat4 m(1.0f);
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) m[c][r] = static_cast<float>(pose.rotation[c][r]);
  m[3] = glm::vec4(glm::vec3(pose.translation), 1.0f);
  return m;
}

Result<std::unique_ptr<SceneRenderer>> SceneRenderer::create(const ProstateModel& prostate) {
  std::unique_ptr<SceneRenderer> r(new SceneRenderer());
  if (Status built = r->shader_.build("surface", kVertexShader, kFragmentShader); !built) return Error{built.error()};
  const ResectoscopeModel tool = generate_resectoscope();
  r->sheath_ = upload_mesh(tool.sheath, {0.62f, 0.64f, 0.66f});
  // The side walls are the first 2 * 20 * 3 triangles (resectoscope.cpp); the tip cap follows.
  r->sheath_wall_indices_ = 3u * 120u;
  r->loop_ = upload_mesh(tool.loop, {0.85f, 0.85f, 0.80f});
  r->marker_ = upload_mesh(octahedron(), {1.0f, 1.0f, 1.0f});
  r->tissue_ = std::make_unique<MeshBuffers>();
  r->noise_volume_ = make_noise_volume();
  r->landmarks_ = prostate.landmarks;
  r->shape_ = prostate.shape;
  return r;
}

void SceneRenderer::classify_faces(const SimulationSnapshot& s) {
  const std::size_t nodes = s.node_count;
  if (nodes > rest_.size()) {
    // Nodes refinement creates later have their detail painted where they first appear.
    rest_.insert(rest_.end(), s.node_positions.begin() + static_cast<std::ptrdiff_t>(rest_.size()),
                 s.node_positions.begin() + static_cast<std::ptrdiff_t>(nodes));
  }
  looks_.classify(s, 1.6 * shape_.channel_radius_m);
  const std::vector<SurfaceLook>& looks = looks_.looks();
  std::vector<glm::vec3> sum(nodes, glm::vec3(0.0f));
  std::vector<float> lining(nodes, 0.0f), weight(nodes, 0.0f);
  indices_.resize(3u * s.surface_triangle_count);
  for (std::uint32_t f = 0; f < s.surface_triangle_count; ++f) {
    const Triangle& t = s.surface_triangles[f];
    const glm::vec3 color = look_color(looks[f]);
    for (int c = 0; c < 3; ++c) {
      sum[t[c]] += color;
      lining[t[c]] += original_look(looks[f]) ? 1.0f : 0.0f;
      weight[t[c]] += 1.0f;
      indices_[3u * f + static_cast<unsigned>(c)] = t[c];
    }
  }
  node_color_.assign(nodes, glm::vec3(0.5f));
  node_lining_.assign(nodes, 0.0f);
  for (std::size_t n = 0; n < nodes; ++n) {
    if (weight[n] > 0.0f) {
      node_color_[n] = sum[n] / weight[n];
      node_lining_[n] = lining[n] / weight[n];
    }
  }
  tissue_->upload_indices(indices_.data(), indices_.size());
  ++topology_uploads_;
}

void SceneRenderer::update(const SimulationSnapshot& s, bool cutting) {
  if (s.topology_version != topology_version_ || s.surface_triangle_count != triangle_count_ || s.node_count > rest_.size()) {
    // A surface naming a node the snapshot has no position for is not drawn (the last one stays):
    // every per-node array here is indexed by those ids.
    for (std::uint32_t f = 0; f < s.surface_triangle_count; ++f)
      for (std::uint32_t id : s.surface_triangles[f])
        if (id >= s.node_count) return;
    classify_faces(s);
    topology_version_ = s.topology_version;
    triangle_count_ = s.surface_triangle_count;
  }
  const std::size_t nodes = s.node_count;
  node_normal_.assign(nodes, glm::vec3(0.0f));
  // Area-weighted vertex normals of the deformed surface (the cross product's length is twice the area).
  for (std::uint32_t f = 0; f < s.surface_triangle_count; ++f) {
    const Triangle& t = s.surface_triangles[f];
    const glm::vec3 a(s.node_positions[t[0]]), b(s.node_positions[t[1]]), c(s.node_positions[t[2]]);
    const glm::vec3 n = glm::cross(b - a, c - a);
    for (int k = 0; k < 3; ++k) node_normal_[t[k]] += n;
  }
  vertices_.resize(nodes);
  for (std::size_t i = 0; i < nodes; ++i) {
    const glm::vec3 p(s.node_positions[i]);
    const float len = glm::length(node_normal_[i]);
    const glm::vec3 n = len > 0.0f ? node_normal_[i] / len : glm::vec3(0.0f, 0.0f, 1.0f);
    const glm::vec3 c = i < node_color_.size() ? node_color_[i] : glm::vec3(0.5f);
    const glm::vec3 r = i < rest_.size() ? glm::vec3(rest_[i]) : p;
    const float lined = i < node_lining_.size() ? node_lining_[i] : 0.0f;
    vertices_[i] = {{p.x, p.y, p.z}, {n.x, n.y, n.z}, {c.r, c.g, c.b}, {r.x, r.y, r.z}, lined};
  }
  tissue_->upload_vertices(vertices_.data(), vertices_.size());
  sheath_model_ = model_matrix(s.tool.sheath);
  loop_model_ = model_matrix(s.tool.loop);
  cutting_ = cutting;
}

void SceneRenderer::draw_tool(bool endoscope) const {
  shader_.set("mucosa_detail", 0);
  shader_.set("specular", 0.9f);
  shader_.set("model", sheath_model_);
  // Through the lens only the sheath's open end shows (the lens sits inside it): its walls from
  // inside, no caps, drawn over whatever lies behind them: from inside the tube its wall is nearer
  // than anything outside, and tissue the contact lets a millimetre into the sheath must not hide it.
  if (endoscope) glDepthFunc(GL_ALWAYS);
  sheath_->draw(0, endoscope ? sheath_wall_indices_ : SIZE_MAX);
  glDepthFunc(GL_LESS);
  shader_.set("model", loop_model_);
  // The loop glows while the cutting current flows.
  shader_.set("emissive", cutting_ ? glm::vec3(0.9f, 0.45f, 0.1f) : glm::vec3(0.0f));
  loop_->draw();
  shader_.set("emissive", glm::vec3(0.0f));
}

void SceneRenderer::draw_endoscope(RenderTarget& target, const CameraView& camera) const {
  target.begin();
  glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);  // the lens can be inside the lumen or the sheath: draw both sides
  shader_.use();
  shader_.set("view_projection", camera.projection * camera.view);
  shader_.set("eye", camera.eye);
  shader_.set("light_position", camera.eye);
  shader_.set("falloff_m", 0.012f);
  shader_.set("ambient", 0.04f);
  shader_.set("alpha", 1.0f);
  shader_.set("color_override", glm::vec4(0.0f));
  shader_.set("emissive", glm::vec3(0.0f));
  shader_.set("round_image", 1);
  shader_.set("viewport", glm::vec2(static_cast<float>(target.width()), static_cast<float>(target.height())));
  shader_.set("specular", 0.35f);
  shader_.set("model", glm::mat4(1.0f));
  shader_.set("mucosa_detail", 1);
  shader_.set("noise_volume", 0);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_3D, noise_volume_);
  tissue_->draw();
  glBindTexture(GL_TEXTURE_3D, 0);
  draw_tool(true);
  target.end();
}

void SceneRenderer::draw_outside(RenderTarget& target, const CameraView& camera) const {
  target.begin();
  glClearColor(0.10f, 0.11f, 0.13f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  shader_.use();
  shader_.set("view_projection", camera.projection * camera.view);
  shader_.set("eye", camera.eye);
  shader_.set("light_position", camera.eye + 0.05f * camera.up);
  shader_.set("falloff_m", 0.0f);
  shader_.set("ambient", 0.25f);
  shader_.set("alpha", 1.0f);
  shader_.set("round_image", 0);
  shader_.set("emissive", glm::vec3(0.0f));
  shader_.set("color_override", glm::vec4(0.0f));
  // Opaque first: the tool and the landmarks, so they show through the gland.
  draw_tool(false);
  for (const Landmark& l : landmarks_) {
    const glm::mat4 model = glm::scale(glm::translate(glm::mat4(1.0f), glm::vec3(l.position)), glm::vec3(0.0016f));
    shader_.set("model", model);
    shader_.set("color_override", glm::vec4(landmark_color(l.name), 1.0f));
    shader_.set("emissive", 0.3f * landmark_color(l.name));
    marker_->draw();
  }
  shader_.set("color_override", glm::vec4(0.0f));
  shader_.set("emissive", glm::vec3(0.0f));
  // The gland translucent: back faces, then front faces, blended over without writing depth.
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glDepthMask(GL_FALSE);
  glEnable(GL_CULL_FACE);
  shader_.set("model", glm::mat4(1.0f));
  shader_.set("specular", 0.25f);
  shader_.set("alpha", 0.22f);
  shader_.set("mucosa_detail", 0);
  glCullFace(GL_FRONT);
  tissue_->draw();
  glCullFace(GL_BACK);
  tissue_->draw();
  glDepthMask(GL_TRUE);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  target.end();
}

ProjectedPoint SceneRenderer::project(const CameraView& camera, const Vec3& world_m, float width, float height) {
  const glm::vec4 clip = camera.projection * camera.view * glm::vec4(glm::vec3(world_m), 1.0f);
  ProjectedPoint p;
  if (clip.w <= 0.0f) return p;
  const glm::vec3 ndc = glm::vec3(clip) / clip.w;
  p.x = (ndc.x * 0.5f + 0.5f) * width;
  p.y = (1.0f - (ndc.y * 0.5f + 0.5f)) * height;
  p.visible = ndc.x >= -1.0f && ndc.x <= 1.0f && ndc.y >= -1.0f && ndc.y <= 1.0f && ndc.z <= 1.0f;
  return p;
}

}  // namespace resecto::gui

// SessionHeader <-> JSON. Every SimulationConfig field is written explicitly, so a field added to the
// config without a line here shows up as a replay mismatch in the end-to-end test, never silently.
#include "recordings/session_header.h"

#include <string>

#include "recordings/chunk_format.h"

namespace resecto::rec {
namespace {

using nlohmann::ordered_json;

ordered_json pose_json(const RigidPose& pose) {
  const std::array<double, 12> m = to_row_major_3x4(pose);
  return ordered_json(std::vector<double>(m.begin(), m.end()));
}

RigidPose pose_from(const ordered_json& j) {
  const auto m = j.get<std::vector<double>>();
  if (m.size() != 12) throw std::runtime_error("a pose needs 12 numbers");
  RigidPose pose;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) pose.rotation[c][r] = m[static_cast<std::size_t>(r * 4 + c)];
    pose.translation[r] = m[static_cast<std::size_t>(r * 4 + 3)];
  }
  return pose;
}

ordered_json vec_json(const Vec3& v) { return ordered_json::array({v.x, v.y, v.z}); }
Vec3 vec_from(const ordered_json& j) {
  if (!j.is_array() || j.size() != 3) throw std::runtime_error("a vector needs 3 numbers");
  return Vec3(j[0].get<double>(), j[1].get<double>(), j[2].get<double>());
}

ordered_json config_json(const SimulationConfig& c) {
  ordered_json parameters = ordered_json::object();
  for (const TissueParameterSpec& spec : tissue_parameter_specs()) parameters[std::string(spec.key)] = c.parameters.get(spec.id);
  const TissueConfig& t = c.tissue;
  return {{"prostate_triangles", c.prostate_triangles},
          {"collision_hz", c.collision_hz},
          {"physics_per_collision", c.physics_per_collision},
          {"collision_thread", c.collision_thread},
          {"parameters", parameters},
          {"gimbal", {{"pivot_m", vec_json(c.gimbal.pivot_m)}, {"device_to_world", pose_json(c.gimbal.device_to_world)}}},
          {"max_tet_volume_m3", c.max_tet_volume_m3},
          {"input_filter",
           {{"min_cutoff_hz", c.input_filter.min_cutoff_hz},
            {"derivative_cutoff_hz", c.input_filter.derivative_cutoff_hz},
            {"linear_beta_per_m", c.input_filter.linear_beta_per_m},
            {"angular_beta_s_per_rad", c.input_filter.angular_beta_s_per_rad},
            {"enabled", c.input_filter.enabled}}},
          {"predict_search_pose", c.predict_search_pose},
          {"tissue",
           {{"integrator", static_cast<int>(t.integrator)},
            {"max_cg_iterations", t.max_cg_iterations},
            {"cg_tolerance", t.cg_tolerance},
            {"max_substeps", t.max_substeps},
            {"contact_margin_m", t.contact_margin_m},
            {"contact_capacity",
             {{"max_tissue_nodes", t.contact_capacity.max_tissue_nodes},
              {"max_tool_vertices", t.contact_capacity.max_tool_vertices},
              {"max_pair_entries", t.contact_capacity.max_pair_entries}}},
            {"locality_order", t.locality_order},
            {"clearance_certificates", t.clearance_certificates}}}};
}

SimulationConfig config_from(const ordered_json& j) {
  SimulationConfig c;
  c.prostate_triangles = j.at("prostate_triangles").get<int>();
  c.collision_hz = j.at("collision_hz").get<int>();
  c.physics_per_collision = j.at("physics_per_collision").get<int>();
  c.collision_thread = j.at("collision_thread").get<bool>();
  for (const auto& [key, value] : j.at("parameters").items()) {
    const std::optional<TissueParameter> id = find_tissue_parameter(key);
    if (!id) throw std::runtime_error("unknown tissue parameter '" + key + "'");
    if (Status set = c.parameters.set(*id, value.get<double>()); !set) throw std::runtime_error(set.error());
  }
  c.gimbal.pivot_m = vec_from(j.at("gimbal").at("pivot_m"));
  c.gimbal.device_to_world = pose_from(j.at("gimbal").at("device_to_world"));
  c.max_tet_volume_m3 = j.at("max_tet_volume_m3").get<double>();
  const auto& f = j.at("input_filter");
  c.input_filter.min_cutoff_hz = f.at("min_cutoff_hz").get<double>();
  c.input_filter.derivative_cutoff_hz = f.at("derivative_cutoff_hz").get<double>();
  c.input_filter.linear_beta_per_m = f.at("linear_beta_per_m").get<double>();
  c.input_filter.angular_beta_s_per_rad = f.at("angular_beta_s_per_rad").get<double>();
  c.input_filter.enabled = f.at("enabled").get<bool>();
  c.predict_search_pose = j.at("predict_search_pose").get<bool>();
  const auto& t = j.at("tissue");
  const int integrator = t.at("integrator").get<int>();
  if (integrator < 0 || integrator > static_cast<int>(TissueIntegrator::kImplicitEuler)) throw std::runtime_error("unknown integrator");
  c.tissue.integrator = static_cast<TissueIntegrator>(integrator);
  c.tissue.max_cg_iterations = t.at("max_cg_iterations").get<int>();
  c.tissue.cg_tolerance = t.at("cg_tolerance").get<double>();
  c.tissue.max_substeps = t.at("max_substeps").get<int>();
  c.tissue.contact_margin_m = t.at("contact_margin_m").get<double>();
  c.tissue.contact_capacity.max_tissue_nodes = t.at("contact_capacity").at("max_tissue_nodes").get<std::int32_t>();
  c.tissue.contact_capacity.max_tool_vertices = t.at("contact_capacity").at("max_tool_vertices").get<std::int32_t>();
  c.tissue.contact_capacity.max_pair_entries = t.at("contact_capacity").at("max_pair_entries").get<std::int32_t>();
  c.tissue.locality_order = t.at("locality_order").get<bool>();
  c.tissue.clearance_certificates = t.at("clearance_certificates").get<bool>();
  if (Status valid = c.validate(); !valid) throw std::runtime_error(valid.error());
  return c;
}

}  // namespace

std::string build_identity() {
  std::string id = "resecto " RESECTO_VERSION_STRING;
#if defined(__clang__)
  id += " (clang " __clang_version__;
#elif defined(__GNUC__)
  id += " (GCC " + std::to_string(__GNUC__) + "." + std::to_string(__GNUC_MINOR__) + "." + std::to_string(__GNUC_PATCHLEVEL__);
#else
  id += " (unknown compiler";
#endif
  id += ", " RESECTO_BUILD_TYPE ")";
  return id;
}

nlohmann::ordered_json header_to_json(const SessionHeader& h) {
  return {{"format_version", h.format_version},
          {"build", h.build},
          {"procedure", h.procedure},
          {"mode", h.mode},
          {"seed", h.seed},
          {"start_tick", h.start_tick},
          {"tick_s", h.simulation.tick_s()},
          {"surface_triangles", h.surface_triangles},
          {"nodes", h.nodes},
          {"metric_words", h.metric_words},
          {"keyframe_every_steps", h.keyframe_every_steps},
          {"quantisation",
           {{"origin_m", {h.grid.origin[0], h.grid.origin[1], h.grid.origin[2]}}, {"range_m", h.grid.range}, {"bits", h.grid.bits}}},
          {"simulation", config_json(h.simulation)},
          {"calibration", h.calibration}};
}

Result<SessionHeader> header_from_json(std::string_view text) {
  try {
    const ordered_json j = ordered_json::parse(text);
    SessionHeader h;
    h.format_version = j.at("format_version").get<std::uint32_t>();
    if (h.format_version != kFormatVersion) {
      return Error{"format version " + std::to_string(h.format_version) + " (this build reads " + std::to_string(kFormatVersion) + ")"};
    }
    h.build = j.at("build").get<std::string>();
    h.procedure = j.at("procedure").get<std::string>();
    h.mode = j.at("mode").get<std::string>();
    h.seed = j.at("seed").get<std::uint64_t>();
    h.start_tick = j.at("start_tick").get<std::int64_t>();
    h.surface_triangles = j.at("surface_triangles").get<std::uint32_t>();
    h.nodes = j.at("nodes").get<std::uint32_t>();
    h.metric_words = j.at("metric_words").get<std::uint32_t>();
    h.keyframe_every_steps = j.at("keyframe_every_steps").get<int>();
    if (h.keyframe_every_steps < 1) throw std::runtime_error("keyframe_every_steps must be at least 1");
    const auto& q = j.at("quantisation");
    for (int i = 0; i < 3; ++i) h.grid.origin[i] = q.at("origin_m").at(static_cast<std::size_t>(i)).get<float>();
    h.grid.range = q.at("range_m").get<float>();
    h.grid.bits = q.at("bits").get<int>();
    if (h.grid.bits < 1 || h.grid.bits > 30 || !(h.grid.range > 0.0f)) throw std::runtime_error("bad quantisation grid");
    h.simulation = config_from(j.at("simulation"));
    h.calibration = j.contains("calibration") ? j.at("calibration") : ordered_json(nullptr);
    return h;
  } catch (const std::exception& e) {
    return Error{std::string("header: ") + e.what()};
  }
}

}  // namespace resecto::rec

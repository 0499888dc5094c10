// SessionHeader <-> JSON. Every SimulationConfig field is written explicitly, so a field added to the
// config without a line here shows up as a replay mismatch in the end-to-end test, never silently.
#include "recordings/session_header.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "recordings/chunk_format.h"
#include "recordings/json_fields.h"
#include "rtcore/base/checked_number.h"
#include "rtcore/base/json_text.h"

namespace resecto::rec {
namespace {

using nlohmann::ordered_json;

ordered_json pose_json(const RigidPose& pose) {
  const std::array<double, 12> m = to_row_major_3x4(pose);
  return ordered_json(std::vector<double>(m.begin(), m.end()));
}

RigidPose pose_from(const std::array<double, 12>& m) {
  RigidPose pose;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) pose.rotation[c][r] = m[static_cast<std::size_t>(r * 4 + c)];
    pose.translation[r] = m[static_cast<std::size_t>(r * 4 + 3)];
  }
  return pose;
}

ordered_json vec_json(const Vec3& v) { return ordered_json::array({v.x, v.y, v.z}); }

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
            {"contact_reuse_m", t.contact_reuse_m},
            {"contact_capacity",
             {{"max_tissue_nodes", t.contact_capacity.max_tissue_nodes},
              {"max_tool_vertices", t.contact_capacity.max_tool_vertices},
              {"max_pair_entries", t.contact_capacity.max_pair_entries}}},
            {"locality_order", t.locality_order},
            {"clearance_certificates", t.clearance_certificates}}}};
}

SimulationConfig config_from(const JsonFields& j) {
  SimulationConfig c;
  c.prostate_triangles = j.get<int>("prostate_triangles");
  c.collision_hz = j.get<int>("collision_hz");
  c.physics_per_collision = j.get<int>("physics_per_collision");
  c.collision_thread = j.get<bool>("collision_thread");
  const JsonFields parameters = j.object("parameters");
  for (const auto& [key, value] : parameters.json().items()) {
    const std::optional<TissueParameter> id = find_tissue_parameter(key);
    if (!id) JsonFields::fail(parameters.path_of(key), "unknown tissue parameter");
    if (Status set = c.parameters.set(*id, parameters.get<double>(key.c_str())); !set) JsonFields::fail(parameters.path_of(key), set.error());
  }
  // Every parameter the recorder wrote: one missing would replay at its default, silently another
  // run than the one recorded (audit 29, F7).
  for (const TissueParameterSpec& spec : tissue_parameter_specs()) {
    const std::string key(spec.key);
    if (!parameters.json().contains(key)) JsonFields::fail(parameters.path_of(key), "is missing");
  }
  const JsonFields gimbal = j.object("gimbal");
  const std::array<double, 3> pivot = gimbal.numbers<3>("pivot_m");
  c.gimbal.pivot_m = Vec3(pivot[0], pivot[1], pivot[2]);
  c.gimbal.device_to_world = pose_from(gimbal.numbers<12>("device_to_world"));
  c.max_tet_volume_m3 = j.get<double>("max_tet_volume_m3");
  const JsonFields f = j.object("input_filter");
  c.input_filter.min_cutoff_hz = f.get<double>("min_cutoff_hz");
  c.input_filter.derivative_cutoff_hz = f.get<double>("derivative_cutoff_hz");
  c.input_filter.linear_beta_per_m = f.get<double>("linear_beta_per_m");
  c.input_filter.angular_beta_s_per_rad = f.get<double>("angular_beta_s_per_rad");
  c.input_filter.enabled = f.get<bool>("enabled");
  for (const auto& [name, value] : {std::pair{"min_cutoff_hz", c.input_filter.min_cutoff_hz}, std::pair{"derivative_cutoff_hz", c.input_filter.derivative_cutoff_hz}}) {
    if (!(value > 0.0 && std::isfinite(value))) JsonFields::fail(f.path_of(name), "must be a positive cut-off, not " + exact_number(value));
  }
  for (const auto& [name, value] : {std::pair{"linear_beta_per_m", c.input_filter.linear_beta_per_m}, std::pair{"angular_beta_s_per_rad", c.input_filter.angular_beta_s_per_rad}}) {
    if (!(value >= 0.0 && std::isfinite(value))) JsonFields::fail(f.path_of(name), "must be at least 0, not " + exact_number(value));
  }
  c.predict_search_pose = j.get<bool>("predict_search_pose");
  const JsonFields t = j.object("tissue");
  const int integrator = t.get<int>("integrator");
  if (integrator < 0 || integrator > static_cast<int>(TissueIntegrator::kImplicitEuler)) {
    JsonFields::fail(t.path_of("integrator"), "unknown integrator " + std::to_string(integrator));
  }
  c.tissue.integrator = static_cast<TissueIntegrator>(integrator);
  c.tissue.max_cg_iterations = t.get<int>("max_cg_iterations");
  c.tissue.cg_tolerance = t.get<double>("cg_tolerance");
  c.tissue.max_substeps = t.get<int>("max_substeps");
  c.tissue.contact_margin_m = t.get<double>("contact_margin_m");
  // Recordings made before the search kept its candidates searched at every collision step.
  c.tissue.contact_reuse_m = t.contains("contact_reuse_m") ? t.get<double>("contact_reuse_m") : 0.0;
  const JsonFields capacity = t.object("contact_capacity");
  c.tissue.contact_capacity.max_tissue_nodes = capacity.get<std::int32_t>("max_tissue_nodes");
  c.tissue.contact_capacity.max_tool_vertices = capacity.get<std::int32_t>("max_tool_vertices");
  c.tissue.contact_capacity.max_pair_entries = capacity.get<std::int32_t>("max_pair_entries");
  c.tissue.locality_order = t.get<bool>("locality_order");
  c.tissue.clearance_certificates = t.get<bool>("clearance_certificates");
  if (Status valid = c.validate(); !valid) JsonFields::fail(j.path(), valid.error());
  return c;
}

}  // namespace

std::size_t most_nodes(const SimulationConfig& config) {
  // The gland has about 0.86 nodes per surface triangle, and the core reserves room for three times
  // its nodes (or TissueConfig::kMinNodeCapacity): eight a triangle is ample.
  return std::max<std::size_t>(TissueConfig::kMinNodeCapacity, 8 * static_cast<std::size_t>(std::max(0, config.prostate_triangles)));
}

std::size_t most_surface_triangles(const SimulationConfig& config) {
  // A closed surface has about two triangles a vertex; four a node of the room's floor, sixteen a
  // gland triangle, leave as much again for cut surfaces with handles.
  return std::max<std::size_t>(4 * TissueConfig::kMinNodeCapacity, 16 * static_cast<std::size_t>(std::max(0, config.prostate_triangles)));
}

std::size_t least_surface_triangles(const SimulationConfig& config) {
  // Half the triangles asked for: the grid's count is within half a percent of them where one fits,
  // and never far off where none does.
  return static_cast<std::size_t>(std::max(0, config.prostate_triangles)) / 2;
}

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
  if (std::optional<std::string> deep = json_nesting_error(text, "header")) return Error{*deep};
  try {
    const ordered_json document = ordered_json::parse(text);
    const JsonFields j(document, "");
    SessionHeader h;
    h.format_version = j.get<std::uint32_t>("format_version");
    if (h.format_version != kFormatVersion) {
      return Error{"format version " + std::to_string(h.format_version) + " (this build reads " + std::to_string(kFormatVersion) + ")"};
    }
    h.build = j.get<std::string>("build");
    h.procedure = j.get<std::string>("procedure");
    h.mode = j.get<std::string>("mode");
    if (h.mode != "batch" && h.mode != "realtime" && h.mode != "console") JsonFields::fail("mode", "\"" + h.mode + "\" (batch, realtime or console)");
    h.seed = j.get<std::uint64_t>("seed");
    h.start_tick = j.get<std::int64_t>("start_tick");
    if (h.start_tick < 0) JsonFields::fail("start_tick", "must be at least 0, not " + std::to_string(h.start_tick));
    h.surface_triangles = j.get<std::uint32_t>("surface_triangles");
    h.nodes = j.get<std::uint32_t>("nodes");
    h.metric_words = j.get<std::uint32_t>("metric_words");
    h.keyframe_every_steps = j.get<int>("keyframe_every_steps");
    if (h.keyframe_every_steps < 1) JsonFields::fail("keyframe_every_steps", "must be at least 1");
    const JsonFields q = j.object("quantisation");
    h.simulation = config_from(j.object("simulation"));
    if (h.nodes > most_nodes(h.simulation)) {
      JsonFields::fail("nodes", std::to_string(h.nodes) + " is more than a gland of " + std::to_string(h.simulation.prostate_triangles) +
                                    " triangles holds (at most " + std::to_string(most_nodes(h.simulation)) + ")");
    }
    if (h.surface_triangles > most_surface_triangles(h.simulation)) {
      JsonFields::fail("surface_triangles", std::to_string(h.surface_triangles) + " is more than a gland of " +
                                                std::to_string(h.simulation.prostate_triangles) + " triangles holds (at most " +
                                                std::to_string(most_surface_triangles(h.simulation)) + ")");
    }
    // The gland built from the settings has a surface within a percent of the triangles asked for
    // (generate_prostate's grid): a count far below says the header was edited, and a replay would
    // first build the model the settings ask for (54 s and 2.5 GB at 300,000) only to refuse it then
    // (audit 7, F3). The recorder writes the surface at the start, before any cut.
    if (h.surface_triangles < least_surface_triangles(h.simulation)) {
      JsonFields::fail("surface_triangles", std::to_string(h.surface_triangles) + " is far fewer than a gland of " +
                                                std::to_string(h.simulation.prostate_triangles) + " triangles has (at least " +
                                                std::to_string(least_surface_triangles(h.simulation)) + "): the header was edited");
    }
    const std::array<double, 3> origin = q.numbers<3>("origin_m");
    for (std::size_t i = 0; i < 3; ++i) h.grid.origin[i] = static_cast<float>(origin[i]);
    h.grid.range = q.get<float>("range_m");
    h.grid.bits = q.get<int>("bits");
    if (h.grid.bits < 1 || h.grid.bits > 30 || !(h.grid.range > 0.0f)) JsonFields::fail("quantisation", "bad grid (bits 1 to 30, a positive range)");
    // Written for the reader, derived from the rates on reading: a file whose tick disagrees with
    // its rates (or lacks it) was not written by the recorder.
    const double tick_s = j.get<double>("tick_s");
    if (!(std::abs(tick_s - h.simulation.tick_s()) <= 1e-12 * h.simulation.tick_s())) {
      JsonFields::fail("tick_s", exact_number(tick_s) + " disagrees with the rates (" + exact_number(h.simulation.tick_s()) + " s)");
    }
    if (!j.contains("calibration") || !j.at("calibration").is_object()) JsonFields::fail("calibration", "is missing (the device calibration, an object)");
    h.calibration = j.at("calibration");
    return h;
  } catch (const std::exception& e) {
    return Error{"header: " + library_free(e.what())};
  }
}

}  // namespace resecto::rec

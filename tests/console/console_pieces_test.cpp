// The console's parts that need no window: the action script's parser and its messages, tissue
// presets (round trip, clear errors), the endoscope's camera (30 degrees toward the loop, turning
// with the sheath's roll), and the surface's looks (lining, cut adenoma, cut capsule) through
// refinement, a cut and a replay's seek back.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include <glm/trigonometric.hpp>
#include <glm/geometric.hpp>

#include "console/gui/action_script.h"
#include "console/gui/surface_looks.h"
#include "console/gui/tissue_presets.h"
#include "console/gui/view_cameras.h"
#include "rtcore/kinematics/tool_kinematics.h"
#include "tests/console/run_resecto.h"

namespace resecto::gui {
namespace {

TEST(ActionScript, ParsesEveryVerbInFrameOrder) {
  const char* text =
      "# a tutorial\n"
      "frame 30 quit\n"
      "frame 5 set stiffness 120   # stiffer\n"
      "frame 5 pedal cut on\n"
      "frame 6 key W down\n"
      "frame 7 drag outside 40 -10\n"
      "frame 8 pause\nframe 9 step 16\nframe 10 resume\n"
      "frame 11 record out.resecto\nframe 12 screenshot a.png\nframe 13 preset save p.json\n"
      "frame 14 replay seek 2.5\n";
  Result<std::vector<Action>> actions = parse_actions(text, "t.actions");
  ASSERT_TRUE(actions) << actions.error();
  ASSERT_EQ(actions->size(), 12u);
  EXPECT_EQ((*actions)[0].frame, 5u);
  EXPECT_EQ((*actions)[0].verb, ActionVerb::kSet);
  EXPECT_EQ((*actions)[0].words[0], "stiffness");
  EXPECT_EQ((*actions)[0].value, 120.0);
  EXPECT_EQ((*actions)[1].verb, ActionVerb::kPedal);  // same frame: written order
  EXPECT_EQ((*actions)[3].value, 40.0);
  EXPECT_EQ((*actions)[3].value2, -10.0);
  EXPECT_EQ((*actions)[5].value, 16.0);
  EXPECT_EQ((*actions)[10].value, 2.5);
  EXPECT_EQ(actions->back().verb, ActionVerb::kQuit);
  EXPECT_EQ(actions->back().line, 2);
}

// Lines may end in LF, CR LF or a lone CR; a comment starts at a word that begins with '#', so a
// path may hold one (audit 24, F11: "screenshot shots/#2.png" lost its file name to the comment).
TEST(ActionScript, LineEndingsAndHashesInPaths) {
  for (const char* ending : {"\n", "\r\n", "\r"}) {
    const std::string text = std::string("# tutorial") + ending + "frame 2 screenshot shots/#2.png  # the second" + ending + ending + "frame 3 quit";
    Result<std::vector<Action>> parsed = parse_actions(text, "t");
    ASSERT_TRUE(parsed) << parsed.error();
    ASSERT_EQ(parsed->size(), 2u);
    EXPECT_EQ((*parsed)[0].words[0], "shots/#2.png");
    EXPECT_EQ((*parsed)[0].line, 2);
    EXPECT_EQ((*parsed)[1].line, 4);
  }
}

// Audit 6, D: numbers are read as on the command line, where `--set stiffness=+40` now is.
TEST(ActionScript, NumbersMayCarryALeadingPlus) {
  Result<std::vector<Action>> parsed = parse_actions("frame +2 set stiffness +45\n", "t");
  ASSERT_TRUE(parsed) << parsed.error();
  EXPECT_EQ((*parsed)[0].frame, 2u);
  EXPECT_EQ((*parsed)[0].value, 45.0);
}

TEST(ActionScript, ErrorsNameTheLineAndTheProblem) {
  const std::pair<const char*, const char*> cases[] = {
      {"frame 1 pause\nframe x quit\n", "t:2:7: expected 'frame N VERB"},
      {"frame 1 jump\n", "t:1:9: unknown action 'jump'"},
      {"frame 1 set stifness 50\n", "t:1:13: unknown key 'stifness'"},
      {"frame 1 set stiffness 1e9\n", "t:1:13: parameter stiffness = 1e+09 is out of range"},
      {"frame 1 set speed 2\n", "t:1:13: speed 2 is outside [1/64, 1]"},
      // Audit 8, G9: values past what the device or the core takes were clamped without a word.
      {"frame 1 set speed 0.001\n", "t:1:13: speed 0.001 is outside [1/64, 1]"},
      {"frame 1 set insertion 500\n", "t:1:13: insertion 500 is outside the device's travel [0, 230] mm"},
      {"frame 1 set loop -99\n", "t:1:13: loop -99 is outside the device's travel [0, 36] mm"},
      {"frame 1 set yaw 1000\n", "yaw 1000 is outside the device's travel"},
      {"frame 1 replay speed 100\n", "t:1:22: replay speed 100 is outside [0.1, 4], the replay panel's range"},
      {"frame 1 key F1 down\n", "t:1:13: key: 'F1' is not a key"},
      {"\tframe 1 pedal cut sometimes\n", "t:1:20: pedal: expected on or off"},
      {"frame 1 set stiffness soft\n", "'soft' is not a number"},
      {"frame 1 pedal cut maybe\n", "expected on or off"},
      {"frame 1 step 0\n", "whole number of ticks"},
      {"frame 1 quit now\n", "takes 0 argument(s), got 1"},
      {"frame 1 replay rewind\n", "unknown operation 'rewind'"},
      {"frame -3 quit\n", "t:1:"},
      {"frame 1e1 quit\n", "t:1:7: expected 'frame N VERB ...' with N a whole number"},
      {"frame 2.0 quit\n", "t:1:7: expected 'frame N VERB ...' with N a whole number"},
  };
  for (const auto& [text, expected] : cases) {
    Result<std::vector<Action>> parsed = parse_actions(text, "t");
    ASSERT_FALSE(parsed) << text;
    EXPECT_NE(parsed.error().find(expected), std::string::npos) << parsed.error();
  }
  EXPECT_FALSE(load_actions("/nonexistent/x.actions"));
  // The hand-driven device's actions, refused up front for a session whose device follows a procedure.
  Result<std::vector<Action>> manual = parse_actions("frame 1 set stiffness 50\nframe 9 drag endoscope 5 5\n", "t");
  ASSERT_TRUE(manual) << manual.error();
  EXPECT_TRUE(check_actions_for_device(*manual, true, "t"));
  const Status refused = check_actions_for_device(*manual, false, "t");
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().find("t:2:14: drag drives the hand-driven device"), std::string::npos) << refused.error();
  // A device is refused by name, not read until the memory runs out.
  Result<std::vector<Action>> device = load_actions("/dev/zero");
  ASSERT_FALSE(device);
  EXPECT_NE(device.error().find("/dev/zero: not a regular file"), std::string::npos) << device.error();
}

TEST(TissuePresets, RoundTripAndClearErrors) {
  const auto dir = testing::scratch_directory("presets");
  TissueParameters tuned;
  ASSERT_TRUE(tuned.set(TissueParameter::kStiffness, 75.0));
  ASSERT_TRUE(tuned.set(TissueParameter::kCuttingRadius, 1.5));
  ASSERT_TRUE(save_preset(dir / "p.json", tuned));
  Result<TissueParameters> loaded = load_preset(dir / "p.json", TissueParameters{});
  ASSERT_TRUE(loaded) << loaded.error();
  EXPECT_EQ(loaded->values, tuned.values);

  std::ofstream(dir / "partial.json") << R"({"resecto_preset": 1, "parameters": {"density": 1.2}})";
  Result<TissueParameters> partial = load_preset(dir / "partial.json", tuned);
  ASSERT_TRUE(partial);
  EXPECT_EQ(partial->get(TissueParameter::kDensity), 1.2);
  EXPECT_EQ(partial->get(TissueParameter::kStiffness), 75.0);

  const std::pair<const char*, const char*> bad[] = {
      {R"({"resecto_preset": 1, "parameters": {"hardness": 3}})", "unknown parameter 'hardness'"},
      // A NUL or escape in a key is written out, not sent raw (audit 8, G13).
      {R"({"resecto_preset": 1, "parameters": {"stiff\u0000ness": 3}})", "unknown parameter 'stiff\\x00ness' (see resecto params)"},
      {R"({"resecto_preset": 1, "parameters": {"\u001b[2J": 3}})", "unknown parameter '\\x1b[2J'"},
      {R"({"resecto_preset": 1, "parameters": {"stiffness": 9000}})", "out of range"},
      {R"({"resecto_preset": 1, "parameters": {"stiffness": "hard"}})", "must be a number"},
      {R"({"parameters": {}})", "not a Resecto preset"},
      {R"(not json)", "not valid JSON at line 1, column 2"},
      {"{\"resecto_preset\": 1,\n \"parameters\": {\"stiffness\" 40}}", "not valid JSON at line 2, column "},
      {R"([1, 2])", "not a JSON object"},
      {R"({"resecto_preset": 2, "parameters": {}})", "preset format 2 is not one this build reads"},
      {R"({"resecto_preset": 1, "parameters": {}, "stiffnes": 40})", "unknown key 'stiffnes'"},
      {R"({"resecto_preset": 1, "parameters": {"stiffness": 40, "stiffness": 60}})", "parameters.stiffness: the key appears twice in its object"},
  };
  for (const auto& [text, expected] : bad) {
    std::ofstream(dir / "bad.json") << text;
    Result<TissueParameters> r = load_preset(dir / "bad.json", TissueParameters{});
    ASSERT_FALSE(r) << text;
    EXPECT_NE(r.error().find(expected), std::string::npos) << r.error();
    EXPECT_NE(r.error().find("bad.json"), std::string::npos) << r.error();
  }
  // A folder, or a device that would be read for ever, is refused by name before any read.
  for (const std::filesystem::path& not_a_file : {dir, std::filesystem::path("/dev/zero")}) {
    Result<TissueParameters> r = load_preset(not_a_file, TissueParameters{});
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().find(not_a_file.string() + ": "), std::string::npos) << r.error();
  }
}

TEST(EndoscopeCamera, LooksThirtyDegreesTowardTheLoopAndRollsWithTheSheath) {
  DeviceJoints joints;
  joints.insertion_m = 0.168;
  const GimbalGeometry geometry;
  const ToolPoses straight = tool_poses(joints, geometry);
  const EndoscopeLens lens;
  const CameraView view = endoscope_camera(straight.sheath, lens, 1.0f);
  const glm::vec3 axis = glm::vec3(straight.sheath.apply_vector(Vec3(0, 0, 1)));
  const glm::vec3 loop_side = glm::vec3(straight.sheath.apply_vector(Vec3(0, -1, 0)));
  EXPECT_NEAR(glm::degrees(std::acos(glm::dot(view.forward, axis))), 30.0, 1e-3);
  EXPECT_GT(glm::dot(view.forward, loop_side), 0.49f) << "tilted toward the loop";
  // The loop's wire front (tool frame: 4.5 mm below the axis, 4 mm ahead) is inside the image.
  const Vec3 loop_front = straight.sheath.apply_point(Vec3(0.0, -0.0045, 0.004));
  const glm::vec4 clip = view.projection * view.view * glm::vec4(glm::vec3(loop_front), 1.0f);
  ASSERT_GT(clip.w, 0.0f);
  EXPECT_LT(std::abs(clip.x / clip.w), 1.0f);
  EXPECT_LT(std::abs(clip.y / clip.w), 1.0f);

  joints.roll_rad = std::acos(-1.0) / 2.0;
  const CameraView rolled = endoscope_camera(tool_poses(joints, geometry).sheath, lens, 1.0f);
  // The image's up, seen along the sheath's axis, turns by the roll.
  auto across = [&](glm::vec3 v) { return glm::normalize(v - glm::dot(v, axis) * axis); };
  EXPECT_NEAR(glm::degrees(std::acos(glm::dot(across(rolled.up), across(view.up)))), 90.0, 1e-2) << "a quarter roll turns the image a quarter";
  EXPECT_NEAR(glm::degrees(std::acos(glm::dot(rolled.forward, axis))), 30.0, 1e-3);
}

TEST(OrbitCamera, DragTurnsAndTiltsWithinLimitsAndZoomStaysBounded) {
  OrbitCamera orbit;
  const float yaw = orbit.yaw_deg;
  orbit.drag(100.0f, 0.0f);
  EXPECT_NE(orbit.yaw_deg, yaw);
  orbit.drag(0.0f, 10000.0f);
  EXPECT_LE(orbit.pitch_deg, 85.0f);
  for (int i = 0; i < 100; ++i) orbit.zoom(5.0f);
  EXPECT_GE(orbit.distance_m, 0.03f);
  const CameraView v = orbit.view(1.5f);
  EXPECT_NEAR(glm::length(v.eye - orbit.target), orbit.distance_m, 1e-5f);
}

/// A snapshot with these node positions, faces and regions (adenoma where none is given).
SimulationSnapshot surface_snapshot(const std::vector<Vec3>& nodes, const std::vector<Triangle>& faces,
                                    const std::vector<TissueRegion>& regions = {}) {
  SimulationSnapshot s;
  s.node_positions = nodes;
  s.node_count = static_cast<std::uint32_t>(nodes.size());
  s.surface_triangles = faces;
  s.surface_triangle_count = static_cast<std::uint32_t>(faces.size());
  s.surface_regions = regions.empty() ? std::vector<TissueRegion>(faces.size(), TissueRegion::kAdenoma) : regions;
  return s;
}

TEST(SurfaceLooks, RefinedPiecesKeepTheirFacesLookAndCutFacesShowTheirRegion) {
  constexpr double kLining = 0.01;
  // A lining face by the axis (0, 1, 2), a capsule face far from it (3, 4, 5), and an inner node (6)
  // just under the lining face: a flat tetrahedron, whose inner faces lie nearly on the outer one.
  std::vector<Vec3> nodes = {{-0.002, -0.001, 0.0}, {0.002, -0.001, 0.0}, {0.0, 0.002, 0.0},
                             {0.03, 0.0, 0.0},      {0.04, 0.0, 0.0},     {0.035, 0.0, 0.008},
                             {0.0, 0.0, -0.0001}};
  SurfaceLooks looks;
  looks.classify(surface_snapshot(nodes, {{0, 1, 2}, {3, 4, 5}}), kLining);
  EXPECT_EQ(looks.looks(), (std::vector<SurfaceLook>{SurfaceLook::kMucosa, SurfaceLook::kCapsuleOut}));

  // Refinement: the lining face quartered (7, 8, 9 the middles of its edges, pushed 0.4 mm off its
  // plane, as the loop deforms tissue), the capsule face halved (10 the middle of 3-4).
  auto middle = [&](int a, int b, double lift) { return 0.5 * (nodes[a] + nodes[b]) + Vec3(0.0, 0.0, lift); };
  nodes.push_back(middle(0, 1, 0.0004));
  nodes.push_back(middle(1, 2, -0.0003));
  nodes.push_back(middle(2, 0, 0.0004));
  nodes.push_back(middle(3, 4, 0.0));
  const std::vector<Triangle> refined = {{0, 7, 9}, {7, 1, 8}, {9, 8, 2}, {7, 8, 9}, {3, 10, 5}, {10, 4, 5}};
  looks.classify(surface_snapshot(nodes, refined), kLining);
  EXPECT_EQ(looks.looks(), (std::vector<SurfaceLook>{SurfaceLook::kMucosa, SurfaceLook::kMucosa, SurfaceLook::kMucosa,
                                                     SurfaceLook::kMucosa, SurfaceLook::kCapsuleOut, SurfaceLook::kCapsuleOut}));

  // The cut removes the centre piece's tetrahedron: its three inner faces, all through node 6, show
  // the region behind them, however close to the removed face they lie.
  const std::vector<Triangle> cut = {{0, 7, 9}, {7, 1, 8}, {9, 8, 2}, {7, 8, 6}, {8, 9, 6}, {9, 7, 6}, {3, 10, 5}, {10, 4, 5}};
  const std::vector<TissueRegion> regions = {TissueRegion::kAdenoma, TissueRegion::kAdenoma, TissueRegion::kAdenoma,
                                             TissueRegion::kCapsule, TissueRegion::kAdenoma, TissueRegion::kAdenoma,
                                             TissueRegion::kCapsule, TissueRegion::kCapsule};
  looks.classify(surface_snapshot(nodes, cut, regions), kLining);
  EXPECT_EQ(looks.looks(), (std::vector<SurfaceLook>{SurfaceLook::kMucosa, SurfaceLook::kMucosa, SurfaceLook::kMucosa,
                                                     SurfaceLook::kCapsuleCut, SurfaceLook::kAdenoma, SurfaceLook::kAdenoma,
                                                     SurfaceLook::kCapsuleOut, SurfaceLook::kCapsuleOut}));

  // A replay scrubbed back to before the cut: the uncut faces take their first look again.
  looks.classify(surface_snapshot(nodes, {{3, 4, 5}, {0, 1, 2}}), kLining);
  EXPECT_EQ(looks.looks(), (std::vector<SurfaceLook>{SurfaceLook::kCapsuleOut, SurfaceLook::kMucosa}));
}

}  // namespace
}  // namespace resecto::gui

// Issue 18's hostile-input reproducers through the command line: every one must end with a clear
// one-line error and a non-zero exit, within 5 s and 512 MB, without a crash; and no output may
// replace a good file or leave a partial one behind. The full-disk cases write into a small tmpfs
// this test mounts and fills (they are skipped, saying so, where mounting is not permitted).
#include <gtest/gtest.h>

#include <sys/mount.h>
#include <sys/stat.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "tests/console/run_resecto.h"

namespace resecto::testing {
namespace {

void write_bytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

/// The run failed the way a user should see: exit code 1-127, no crash or kill, and one line on
/// standard error naming the problem (CLI11's parse errors add a "Run with --help" line).
void expect_clean_failure(const CommandOutput& run, const std::string& expected, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_GT(run.exit_code, 0) << "crashed, hung or exceeded 512 MB (-1) or succeeded (0); stderr: " << run.err;
  ASSERT_FALSE(run.err.empty());
  const std::string first = run.err.substr(0, run.err.find('\n'));
  EXPECT_NE(first.find(expected), std::string::npos) << "stderr: " << run.err;
  const std::string rest = run.err.substr(first.size());
  EXPECT_TRUE(rest == "\n" || rest == "\nRun with --help for more information.\n") << "more than one line: " << run.err;
}

/// Names of the entries in `dir`, to check nothing new (a temporary, a partial file) appeared.
std::set<std::string> listing(const std::filesystem::path& dir) {
  std::set<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) names.insert(entry.path().filename().string());
  return names;
}

const char* kIdentityPose = "1 0 0 0  0 1 0 0  0 0 1 0\n";

class HostileInput : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::filesystem::path(scratch_directory("hostile_input"));
    ASSERT_EQ(run_resecto("mesh prostate --triangles 1296 -o " + (*dir_ / "p.off").string()).exit_code, 0);
    ASSERT_EQ(run_resecto("mesh resectoscope -o " + (*dir_ / "tool.off").string()).exit_code, 0);
    write_bytes(*dir_ / "pose.txt", kIdentityPose);
  }
  static void TearDownTestSuite() { delete dir_; }
  static std::filesystem::path path(const std::string& name) { return *dir_ / name; }
  static std::string arg(const std::string& name) { return (*dir_ / name).string(); }
  /// `collide` with this tissue against the resectoscope at the identity pose.
  static std::string collide_args(const std::string& tissue, const std::string& poses = "pose.txt") {
    return "collide --tissue " + tissue + " --tool " + arg("tool.off") + " --poses " + arg(poses);
  }

  static std::filesystem::path* dir_;
};
std::filesystem::path* HostileInput::dir_ = nullptr;

TEST_F(HostileInput, DeviceMonitorChecksThePathIsAHidrawNode) {
  write_bytes(path("regular.bin"), std::string(64, '\x01'));
  for (const std::string& node : {std::string("/dev/null"), std::string("/dev/zero"), arg("regular.bin")}) {
    expect_clean_failure(run_resecto_bounded("device monitor --path " + node + " --seconds 0.2"), "not a hidraw device", node);
  }
}

TEST_F(HostileInput, DeviceMonitorEndsOnTimeWhateverIsInjected) {
  // With every report dropped or delayed, a read never returned and the monitor never ended.
  for (const std::string faults : {"--drop 1", "--delay 1", "--drop 0.5 --delay 0.5"}) {
    const CommandOutput run = run_resecto_bounded("device monitor --device emulator --seconds 0.3 --json " + faults);
    EXPECT_EQ(run.exit_code, 0) << faults << ": " << run.err;
  }
}

TEST_F(HostileInput, MissingInputsAndUnknownNamesAreUsageErrors) {
  // docs/commands.md: exit 2 for a command line that cannot be run, before anything runs; most of
  // these exited 1 after the command had started.
  const std::string missing = arg("missing.file");
  const std::pair<std::string, std::string> cases[] = {
      {"mesh check " + missing, "no such file"},
      {"mesh tetra " + missing + " -o " + arg("t.vtk"), "no such file"},
      {"rec info " + missing, "no such file"},
      {"rec verify " + missing, "no such file"},
      {"rec recover " + missing + " " + arg("out.rsrec"), "no such file"},
      {"rec export " + missing + " -o " + arg("out.off"), "no such file"},
      {"replay " + missing, "no such file"},
      {"run --headless --procedure " + missing, "no such file"},
      {"run --headless --procedure nosuchname", "no built-in procedure 'nosuchname'"},
      {"run --headless --calibration " + missing, "no such file"},
      {"run --headless --set stiffness=-5", "stiffness = -5 is out of range"},
      {"run --headless --set nonsense=1", "unknown parameter 'nonsense'"},
      {"console --replay " + missing, "no such file"},
  };
  for (const auto& [args, expected] : cases) {
    const CommandOutput run = run_resecto_bounded(args);
    EXPECT_EQ(run.exit_code, 2) << args << ": " << run.err;
    expect_clean_failure(run, expected, args);
  }
  EXPECT_FALSE(std::filesystem::exists(path("t.vtk")));
  EXPECT_FALSE(std::filesystem::exists(path("out.rsrec")));
}

TEST_F(HostileInput, EmptyOutputPathsAreUsageErrors) {
  // An output given as '' read as no output at all: the command succeeded having written nothing.
  for (const std::string& args : {collide_args(arg("p.off")) + " --pairs ''", std::string("run --headless --seconds 0.1 --report ''"),
                                  std::string("run --headless --seconds 0.1 --trace ''"), std::string("run --headless --seconds 0.1 --record ''"),
                                  std::string("run --headless --seconds 0.1 --export-surface ''"), std::string("score --csv '' x.rsrec")}) {
    const CommandOutput run = run_resecto(args);  // the shell gives resecto the empty word
    EXPECT_EQ(run.exit_code, 2) << args << ": " << run.err;
    expect_clean_failure(run, "an empty path names no file", args);
  }
}

TEST_F(HostileInput, OffHeadersWithoutUsableCountsAreBoundedErrors) {
  const std::pair<const char*, std::string> cases[] = {
      {"empty_header.off", "OFF"},
      {"negative.off", "OFF\n-4 -4 0\n"},
      {"huge.off", "OFF\n2000000000 2000000000 0\n"},
      {"huge_face.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1000000000 1 2 3\n"},
      {"binary.off", std::string("OFF BINARY\n") + std::string("\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff", 12)},
      {"more_faces_claimed.off", "OFF\n4 100 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"},
      // Right counts, a bad face: the face is named, not the counts.
      {"two_corner_face.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n2 0 1\n"},
  };
  const char* expected[] = {"the header ends before its vertex, face and edge counts", "vertex count -4 is negative",
                            "vertex count 2000000000 is over the limit", "face 0 has 1000000000 corners",
                            "binary OFF is not read", "face count 100 needs at least 8 bytes each",
                            "face 0 has 2 corners"};
  for (std::size_t i = 0; i < std::size(cases); ++i) {
    write_bytes(path(cases[i].first), cases[i].second);
    const std::string file = arg(cases[i].first);
    expect_clean_failure(run_resecto_bounded("mesh check " + file), expected[i], "mesh check " + file);
    expect_clean_failure(run_resecto_bounded("mesh tetra " + file + " -o " + arg("t.vtk")), expected[i], "mesh tetra " + file);
    expect_clean_failure(run_resecto_bounded(collide_args(file)), expected[i], "collide " + file);
  }
  EXPECT_FALSE(std::filesystem::exists(path("t.vtk")));
}

TEST_F(HostileInput, CollideNeverWritesItsPairsOverAnInput) {
  const std::string tool = read_text(path("tool.off"));
  for (const std::string input : {"tool.off", "pose.txt", "p.off"}) {
    const std::set<std::string> before = listing(*dir_);
    expect_clean_failure(run_resecto_bounded(collide_args(arg("p.off")) + " --pairs " + arg(input)), arg(input) + ": is the input", input);
    EXPECT_EQ(listing(*dir_), before);
  }
  EXPECT_EQ(read_text(path("tool.off")), tool);
  // A pairs file in a folder that is not there is refused before the queries run.
  expect_clean_failure(run_resecto_bounded(collide_args(arg("p.off")) + " --pairs " + arg("missing/pairs.csv")), "does not exist", "missing folder");
}

TEST_F(HostileInput, AnOutputFolderThatTakesNoFileIsRefusedBeforeTheRun) {
  // /proc passes access(W_OK) for root but makes no file: the full turp procedure (minutes) used to
  // run to its end and only then fail to write its surface or report.
  for (const std::string option : {"--export-surface /proc/resecto.off", "--report /proc/resecto.json", "--trace /proc/resecto.trace.json"}) {
    expect_clean_failure(run_resecto_bounded("run --headless --procedure turp " + option), "cannot create a file in its folder /proc", option);
  }
}

TEST_F(HostileInput, CollideWithAToolFarBelowAMillimetreStaysBounded) {
  // A triangle 1e-110 mm across: its box's volume underflowed to zero, and so did the tool grids'
  // cells, which then numbered 65,537 a side (terabytes; the run grew past 12 GB before it was killed).
  // Such a tool is now refused at once (audit 32, F7: the exact tests underflow below spans of 1e-60);
  // one of 1e-50 still runs, bounded.
  for (const char* side : {"1e-110", "5e-324"}) {
    write_bytes(path("speck.off"), std::string("OFF\n3 1 0\n0 0 0\n") + side + " 0 0\n0 " + side + " 0\n3 0 1 2\n");
    expect_clean_failure(run_resecto_bounded("collide --tissue " + arg("p.off") + " --tool " + arg("speck.off") + " --poses " + arg("pose.txt")),
                         "the exact triangle tests need a span from 1e-60 to 1e+60", side);
  }
  write_bytes(path("speck.off"), "OFF\n3 1 0\n0 0 0\n1e-50 0 0\n0 1e-50 0\n3 0 1 2\n");
  const CommandOutput run = run_resecto_bounded("collide --tissue " + arg("p.off") + " --tool " + arg("speck.off") + " --poses " + arg("pose.txt"));
  EXPECT_EQ(run.exit_code, 0) << run.err;
}

TEST_F(HostileInput, ProcedureFromADeviceIsRefusedAtOnce) {
  expect_clean_failure(run_resecto_bounded("run --headless --procedure /dev/urandom"), "/dev/urandom: not a regular file", "urandom");
  write_bytes(path("past_travel.txt"), "0 0 0 0 230.0001 0 0 0\n");
  expect_clean_failure(run_resecto_bounded("run --headless --procedure " + arg("past_travel.txt")),
                       "insertion_mm 230.0001 is outside [0, 230]", "230.0001");
}

TEST_F(HostileInput, ObjAndStlFacesAndNumbersAreNeverDroppedSilently) {
  const std::string vertices = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  const std::pair<std::string, std::string> cases[] = {
      {vertices + "f 2 3 4000000000\n", "vertex index '4000000000' is not in"},
      {vertices + "f a b c\n", "corner 'a' is not a vertex index"},
      {vertices + "f 0 0 0\n", "vertex index '0' is not in"},
      {"v nan nan nan\n" + vertices + "f 1 2 3\n", "1:3: 'nan' is not a finite number"},
      {vertices + "f 1 2 3\nf 1 2 7\n", "face 1 refers to vertex 7, but the file has 3 vertices"},
  };
  for (std::size_t i = 0; i < std::size(cases); ++i) {
    const std::string name = "bad" + std::to_string(i) + ".obj";
    write_bytes(path(name), cases[i].first);
    expect_clean_failure(run_resecto_bounded("mesh check " + arg(name)), cases[i].second, cases[i].first);
  }
  write_bytes(path("nan.stl"), "solid t\nfacet normal 0 0 1\nouter loop\nvertex nan nan nan\nvertex 1 0 0\nvertex 0 1 0\n"
                               "endloop\nendfacet\nendsolid t\n");
  expect_clean_failure(run_resecto_bounded("mesh check " + arg("nan.stl")), "nan.stl:4:8: 'nan' is not a finite number", "STL nan");
  std::string billion(84, '\0');
  const std::uint32_t claimed = 1'000'000'000;
  for (int b = 0; b < 4; ++b) billion[static_cast<std::size_t>(80 + b)] = static_cast<char>((claimed >> (8 * b)) & 0xff);
  write_bytes(path("billion.stl"), billion);
  expect_clean_failure(run_resecto_bounded("mesh check " + arg("billion.stl")), "binary STL declares 1000000000 triangles", "1e9 STL");
  write_bytes(path("nan_vertex.off"), "OFF\n4 4 0\nnan 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  expect_clean_failure(run_resecto_bounded("mesh check " + arg("nan_vertex.off")), "nan_vertex.off:3:1: 'nan' is not a finite number",
                       "OFF nan vertex");
}

TEST_F(HostileInput, SurfacesThatCrashedOrExhaustedTetraAndCollideAreHandled) {
  const std::string faces = "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  const auto corner = [&](const std::string& side, const std::string& extra_vertex = "") {
    return "OFF\n" + std::string(extra_vertex.empty() ? "4" : "5") + " 4 0\n0 0 0\n" + side + " 0 0\n0 " + side + " 0\n0 0 " + side +
           "\n" + extra_vertex + faces;
  };
  // An unused vertex outside the hull crashed TetGen (139); it is now no part of the surface.
  write_bytes(path("unused.off"), corner("10", "50 50 50\n"));
  CommandOutput run = run_resecto_bounded("mesh tetra " + arg("unused.off") + " -o " + arg("unused.vtk"));
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("1 tetrahedra over 4 nodes"), std::string::npos) << run.out;
  run = run_resecto_bounded("mesh check " + arg("unused.off"));
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("unused vertices  1"), std::string::npos) << run.out;
  // A 0 mm capsule asked for 16.8 GB, a 10 m tetrahedron as much: now within 512 MB and 5 s.
  write_bytes(path("tet10.off"), corner("10"));
  write_bytes(path("tet1e4.off"), corner("1e4"));
  EXPECT_EQ(run_resecto_bounded("mesh tetra " + arg("tet10.off") + " --capsule 0 -o " + arg("t.vtk")).exit_code, 0);
  EXPECT_EQ(run_resecto_bounded("mesh tetra " + arg("tet1e4.off") + " -o " + arg("t.vtk")).exit_code, 0);
  // Quality bounds TetGen cannot reach used to refine forever; the bounded refinement says so.
  expect_clean_failure(run_resecto_bounded("mesh tetra " + arg("p.off") + " --min-dihedral 30 -o " + arg("q.vtk"), 30.0),
                       "without reaching a radius-edge ratio of 1.8 and dihedral angles of 30 deg (reached", "--min-dihedral 30");
  EXPECT_FALSE(std::filesystem::exists(path("q.vtk")));
  // Coordinates of 1e150 hung the clearance grid, 1e300 took 7.5 GB: refused where they are read.
  write_bytes(path("huge_tool.off"), corner("1e150"));
  expect_clean_failure(run_resecto_bounded("collide --tissue " + arg("tet10.off") + " --tool " + arg("huge_tool.off") + " --poses " + arg("pose.txt")),
                       "huge_tool.off: vertex 1 has coordinate 1e+150 mm, beyond the ±1e+06 mm a surface may reach", "collide 1e150 tool");
  write_bytes(path("huge_tissue.off"), corner("1e300"));
  expect_clean_failure(run_resecto_bounded(collide_args(arg("huge_tissue.off"))), "huge_tissue.off: vertex 1 has coordinate 1e+300 mm",
                       "collide 1e300 tissue");
  expect_clean_failure(run_resecto_bounded("mesh check " + arg("huge_tissue.off")), "vertex 1 has coordinate 1e+300 mm", "mesh check 1e300");
}

TEST_F(HostileInput, CollideRefusesTruncatedMeshesInEveryFormat) {
  for (const char* format : {"off", "obj", "ply", "stl"}) {
    const std::string whole = "whole." + std::string(format);
    ASSERT_EQ(run_resecto("mesh prostate --triangles 1296 -o " + arg(whole)).exit_code, 0);
    const std::string bytes = read_text(path(whole));
    const std::string cut = "cut." + std::string(format);
    write_bytes(path(cut), bytes.substr(0, bytes.size() / 2 + 7));
    const CommandOutput run = run_resecto_bounded(collide_args(arg(cut)));
    expect_clean_failure(run, "cut." + std::string(format), format);
  }
  // A binary PLY cut inside its face list says so (it read as "has 3 corners (3 to 1024 are read)").
  std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                    "element face 4\nproperty list uchar int vertex_indices\nend_header\n";
  const float corners[4][3] = {{0, 0, 0}, {10, 0, 0}, {0, 10, 0}, {0, 0, 10}};
  ply.append(reinterpret_cast<const char*>(corners), sizeof corners);  // little-endian, as on every machine this builds for
  const std::int32_t faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (const auto& face : faces) ply.append(1, '\x03').append(reinterpret_cast<const char*>(face), sizeof face);
  write_bytes(path("tet.ply"), ply);
  EXPECT_EQ(run_resecto_bounded("mesh check " + arg("tet.ply")).exit_code, 0);
  write_bytes(path("cut_binary.ply"), ply.substr(0, ply.size() - 10));
  expect_clean_failure(run_resecto_bounded("mesh check " + arg("cut_binary.ply")), "face 3 vertex_indices has 3 items, but 2 bytes are left: the file is cut short",
                       "binary PLY cut in a face");
}

TEST_F(HostileInput, NumericOptionsRejectNanAndZeroDurations) {
  const std::pair<std::string, std::string> cases[] = {
      {"run --headless --seconds nan", "--seconds: 'nan' is not a finite number"},
      {"run --headless --seconds 0", "--seconds: 0 is outside (0, 86400]"},
      {"tissue indent --depth-mm nan", "--depth-mm: 'nan' is not a finite number"},
      {"device monitor --device emulator --seconds 0.1 --unplug nan", "--unplug: 'nan' is not a finite number"},
      {"mesh resectoscope --loop-travel 36.0001 -o " + arg("x.off"), "--loop-travel: 36.0001 is outside [0, 36]"},
      // The console's options are checked before any window opens.
      {"console --view-scale nan --frames 1", "--view-scale: 'nan' is not a finite number"},
      {"console --slow-frame-ms nan --frames 1", "--slow-frame-ms: 'nan' is not a finite number"},
      {"console --device keyboard --insertion-mm nan --frames 1", "--insertion-mm: 'nan' is not a finite number"},
      // Whole numbers in decimal digits only (audit 24, F11): 0x510 ran as 1296 triangles, and 1296.0
      // was refused as "not in range 200 to 5000000".
      {"mesh prostate --triangles 0x510 -o " + arg("x.off"), "--triangles: '0x510' is not a whole number of decimal digits"},
      {"mesh prostate --triangles 1296.0 -o " + arg("x.off"), "--triangles: '1296.0' is not a whole number of decimal digits"},
      {"run --headless --substeps 1e1", "--substeps: '1e1' is not a whole number of decimal digits"},
      {"run --headless --triangles 199", "--triangles: 199 is outside [200, 1000000]"},
      {"console --frames 99999999999999999999", "--frames: 99999999999999999999 is outside [1, 100000000]"},
  };
  for (const auto& [arguments, expected] : cases) expect_clean_failure(run_resecto_bounded(arguments), expected, arguments);
}

TEST_F(HostileInput, PosesMustBeRigidAndWithinReach) {
  write_bytes(path("mirror.txt"), "-1 0 0 0  0 1 0 0  0 0 1 0\n");
  expect_clean_failure(run_resecto_bounded(collide_args(arg("p.off"), "mirror.txt")),
                       "mirror.txt:1: the 3x3 rotation is a reflection", "det -1");
  write_bytes(path("far.txt"), "1 0 0 1e200  0 1 0 0  0 0 1 0\n");
  expect_clean_failure(run_resecto_bounded(collide_args(arg("p.off"), "far.txt")),
                       "far.txt:1: translation 1e+200 is outside", "1e200");
  // Lines ended by a lone CR (classic Mac OS) are lines, not one long line of 24 numbers (audit 24, F11).
  write_bytes(path("cr.txt"), "# two poses\r1 0 0 0  0 1 0 0  0 0 1 0\r1 0 0 0  0 1 0 0  0 0 1 1\r");
  const CommandOutput cr = run_resecto_bounded(collide_args(arg("p.off"), "cr.txt") + " --json");
  ASSERT_EQ(cr.exit_code, 0) << cr.err;
  EXPECT_NE(cr.out.find("\"poses\":2"), std::string::npos) << cr.out;
}

TEST_F(HostileInput, CalibrationInputsOutsideTheDeviceAreRefused) {
  // A valid file first, then each field pushed out of range.
  std::string sheath = "position_mm,potentiometer_counts\n";
  for (int i = 0; i <= 23; ++i) sheath += std::to_string(10 * i) + "," + std::to_string(3704 - 45 * i) + "\n";
  write_bytes(path("sheath.csv"), sheath);
  ASSERT_EQ(run_resecto("device calibrate --sheath " + arg("sheath.csv") + " -o " + arg("good.json")).exit_code, 0);
  nlohmann::json far = nlohmann::json::parse(read_text(path("good.json")));
  far["registration"]["translation_mm"][1] = 1e308;
  write_bytes(path("far.json"), far.dump());
  expect_clean_failure(run_resecto_bounded("run --headless --seconds 0.1 --calibration " + arg("far.json")),
                       "registration.translation_mm[1]: 1e+308 is outside [-1000, 1000] mm", "translation");
  // Audit 6, A: a sheath model reading every count off the travel, a misspelt key and a repeated one
  // were all run as if nothing were wrong.
  nlohmann::json off_travel = nlohmann::json::parse(read_text(path("good.json")));
  off_travel["sheath"]["offset_mm"] = -1e6;
  write_bytes(path("off_travel.json"), off_travel.dump());
  expect_clean_failure(run_resecto_bounded("device monitor --device emulator --seconds 0.1 --calibration " + arg("off_travel.json")),
                       "off_travel.json: sheath: potentiometer counts 0-4095 map to ", "offset -1e6");
  nlohmann::json misspelt = nlohmann::json::parse(read_text(path("good.json")));
  misspelt["sheath"]["gain"] = -0.25;
  write_bytes(path("misspelt.json"), misspelt.dump());
  expect_clean_failure(run_resecto_bounded("run --headless --seconds 0.1 --calibration " + arg("misspelt.json")),
                       "misspelt.json: sheath.gain: unknown key (sheath holds gain_mm_per_count, offset_mm, min_mm, max_mm)", "misspelt");
  const std::string good_text = read_text(path("good.json"));
  write_bytes(path("twice.json"), good_text.substr(0, good_text.rfind('}')) + ", \"version\": 1}");
  expect_clean_failure(run_resecto_bounded("run --headless --seconds 0.1 --calibration " + arg("twice.json")),
                       "twice.json: version: the key appears twice in its object", "repeated key");

  const std::pair<std::string, std::string> sheaths[] = {
      {"position_mm,potentiometer_counts\n0,100\n10,5000\n", "potentiometer_counts 5000 is outside [0, 4095]"},
      {"position_mm,potentiometer_counts\n0,100\n-10,200\n", "position_mm -10 is outside [0, 230]"},
      {"position_mm,potentiometer_counts\nnan,100\nnan,200\n", "column position_mm: not a finite number: 'nan'"},
      // Audit 24: a mistyped row (rms residual 64 mm) and two rows 1 mm apart were fitted and written.
      {"position_mm,potentiometer_counts\n0,3686\n230,2646\n115,4000\n", "by 86.187 mm, more than 2.000: a row is misread or mistyped"},
      {"position_mm,potentiometer_counts\n10,3640\n11,3636\n", "the measurements cover only 10.000 to 11.000 mm"},
      // Audit 6, A: a ';'-separated export was "column position_mm;potentiometer_counts: not a number".
      {"position_mm;potentiometer_counts\n0;3686\n230;2646\n",
       "bad_sheath.csv:1: the header has no columns 'position_mm', 'potentiometer_counts'"},
  };
  for (const auto& [csv, expected] : sheaths) {
    write_bytes(path("bad_sheath.csv"), csv);
    expect_clean_failure(run_resecto_bounded("device calibrate --sheath " + arg("bad_sheath.csv") + " -o " + arg("out.json")), expected, csv);
  }
  write_bytes(path("bad_hall.csv"), "position_mm,hall_sum_counts\n0,100\n1e9,200\n");
  expect_clean_failure(run_resecto_bounded("device calibrate --hall " + arg("bad_hall.csv") + " -o " + arg("out.json")),
                       "position_mm 1e+09 is outside [0, 36.5]", "hall 1e9");
  EXPECT_FALSE(std::filesystem::exists(path("out.json")));
}

TEST_F(HostileInput, LandmarksMustBeFiniteAndDistinct) {
  const nlohmann::json good = nlohmann::json::parse(read_text(path("p.landmarks.json")));
  const char* expected[] = {"apex and bladder_neck are less than 1 mm apart", "channel_axis.apex[2] 1e+308 is outside",
                            "units: \"m\" (only \"mm\" is read"};
  for (int variant = 0; variant < 3; ++variant) {
    const auto dir = scratch_directory("hostile_landmarks_" + std::to_string(variant));
    std::filesystem::copy_file(path("p.off"), dir / "p.off");
    nlohmann::json bad = good;
    if (variant == 0) bad["channel_axis"]["bladder_neck"] = bad["channel_axis"]["apex"];
    if (variant == 1) bad["channel_axis"]["apex"][2] = 1e308;
    if (variant == 2) bad["units"] = "m";  // read as millimetres, it was a thousandfold off (audit 29, F13)
    write_bytes(dir / "p.landmarks.json", bad.dump());
    expect_clean_failure(run_resecto_bounded("mesh tetra " + (dir / "p.off").string() + " -o " + (dir / "t.vtk").string()), expected[variant],
                         bad.dump());
    EXPECT_FALSE(std::filesystem::exists(dir / "t.vtk"));
  }
}

TEST_F(HostileInput, FoldersAndDevicesAreNamedAndNeverReplaced) {
  std::filesystem::create_directories(path("folder.off"));
  expect_clean_failure(run_resecto_bounded("mesh check " + arg("folder.off")), "folder.off: is a folder, not a file", "folder input");
  expect_clean_failure(run_resecto_bounded("mesh prostate --triangles 1296 -o " + arg("folder.off")), "folder.off: is a folder; not replaced",
                       "folder output");
  EXPECT_TRUE(std::filesystem::is_directory(path("folder.off")));
  expect_clean_failure(run_resecto_bounded("run --headless --triangles 1296 --seconds 0.2 --trace /dev/null"),
                       "/dev/null: is not a regular file", "--trace /dev/null");
  write_bytes(path("sheath2.csv"), "position_mm,potentiometer_counts\n0,3704\n100,3250\n200,2795\n");
  expect_clean_failure(run_resecto_bounded("device calibrate --sheath " + arg("sheath2.csv") + " -o /dev/null"),
                       "/dev/null: is not a regular file", "calibrate -o /dev/null");
  struct stat null_node {};
  ASSERT_EQ(::stat("/dev/null", &null_node), 0);
  EXPECT_TRUE(S_ISCHR(null_node.st_mode)) << "/dev/null was replaced";
}

TEST_F(HostileInput, AFullStandardOutputIsAFailure) {
  expect_clean_failure(run_resecto_bounded("mesh check " + arg("p.off"), 5.0, 512, "/dev/full"), "cannot write to standard output",
                       "mesh check > /dev/full");
  expect_clean_failure(run_resecto_bounded(collide_args(arg("p.off")) + " --json", 5.0, 512, "/dev/full"),
                       "cannot write to standard output", "collide --json > /dev/full");
  expect_clean_failure(run_resecto_bounded("--help", 5.0, 512, "/dev/full"), "cannot write to standard output", "--help > /dev/full");
}

// Files saved by Windows editors and spreadsheets start with a UTF-8 byte-order mark: read as if it were not there.
TEST_F(HostileInput, AByteOrderMarkBeforeTextIsIgnored) {
  const std::string bom = "\xEF\xBB\xBF";
  std::ifstream in(path("p.off"), std::ios::binary);
  const std::string surface((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  write_bytes(path("bom.off"), bom + surface);
  write_bytes(path("bom_pose.txt"), bom + std::string(kIdentityPose));
  write_bytes(path("bom.proc"), bom + "0 0 0 0 125 0 0 0\n1 0 0 0 140 0 0 0\n");
  EXPECT_EQ(run_resecto_bounded("mesh check " + arg("bom.off")).exit_code, 0);
  const CommandOutput collide = run_resecto_bounded(collide_args(arg("bom.off"), "bom_pose.txt"));
  EXPECT_EQ(collide.exit_code, 0) << collide.err;
  const CommandOutput run = run_resecto_bounded("run --headless --triangles 1296 --procedure " + arg("bom.proc"), 60.0);
  EXPECT_EQ(run.exit_code, 0) << run.err;
}

// Audit 6, C: a UTF-16 procedure or pose file ("Unicode" in Windows editors) was reported as mojibake;
// procedure columns separated by commas were "found 1", while pose files took commas.
TEST_F(HostileInput, Utf16TextIsNamedAndProcedureColumnsTakeCommas) {
  std::string utf16 = "\xFF\xFE";
  for (const char c : std::string("0 0 0 0 125 0 0 0\n1 0 0 0 140 0 0 0\n")) utf16 += std::string{c, '\0'};
  write_bytes(path("utf16.proc"), utf16);
  expect_clean_failure(run_resecto_bounded("run --headless --procedure " + arg("utf16.proc")),
                       "utf16.proc: is UTF-16, not UTF-8 text; save it as UTF-8", "UTF-16 procedure");
  write_bytes(path("utf16_pose.txt"), "\xFE\xFF" + std::string(1, '\0') + "1");
  expect_clean_failure(run_resecto_bounded(collide_args(arg("p.off"), "utf16_pose.txt")), "utf16_pose.txt: is UTF-16, not UTF-8 text",
                       "UTF-16 poses");
  write_bytes(path("commas.proc"), "0.0, 0, 0, 0, 125, 0, 0, 0\n1.0,0,0,0,140,0,0,0\n");
  const CommandOutput commas = run_resecto_bounded("run --headless --triangles 1296 --procedure " + arg("commas.proc"), 60.0);
  EXPECT_EQ(commas.exit_code, 0) << commas.err;
}

/// A 256 KiB tmpfs, mounted for one test and filled to the last byte after the good files are in.
class FullDisk : public HostileInput {
 protected:
  void SetUp() override {
    disk_ = scratch_directory("hostile_full_disk");
    if (::mount("tmpfs", disk_.c_str(), "tmpfs", 0, "size=256k") != 0) {
      GTEST_SKIP() << "cannot mount a tmpfs here (needs root): the full-disk cases are not run";
    }
    mounted_ = true;
  }
  void TearDown() override {
    if (mounted_) ::umount2(disk_.c_str(), MNT_DETACH);
  }
  /// Fills the disk: a filler file grows until the file system refuses another byte.
  void fill() {
    std::FILE* filler = std::fopen((disk_ / "filler").c_str(), "wb");
    ASSERT_NE(filler, nullptr);
    const std::string block(512, 'x');
    while (std::fwrite(block.data(), 1, block.size(), filler) == block.size() && std::fflush(filler) == 0) {
    }
    std::fclose(filler);
    std::FILE* probe = std::fopen((disk_ / "probe").c_str(), "wb");
    if (probe != nullptr) {
      EXPECT_TRUE(std::fputc('x', probe) == EOF || std::fflush(probe) != 0) << "the disk is not full";
      std::fclose(probe);
      std::filesystem::remove(disk_ / "probe");
    }
  }
  std::string on_disk(const std::string& name) const { return (disk_ / name).string(); }

  std::filesystem::path disk_;
  bool mounted_ = false;
};

TEST_F(FullDisk, MeshWritersKeepTheGoodFileInEveryFormat) {
  for (const char* format : {"off", "obj", "ply", "stl"}) {
    const std::string name = "good." + std::string(format);
    ASSERT_EQ(run_resecto("mesh resectoscope -o " + on_disk(name)).exit_code, 0) << format;
  }
  fill();
  const std::set<std::string> before = listing(disk_);
  for (const char* format : {"off", "obj", "ply", "stl"}) {
    const std::string name = "good." + std::string(format);
    const std::string good = read_text(disk_ / name);
    expect_clean_failure(run_resecto_bounded("mesh prostate --triangles 8640 -o " + on_disk(name)), name + ": cannot write", name);
    expect_clean_failure(run_resecto_bounded("mesh resectoscope --loop-travel 20 -o " + on_disk(name)), name + ": cannot write", name);
    EXPECT_EQ(read_text(disk_ / name), good) << name << " was replaced";
  }
  EXPECT_EQ(listing(disk_), before) << "a temporary or partial file was left behind";
}

TEST_F(FullDisk, ReportsTracesPairsTetraAndRecordingsFailAndLeaveNothing) {
  write_bytes(disk_ / "old_report.json", "{\"previous\": true}\n");
  fill();
  const std::set<std::string> before = listing(disk_);
  expect_clean_failure(run_resecto_bounded("run --headless --triangles 1296 --seconds 0.3 --report " + on_disk("old_report.json"), 30.0),
                       "old_report.json: cannot write", "--report");
  EXPECT_EQ(read_text(disk_ / "old_report.json"), "{\"previous\": true}\n");
  expect_clean_failure(run_resecto_bounded("run --headless --triangles 1296 --seconds 0.3 --trace " + on_disk("trace.json"), 30.0),
                       "trace.json: cannot write", "--trace");
  expect_clean_failure(run_resecto_bounded(collide_args(arg("p.off")) + " --pairs " + on_disk("pairs.csv")), "pairs.csv: cannot write",
                       "--pairs");
  expect_clean_failure(run_resecto_bounded("mesh tetra " + arg("p.off") + " -o " + on_disk("t.vtk"), 30.0), "t.vtk: cannot write",
                       "mesh tetra");
  expect_clean_failure(run_resecto_bounded("device monitor --device emulator --seconds 0.5 --json --record " + on_disk("raw.txt")),
                       "raw.txt: cannot write", "--record");
  EXPECT_EQ(listing(disk_), before) << "a temporary or partial file was left behind";
}

}  // namespace
}  // namespace resecto::testing

// `resecto collide` through the command line: the contract's text, JSON and pairs CSV (checked
// against brute force on the same files), and one-line errors naming the poses line or the face.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "rtcore/collision/collide.h"
#include "rtcore/mesh/mesh_io.h"
#include "tests/console/run_resecto.h"

namespace resecto {
namespace {

using testing::read_text;
using testing::run_resecto;
using testing::scratch_directory;

struct Files {
  std::filesystem::path dir, tissue, tool, poses;
};

// The gland and the tool written by `resecto mesh` (millimetres), and poses that press the tool
// into the channel wall; poses 2 and 4 sit in the file behind a comment and a blank line.
Files make_files(const std::string& name) {
  Files f;
  f.dir = scratch_directory(name);
  f.tissue = f.dir / "gland.off";
  f.tool = f.dir / "tool.stl";
  f.poses = f.dir / "poses.txt";
  EXPECT_EQ(run_resecto("mesh prostate --triangles 1296 -o " + f.tissue.string()).exit_code, 0);
  EXPECT_EQ(run_resecto("mesh resectoscope -o " + f.tool.string()).exit_code, 0);
  std::ofstream out(f.poses);
  out << "# r00 r01 r02 tx r10 r11 r12 ty r20 r21 r22 tz (mm)\n"
      << "1 0 0 1.5 0 1 0 0 0 0 1 20\n"
      << "\n"
      << "0 -1 0 0 1 0 0 -2 0 0 1 30\n"
      << "1 0 0 0 0 1 0 0 0 0 1 -500\n"
      << "   0.9950041652780258 0 0.09983341664682815 0.5   0 1 0 1   -0.09983341664682815 0 0.9950041652780258 35\n";
  return f;
}

std::string common_args(const Files& f) {
  return "collide --tissue " + f.tissue.string() + " --tool " + f.tool.string() + " --poses " + f.poses.string();
}

TEST(CollideCommand, PairsCsvEqualsBruteForceOnTheSameFiles) {
  const Files f = make_files("collide_pairs");
  const auto pairs_path = f.dir / "pairs.csv";
  const auto result = run_resecto(common_args(f) + " --pairs " + pairs_path.string() + " --repeat 3");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("median"), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("p95"), std::string::npos) << result.out;

  const auto tissue = read_surface_mesh(f.tissue, 1.0);
  const auto tool = read_surface_mesh(f.tool, 1.0);
  ASSERT_TRUE(tissue.ok() && tool.ok());
  const double rotations[4][12] = {{1, 0, 0, 1.5, 0, 1, 0, 0, 0, 0, 1, 20},
                                   {0, -1, 0, 0, 1, 0, 0, -2, 0, 0, 1, 30},
                                   {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, -500},
                                   {0.9950041652780258, 0, 0.09983341664682815, 0.5, 0, 1, 0, 1, -0.09983341664682815, 0,
                                    0.9950041652780258, 35}};
  std::ostringstream expected;
  expected << "pose,tissue_face,tool_face\n";
  std::size_t total = 0;
  for (int p = 0; p < 4; ++p) {
    std::array<double, 12> row_major{};
    std::copy(rotations[p], rotations[p] + 12, row_major.begin());
    const RigidPose pose = from_row_major_3x4(row_major);
    for (const TrianglePair& pair : collide_brute_force(*tissue, *tool, pose)) {
      expected << p << ',' << pair.tissue << ',' << pair.tool << '\n';
      ++total;
    }
  }
  EXPECT_GT(total, 100u);
  EXPECT_EQ(read_text(pairs_path), expected.str());

  const auto json_run = run_resecto(common_args(f) + " --json");
  ASSERT_EQ(json_run.exit_code, 0) << json_run.err;
  const auto report = nlohmann::json::parse(json_run.out);
  EXPECT_EQ(report["tissue_triangles"], tissue->triangle_count());
  EXPECT_EQ(report["tool_triangles"], 488);
  EXPECT_EQ(report["poses"], 4);
  EXPECT_EQ(report["pairs"], total);
  EXPECT_GE(report["build_ms"].get<double>(), 0.0);
  EXPECT_LE(report["query_us"]["median"].get<double>(), report["query_us"]["p95"].get<double>());
}

// --sequence on consecutive frames (the tool advancing 0.2 mm a frame along the channel, pressed
// into the wall, turning slowly): the same pairs CSV as independent queries, and brute force's.
TEST(CollideCommand, SequenceGivesThePairsOfIndependentQueries) {
  Files f = make_files("collide_sequence");
  f.poses = f.dir / "frames.txt";
  std::vector<RigidPose> frames;
  {
    std::ofstream out(f.poses);
    out.precision(17);
    for (int k = 0; k < 40; ++k) {
      const double a = 0.01 * k;
      RigidPose pose;
      pose.rotation = rotation_about_z(a);
      pose.translation = Vec3{1.6, 0.3, 15.0 + 0.2 * k};
      frames.push_back(pose);
      const std::array<double, 12> row_major = to_row_major_3x4(pose);
      for (std::size_t e = 0; e < 12; ++e) out << row_major[e] << (e == 11 ? '\n' : ' ');
    }
  }
  const auto independent = f.dir / "independent.csv";
  const auto sequence = f.dir / "sequence.csv";
  ASSERT_EQ(run_resecto(common_args(f) + " --pairs " + independent.string()).exit_code, 0);
  const auto run = run_resecto(common_args(f) + " --sequence --repeat 2 --json --pairs " + sequence.string());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(nlohmann::json::parse(run.out)["sequence"], true);
  EXPECT_EQ(read_text(sequence), read_text(independent));

  const auto tissue = read_surface_mesh(f.tissue, 1.0);
  const auto tool = read_surface_mesh(f.tool, 1.0);
  ASSERT_TRUE(tissue.ok() && tool.ok());
  std::ostringstream expected;
  expected << "pose,tissue_face,tool_face\n";
  std::size_t total = 0;
  for (std::size_t p = 0; p < frames.size(); ++p) {
    for (const TrianglePair& pair : collide_brute_force(*tissue, *tool, frames[p])) {
      expected << p << ',' << pair.tissue << ',' << pair.tool << '\n';
      ++total;
    }
  }
  EXPECT_GT(total, 100u) << "the frames must press into the wall";
  EXPECT_EQ(read_text(sequence), expected.str());
}

// --method: the paper's dual descent and the tool field (the default) write the same pairs, and the
// report says which ran and what the tool's field cost.
TEST(CollideCommand, BothMethodsWriteTheSamePairs) {
  const Files f = make_files("collide_methods");
  const auto field = f.dir / "field.csv";
  const auto dual = f.dir / "dual.csv";
  const auto field_run = run_resecto(common_args(f) + " --json --pairs " + field.string());
  ASSERT_EQ(field_run.exit_code, 0) << field_run.err;
  const auto dual_run = run_resecto(common_args(f) + " --method dual-descent --json --pairs " + dual.string());
  ASSERT_EQ(dual_run.exit_code, 0) << dual_run.err;
  const auto field_report = nlohmann::json::parse(field_run.out);
  const auto dual_report = nlohmann::json::parse(dual_run.out);
  EXPECT_EQ(field_report["method"], "field");
  EXPECT_EQ(dual_report["method"], "dual-descent");
  EXPECT_GT(field_report["tool_field_ms"].get<double>(), 0.0);
  EXPECT_EQ(dual_report["tool_field_ms"].get<double>(), 0.0);
  EXPECT_GT(field_report["pairs"].get<std::size_t>(), 100u);
  EXPECT_EQ(read_text(field), read_text(dual));
  const auto unknown = run_resecto(common_args(f) + " --method fastest");
  EXPECT_NE(unknown.exit_code, 0);
  EXPECT_NE(unknown.err.find("--method"), std::string::npos) << unknown.err;
}

// --threads 2: each pose's query shared with a helper thread writes the one thread's pairs, with
// either method and as a sequence.
TEST(CollideCommand, TwoThreadsWriteTheOneThreadPairs) {
  const Files f = make_files("collide_threads");
  const auto one = f.dir / "one.csv";
  const auto two = f.dir / "two.csv";
  const auto two_dual = f.dir / "two_dual.csv";
  ASSERT_EQ(run_resecto(common_args(f) + " --pairs " + one.string()).exit_code, 0);
  const auto run = run_resecto(common_args(f) + " --threads 2 --repeat 3 --json --pairs " + two.string());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(nlohmann::json::parse(run.out)["threads"], 2);
  EXPECT_EQ(read_text(two), read_text(one));
  ASSERT_EQ(run_resecto(common_args(f) + " --threads 2 --method dual-descent --pairs " + two_dual.string()).exit_code, 0);
  EXPECT_EQ(read_text(two_dual), read_text(one));
  const auto two_sequence = f.dir / "two_sequence.csv";
  ASSERT_EQ(run_resecto(common_args(f) + " --threads 2 --sequence --repeat 2 --pairs " + two_sequence.string()).exit_code, 0);
  EXPECT_EQ(read_text(two_sequence), read_text(one));
  EXPECT_NE(run_resecto(common_args(f) + " --threads 3").exit_code, 0);
}

TEST(CollideCommand, MalformedPosesLineIsNamed) {
  const Files f = make_files("collide_bad_poses");
  std::ofstream(f.poses) << "# header\n1 0 0 0 0 1 0 0 0 0 1 0\n\n1 0 0 0 0 1 zero 0 0 0 1 0\n";
  auto result = run_resecto(common_args(f));
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.err.find("poses.txt:4:"), std::string::npos) << result.err;
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;

  std::ofstream(f.poses) << "1 0 0 0 0 1 0 0 0 0 1\n";
  result = run_resecto(common_args(f));
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.err.find("poses.txt:1: expected 12 numbers"), std::string::npos) << result.err;

  std::ofstream(f.poses) << "1 0 0 0 0 1 0 0 0 0 1 nan\n";
  result = run_resecto(common_args(f));
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.err.find("poses.txt:1:23: number 12 of 12, 'nan', is not finite"), std::string::npos) << result.err;

  // Decimal numbers only, whole words: strtod took "0x3" as 3 and "1.5abc" as 1.5 then "abc".
  for (const char* word : {"0x3", "1.5abc"}) {
    std::ofstream(f.poses) << "1 0 0 0 0 1 0 0 0 0 1 " << word << "\n";
    result = run_resecto(common_args(f));
    EXPECT_NE(result.exit_code, 0);
    EXPECT_NE(result.err.find(std::string("poses.txt:1:23: '") + word + "' is not a number"), std::string::npos) << result.err;
  }
  std::ofstream(f.poses) << "1,0,0,0, 0,1,0,0, 0,0,1,0.5\n";  // commas still separate
  EXPECT_EQ(run_resecto(common_args(f)).exit_code, 0);
  // A mesh too small (or large) for a double's products is refused, not answered wrongly (audit 32, F7).
  std::ofstream(f.dir / "tiny.off") << "OFF\n4 4 0\n0 0 0\n1e-150 0 0\n0 1e-150 0\n0 0 1e-150\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  std::ofstream(f.poses) << "1 0 0 0 0 1 0 0 0 0 1 0\n";
  result = run_resecto("collide --tissue " + f.tissue.string() + " --tool " + (f.dir / "tiny.off").string() + " --poses " + f.poses.string());
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.err.find("spans 1e-150 units; the exact triangle tests need a span from 1e-60 to 1e+60"), std::string::npos) << result.err;
  // A comment may follow the numbers, as in procedure files (audit 32, F12).
  std::ofstream(f.poses) << "# rest\n1 0 0 0 0 1 0 0 0 0 1 0.5  # on the wall\n1 0 0 0 0 1 0 0 0 0 1 0.6#\n";
  result = run_resecto(common_args(f));
  EXPECT_EQ(result.exit_code, 0) << result.err;

  std::ofstream(f.poses) << "2 0 0 0 0 1 0 0 0 0 1 0\n";
  result = run_resecto(common_args(f));
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.err.find("poses.txt:1: the 3x3 rotation is not orthonormal"), std::string::npos) << result.err;
}

TEST(CollideCommand, MalformedMeshNamesTheFace) {
  const Files f = make_files("collide_bad_mesh");
  const auto bad = f.dir / "bad.off";
  std::ofstream(bad) << "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 9\n";
  const auto result = run_resecto("collide --tissue " + bad.string() + " --tool " + f.tool.string() + " --poses " + f.poses.string());
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.err.find("face 1"), std::string::npos) << result.err;
}

TEST(CollideCommand, MissingArgumentsFailWithHelpAvailable) {
  // A command line that cannot be parsed is a usage error, exit 2, whatever CLI11 calls it.
  const auto missing_file = run_resecto("collide --tissue nowhere.off");
  EXPECT_EQ(missing_file.exit_code, 2);
  EXPECT_NE(missing_file.err.find("nowhere.off"), std::string::npos) << missing_file.err;
  EXPECT_EQ(run_resecto("collide --tissue").exit_code, 2);
  EXPECT_EQ(run_resecto("collide --repeat 0").exit_code, 2);
  EXPECT_EQ(run_resecto("no-such-command").exit_code, 2);
  const auto help = run_resecto("collide --help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("--poses"), std::string::npos);
}

}  // namespace
}  // namespace resecto

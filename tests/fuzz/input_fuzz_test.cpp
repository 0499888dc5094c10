// Every reader of outside input under the mutation driver: the four mesh formats, tool poses,
// procedures, calibration JSON and CSV (through the fits), landmarks, and HID reports. Each input
// must give a value that keeps the reader's promises or one error line naming the source; a crash,
// an out-of-bounds access or undefined behaviour is caught by the sanitizers (CI runs this suite
// under the asan preset), an oversized allocation by the address-space cap set below.
// RESECTO_FUZZ_INPUTS=100000 runs the full campaign; the everyday suite runs 10,000 per target.
#include <gtest/gtest.h>

#include <sys/resource.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "console/commands/pose_file.h"
#include "device/calibration/calibration.h"
#include "device/calibration/calibration_csv.h"
#include "device/calibration/calibration_fit.h"
#include "device/link/report_decoder.h"
#include "resecto/lp3500_protocol.h"
#include "rtcore/anatomy/landmarks_file.h"
#include "rtcore/anatomy/prostate.h"
#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/base/text_file.h"
#include "rtcore/mesh/mesh_io.h"
#include "rtcore/mesh/mesh_parse.h"
#include "rtcore/scenes/procedure.h"
#include "tests/fuzz/mutator.h"

namespace resecto::fuzz {
namespace {

constexpr std::size_t kEverydayInputs = 10000;

/// Without a sanitizer, an allocation a header talked the reader into fails at 2 GiB of address
/// space instead of exhausting the machine (ASan reserves terabytes, so it keeps its own checks).
[[maybe_unused]] const bool kAddressSpaceCapped = [] {
#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
  const rlimit cap{rlim_t{2} << 30, rlim_t{2} << 30};
  return ::setrlimit(RLIMIT_AS, &cap) == 0;
#else
  return false;
#endif
}();

/// A failure must be one line that names where it comes from.
void expect_one_line_error(const std::string& error, const std::string& source, const std::string& input) {
  EXPECT_FALSE(error.empty());
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  if (!source.empty()) {
    EXPECT_NE(error.find(source), std::string::npos) << error << "\ninput of " << input.size() << " bytes";
  }
}

/// Runs `check` on `count` mutated inputs and prints the count and time, as the closing note reports.
void campaign(const char* target, std::vector<std::string> seeds, std::uint64_t seed, const std::function<void(const std::string&)>& check) {
  for (const std::string& s : seeds) check(s);  // the seeds themselves first
  Mutator mutator(std::move(seeds), seed);
  const std::size_t count = input_count(kEverydayInputs);
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < count; ++i) {
    const std::string input = mutator.next();
    check(input);
    if (::testing::Test::HasFailure()) {
      ADD_FAILURE() << target << ": input " << i << " (seed " << seed << ") failed";
      return;
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("[fuzz] %-12s %zu inputs in %.1f s\n", target, count, seconds);
}

/// The bytes `write_surface_mesh` writes for `mesh` in `extension`'s format.
std::string written_mesh(const TriangleMesh& mesh, const std::string& extension) {
  const auto dir = std::filesystem::temp_directory_path() / ("resecto_fuzz_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto path = dir / ("seed" + extension);
  EXPECT_TRUE(write_surface_mesh(path, mesh).ok());
  Result<std::string> bytes = read_text_file(path);
  std::filesystem::remove_all(dir);
  return bytes ? *bytes : std::string();
}

std::vector<std::string> mesh_seeds(MeshFormat format) {
  const TriangleMesh prostate = generate_prostate(200).surface;
  const TriangleMesh tool = combined_resectoscope_mesh(generate_resectoscope());
  switch (format) {
    case MeshFormat::off:
      return {written_mesh(prostate, ".off"), written_mesh(tool, ".off"),
              "OFF\n# a tetrahedron\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3 255 0 0\n3 0 3 2\n3 1 2 3\n"};
    case MeshFormat::obj:
      return {written_mesh(prostate, ".obj"), "o t\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvn 0 0 1\nf 1//1 3//1 2//1\nf 1/1 2/1 4/1\nf -4 -1 -2\nf 2 3 4\n"};
    case MeshFormat::ply: {
      std::string binary = "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                           "element face 4\nproperty list uchar int vertex_indices\nend_header\n";
      const float points[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
      binary.append(reinterpret_cast<const char*>(points), sizeof points);
      const int faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
      for (const auto& f : faces) {
        binary.push_back('\3');
        binary.append(reinterpret_cast<const char*>(f), sizeof f);
      }
      return {written_mesh(prostate, ".ply"), binary,
              "ply\nformat ascii 1.0\ncomment t\nelement vertex 4\nproperty double x\nproperty double y\nproperty double z\n"
              "element face 4\nproperty list uchar uint vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"};
    }
    case MeshFormat::stl:
      return {written_mesh(prostate, ".stl"),
              "solid t\nfacet normal 0 0 -1\nouter loop\nvertex 0 0 0\nvertex 0 1 0\nvertex 1 0 0\nendloop\nendfacet\n"
              "facet normal 0 -1 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 0 1\nendloop\nendfacet\nendsolid t\n"};
  }
  return {};
}

/// A parsed mesh keeps the reader's promises: finite positions, every corner a vertex.
void fuzz_mesh(const char* target, MeshFormat format, std::uint64_t seed) {
  campaign(target, mesh_seeds(format), seed, [format](const std::string& input) {
    Result<TriangleMesh> mesh = parse_surface_mesh(input, format, "fuzz.mesh", 1.0);
    if (!mesh) return expect_one_line_error(mesh.error(), "fuzz.mesh", input);
    EXPECT_FALSE(mesh->triangles.empty());
    for (const Vec3& p : mesh->positions) ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
    for (const Triangle& t : mesh->triangles) {
      for (std::uint32_t v : t) ASSERT_LT(v, mesh->positions.size());
    }
  });
}

TEST(Fuzz, OffReader) { fuzz_mesh("off", MeshFormat::off, 1); }
TEST(Fuzz, ObjReader) { fuzz_mesh("obj", MeshFormat::obj, 2); }
TEST(Fuzz, PlyReader) { fuzz_mesh("ply", MeshFormat::ply, 3); }
TEST(Fuzz, StlReader) { fuzz_mesh("stl", MeshFormat::stl, 4); }

TEST(Fuzz, Poses) {
  campaign("poses", {"1 0 0 0  0 1 0 0  0 0 1 0\n# comment\n\n0 -1 0 5, 1 0 0 -2.5, 0 0 1 100\n", "1 0 0 1e5 0 1 0 0 0 0 1 0\r\n"}, 5,
           [](const std::string& input) {
             Result<std::vector<RigidPose>> poses = cli::parse_poses(input, "fuzz.poses");
             if (!poses) return expect_one_line_error(poses.error(), "fuzz.poses", input);
             for (const RigidPose& pose : *poses) {
               for (int i = 0; i < 3; ++i) ASSERT_LE(std::abs(pose.translation[i]), cli::kMaxPoseTranslation);
             }
           });
}

TEST(Fuzz, Procedures) {
  campaign("procedures",
           {"# t yaw pitch roll insertion loop cut coag\n0 0 0 0 125 0 0 0\n1.5 0 0 0 158 0 0 0\n4.6 0.6 0 90 168 12 0 0\n5 1 0 90 168 12 1 0\n"
            "6.8 0 0 -90 168 1 0 1\n10 0 0 0 125 0 0 0\n"},
           6, [](const std::string& input) {
             Result<Procedure> procedure = parse_procedure(input, "fuzz.procedure");
             if (!procedure) return expect_one_line_error(procedure.error(), "fuzz.procedure", input);
             ASSERT_FALSE(procedure->keyframes.empty());
             for (std::size_t k = 1; k < procedure->keyframes.size(); ++k) {
               ASSERT_GT(procedure->keyframes[k].time_s, procedure->keyframes[k - 1].time_s);
             }
             const ProcedureKeyframe middle = procedure->sample(0.5 * procedure->keyframes.back().time_s);
             ASSERT_TRUE(std::isfinite(middle.insertion_mm) && std::isfinite(middle.roll_deg));
           });
}

TEST(Fuzz, CalibrationJson) {
  campaign("calibration", {device::calibration_to_json(device::default_calibration())}, 7, [](const std::string& input) {
    Result<device::Calibration> calibration = device::parse_calibration(input, "fuzz.json");
    if (!calibration) return expect_one_line_error(calibration.error(), "fuzz.json", input);
    for (double t : calibration->translation_mm) ASSERT_LE(std::abs(t), 1000.0);
  });
}

TEST(Fuzz, CalibrationCsv) {
  std::string sheath = "position_mm,potentiometer_counts\n";
  for (int i = 0; i <= 23; ++i) sheath += std::to_string(10 * i) + "," + std::to_string(3704 - 45 * i) + "\n";
  std::string hall = "# caliper sweep\nposition_mm,hall_a_counts,hall_b_counts\n";
  for (int i = 0; i <= 36; ++i) hall += std::to_string(i) + "," + std::to_string(2000 + 30 * i) + "," + std::to_string(1500 + 10 * i) + "\n";
  campaign("csv", {sheath, hall, "position_mm,hall_sum_counts\n0,3000\n18,4000\n36.5,5000\n"}, 8, [](const std::string& input) {
    Result<device::NumericCsv> csv = device::parse_numeric_csv(input, "fuzz.csv");
    if (!csv) return expect_one_line_error(csv.error(), "fuzz.csv", input);
    for (const auto& row : csv->rows) {
      for (double v : row) ASSERT_TRUE(std::isfinite(v));
    }
    if (auto samples = device::sheath_samples(*csv, "fuzz.csv")) {
      if (auto fit = device::fit_sheath(*samples, "fuzz.csv"); !fit) expect_one_line_error(fit.error(), "fuzz.csv", input);
    }
    if (auto samples = device::hall_samples(*csv, "fuzz.csv")) {
      if (auto fit = device::fit_hall_table(*samples, "fuzz.csv"); !fit) expect_one_line_error(fit.error(), "fuzz.csv", input);
    }
  });
}

TEST(Fuzz, Landmarks) {
  campaign("landmarks", {landmarks_to_json(generate_prostate(200))}, 9, [](const std::string& input) {
    Result<std::pair<Vec3, Vec3>> axis = parse_channel_axis(input, "fuzz.landmarks.json");
    if (!axis) return expect_one_line_error(axis.error(), "fuzz.landmarks.json", input);
    ASSERT_GE(length(axis->second - axis->first), kMinChannelLengthMm * 1e-3);
  });
}

TEST(Fuzz, HidReports) {
  lp3500_input_report report{};
  report.sequence = 77;
  report.device_time_us = 123456;
  report.encoder_counts[0] = -300;
  report.sheath_um = 150000;
  report.loop_um = 12000;
  report.pedals = 1;
  std::array<std::uint8_t, LP3500_INPUT_REPORT_SIZE> input{};
  lp3500_pack_input_report(&report, input.data());
  lp3500_identity identity{};
  identity.firmware_major = 1;
  identity.report_rate_hz = 1000;
  std::array<std::uint8_t, LP3500_IDENTITY_REPORT_SIZE> id_bytes{};
  lp3500_pack_identity(&identity, id_bytes.data());
  const auto to_string = [](const auto& bytes) { return std::string(bytes.begin(), bytes.end()); };
  const JointCalibration joints;
  campaign("hid", {to_string(input), to_string(id_bytes)}, 10, [&joints](const std::string& bytes) {
    const std::span<const std::uint8_t> span(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    const DecodedReport decoded = decode_input_report(span, joints);
    if (decoded.valid) {
      ASSERT_EQ(bytes.size(), std::size_t{LP3500_INPUT_REPORT_SIZE});
      ASSERT_TRUE(std::isfinite(decoded.sample.joints.insertion_m) && std::isfinite(decoded.sample.joints.yaw_rad));
    }
    lp3500_identity id{};
    (void)lp3500_unpack_identity(span.data(), span.size(), &id);
    lp3500_calibration board{};
    (void)lp3500_unpack_calibration(span.data(), span.size(), &board, nullptr);
  });
}

}  // namespace
}  // namespace resecto::fuzz

// `resecto collide`: the collision query between a tissue mesh and a tool mesh over a
// file of tool poses, with the pairs found and the query timings (DESIGN.md "Contracts").
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "console/commands/checked_options.h"
#include "console/commands/command_registry.h"
#include "console/commands/pose_file.h"
#include "rtcore/base/atomic_file.h"
#include "rtcore/base/checked_number.h"
#include "rtcore/base/quantile.h"
#include "rtcore/base/text_file.h"
#include "rtcore/collision/collide.h"
#include "rtcore/collision/parallel_collider.h"
#include "rtcore/mesh/mesh_io.h"

namespace resecto::cli {
namespace {

struct CollideOptions {
  std::string tissue;
  std::string tool;
  std::string poses;
  std::string pairs;
  int repeat = 1;
  bool json = false;
  bool sequence = false;  // the poses are consecutive frames: each query reuses the previous one's work
  int threads = 1;        // 2: each query (or sequence) is shared with a helper thread
  std::string method = "field";
};

// Units as in the file: the query is scale-free, so the meshes and poses are read unconverted.
constexpr double kFileUnits = 1.0;

TriangleMesh read_mesh_or_fail(const std::string& path) {
  Result<TriangleMesh> mesh = read_surface_mesh(path, kFileUnits);
  if (!mesh) fail(mesh.error());
  // Scale-free, but within a double's range: the exact triangle tests multiply up to four coordinate
  // differences, which underflowed at spans of 1e-148 and missed or invented pairs (audit 32, F7).
  if (!mesh->positions.empty()) {
    const Aabb box = bounding_box(*mesh);
    const Vec3 extent = box.max - box.min;
    const double span = std::max({extent.x, extent.y, extent.z});
    constexpr double kSmallestSpan = 1e-60, kLargestSpan = 1e60;
    if (!(span >= kSmallestSpan && span <= kLargestSpan)) {
      fail(path + ": spans " + exact_number(span) + " units; the exact triangle tests need a span from 1e-60 to 1e+60 (rescale the mesh)");
    }
  }
  return std::move(mesh).value();
}

std::vector<RigidPose> read_poses_or_fail(const std::string& path) {
  Result<std::string> text = read_utf8_text_file(path, " the poses file");
  if (!text) fail(text.error());
  Result<std::vector<RigidPose>> poses = parse_poses(*text, path);
  if (!poses) fail(poses.error());
  return std::move(poses).value();
}

void run_collide(const CollideOptions& options) {
  using Clock = std::chrono::steady_clock;
  // Checked before the work: a pairs file that names an input would destroy it, and one whose
  // folder is missing would be found out only after every query had run.
  if (!options.pairs.empty()) {
    const std::filesystem::path inputs[] = {options.tissue, options.tool, options.poses};
    if (Status ok = check_output_path(options.pairs, inputs); !ok) fail(ok.error());
  }
  const TriangleMesh tissue = read_mesh_or_fail(options.tissue);
  const TriangleMesh tool = read_mesh_or_fail(options.tool);
  const std::vector<RigidPose> poses = read_poses_or_fail(options.poses);

  const bool dual = options.method == "dual-descent";
  const auto build_start = Clock::now();
  SphereTree tissue_tree;
  SphereTree tool_tree;
  tissue_tree.set_slabs(dual);  // the tool field reads the tissue's spheres alone
  tissue_tree.build(tissue);
  tool_tree.build(tool);
  const double build_ms = std::chrono::duration<double, std::milli>(Clock::now() - build_start).count();

  const CollisionMethod method = dual ? CollisionMethod::kDualDescent : CollisionMethod::kToolField;
  Collider collider;
  collider.set_method(method);
  std::unique_ptr<ParallelCollider> shared;  // --threads 2
  if (options.threads > 1) {
    shared = std::make_unique<ParallelCollider>(options.threads);
    shared->set_method(method);
  }
  double field_ms = 0.0;  // the dual descent builds no field
  if (!dual) {
    const auto field_start = Clock::now();
    if (shared) {
      shared->prepare_tool(tool);
    } else {
      collider.prepare_tool(tool);
    }
    field_ms = std::chrono::duration<double, std::milli>(Clock::now() - field_start).count();
  }
  const auto reserve = [&](std::size_t pairs) {
    collider.reserve(static_cast<std::int32_t>(pairs), static_cast<std::int32_t>(4 * pairs));
    if (shared) shared->reserve(static_cast<std::int32_t>(pairs), static_cast<std::int32_t>(4 * pairs));
  };
  reserve(1 << 16);
  std::vector<std::vector<TrianglePair>> found(poses.size());
  std::vector<double> times_us;
  times_us.reserve(poses.size() * static_cast<std::size_t>(options.repeat));
  std::size_t most_pairs = 1 << 16;
  const auto query = [&](const RigidPose& pose) {
    if (shared) {
      return options.sequence ? shared->collide_sequence(tissue_tree, tissue, tool_tree, tool, pose)
                              : shared->collide(tissue_tree, tissue, tool_tree, tool, pose);
    }
    return options.sequence ? collider.collide_sequence(tissue_tree, tissue, tool_tree, tool, pose)
                            : collider.collide(tissue_tree, tissue, tool_tree, tool, pose);
  };
  const auto pairs = [&] { return shared ? shared->pairs() : collider.pairs(); };
  // The work behind the timings, summed over the first repeat (one thread: the shared query's
  // counters are split between its two Colliders).
  CollisionStats work;
  std::size_t near_leaves = 0;
  for (int r = 0; r < options.repeat; ++r) {
    collider.reset_sequence();  // every repeat runs the sequence from its first frame
    if (shared) shared->reset_sequence();
    for (std::size_t p = 0; p < poses.size(); ++p) {
      auto start = Clock::now();
      while (!query(poses[p])) {
        most_pairs *= 4;  // more pairs than room: grow (off the timed path) and run this pose again
        reserve(most_pairs);
        collider.reset_sequence();
        if (shared) shared->reset_sequence();
        start = Clock::now();
      }
      times_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count());
      if (r == 0) {
        found[p].assign(pairs().begin(), pairs().end());
        const CollisionStats& s = collider.stats();
        work.sphere_tests += s.sphere_tests;
        work.front_kept += s.front_kept;
        work.front_renewed += s.front_renewed;
        work.leaf_pairs += s.leaf_pairs;
        work.triangle_tests += s.triangle_tests;
        near_leaves += collider.tissue_leaves().size();
      }
    }
  }
  // A count of the first repeat, averaged over its queries.
  const auto per_query = [&](auto total) { return static_cast<double>(total) / static_cast<double>(poses.size()); };
  std::size_t total_pairs = 0;
  for (const auto& f : found) total_pairs += f.size();

  if (!options.pairs.empty()) {
    std::string csv = "pose,tissue_face,tool_face\n";
    for (std::size_t p = 0; p < found.size(); ++p) {
      for (const TrianglePair& pair : found[p]) csv += std::to_string(p) + ',' + std::to_string(pair.tissue) + ',' + std::to_string(pair.tool) + '\n';
    }
    if (Status written = write_file_atomically(options.pairs, csv); !written) fail(written.error());
  }

  std::sort(times_us.begin(), times_us.end());
  const double median = sorted_quantile(times_us, 0.5);
  const double p95 = sorted_quantile(times_us, 0.95);
  if (options.json) {
    nlohmann::json report = {
        {"tissue_triangles", tissue.triangle_count()},
        {"tool_triangles", tool.triangle_count()},
        {"tissue_leaves", tissue_tree.leaf_count()},
        {"tool_leaves", tool_tree.leaf_count()},
        {"poses", poses.size()},
        {"repeat", options.repeat},
        {"sequence", options.sequence},
        {"threads", options.threads},
        {"method", options.method},
        {"pairs", total_pairs},
        {"build_ms", build_ms},
        {"tool_field_ms", field_ms},
        {"query_us", {{"median", median}, {"p95", p95}, {"max", times_us.back()}}},
    };
    if (!shared) {
      report["work_per_query"] = {{"bound_tests", per_query(work.sphere_tests)}, {"near_leaves", per_query(near_leaves)},
                                  {"leaf_candidates", per_query(work.leaf_pairs)}, {"triangle_tests", per_query(work.triangle_tests)},
                                  {"front_kept", per_query(work.front_kept)}, {"front_renewed", per_query(work.front_renewed)}};
    }
    std::printf("%s\n", report.dump().c_str());
    return;
  }
  std::printf("tissue triangles  %zu (%d leaf spheres)\n", tissue.triangle_count(), tissue_tree.leaf_count());
  std::printf("tool triangles    %zu (%d leaf spheres)\n", tool.triangle_count(), tool_tree.leaf_count());
  std::printf("poses             %zu x %d repeats%s\n", poses.size(), options.repeat,
              options.sequence ? " (consecutive frames: --sequence)" : "");
  std::printf("pairs             %zu (over all poses)\n", total_pairs);
  std::printf("method            %s%s\n", dual ? "dual descent (the paper's)" : "tool field", shared ? ", shared by two threads" : "");
  std::printf("tree build        %.3f ms\n", build_ms);
  if (!dual) std::printf("tool field build  %.3f ms (once per tool)\n", field_ms);
  std::printf("query             median %.1f us, p95 %.1f us\n", median, p95);
  if (!shared) {
    std::printf("work per query    %.0f bound tests, %.0f near tissue leaves, %.0f leaf candidates, %.0f triangle tests",
                per_query(work.sphere_tests), per_query(near_leaves), per_query(work.leaf_pairs), per_query(work.triangle_tests));
    if (options.sequence) std::printf(", front %.0f kept / %.0f renewed", per_query(work.front_kept), per_query(work.front_renewed));
    std::printf("\n");
  }
}

void register_collide(CLI::App& app) {
  auto options = std::make_shared<CollideOptions>();
  CLI::App* cmd = app.add_subcommand(
      "collide", "Find every intersecting tissue/tool triangle pair over a file of tool poses (sphere trees)");
  cmd->add_option("--tissue", options->tissue, "Tissue surface mesh (.off, .obj, .ply, .stl)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--tool", options->tool, "Tool surface mesh, in tool coordinates")->required()->check(CLI::ExistingFile);
  cmd->add_option("--poses", options->poses, "Tool poses: 12 numbers a line, row-major 3x4 [R|t]")->required()->check(CLI::ExistingFile);
  cmd->add_option("--pairs", options->pairs, "Write the pairs as CSV: pose,tissue_face,tool_face")->check(nonempty_path());
  cmd->add_option("--repeat", options->repeat, "Run every pose this many times for the timings")
      ->transform(whole_in_range(1, 1'000'000))->capture_default_str();
  cmd->add_flag("--sequence", options->sequence,
                "Treat the poses as consecutive frames of one motion and reuse each query's work in the next "
                "(same pairs; without it every pose is independent)");
  cmd->add_option("--threads", options->threads,
                  "1: every query on one thread (the default); 2: each query shared with a helper thread (same pairs; "
                  "with --sequence each thread keeps the front of its own half of the tissue tree)")
      ->transform(whole_in_range(1, 2))
      ->capture_default_str();
  cmd->add_option("--method", options->method,
                  "field: the tissue's sphere tree against the tool's precomputed field (the default); "
                  "dual-descent: the paper's descent of both sphere trees (same pairs)")
      ->check(CLI::IsMember({"field", "dual-descent"}))
      ->capture_default_str();
  cmd->add_flag("--json", options->json, "Print one JSON object instead of text");
  cmd->callback([options] { run_collide(*options); });
}

const RegisterCommand kRegister{"collide", &register_collide};

}  // namespace
}  // namespace resecto::cli

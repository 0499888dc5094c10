// Figure 13 reproduced and raced: the 488-triangle resectoscope pressed into the urethral wall of
// procedural glands from 1,296 to 138,240 triangles; our sphere-tree query beside the paper's rate,
// FCL 0.7's OBBRSS tree (all contacts) and brute force; refit after deformation (ours vs FCL's AABB
// refit); one insert and one remove. Prints one table; `--gbench` runs the Google Benchmark cases.
#include <benchmark/benchmark.h>

#include <fcl/fcl.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "rtcore/anatomy/prostate.h"
#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/base/quantile.h"
#include "rtcore/collision/collide.h"
#include "rtcore/collision/parallel_collider.h"
#include "rtcore/scenes/collision_poses.h"

namespace {

using namespace resecto;
// CPU time of this thread, not wall time: the 2-core machine is shared with compilers, and being
// descheduled is not the algorithm's cost. Both contenders are timed the same way, side by side.
struct Clock {
  using time_point = double;
  static double now() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) * 1e6 + static_cast<double>(ts.tv_nsec) * 1e-3;
  }
};

// --slice-aspect X: the leaves' slab aspect for both trees (tuning; SphereTree::kSliceAspect if 0).
// --tool-slice-aspect X: the same for the tool's tree alone.
double g_slice_aspect = 0.0;
double g_tool_slice_aspect = 0.0;
// --dual-descent: the tables use the paper's dual descent instead of the tool field.
CollisionMethod g_method = CollisionMethod::kToolField;

void configure(SphereTree& tree, bool tool = false) {
  if (g_slice_aspect > 0.0) tree.set_slice_aspect(g_slice_aspect);
  if (tool && g_tool_slice_aspect > 0.0) tree.set_slice_aspect(g_tool_slice_aspect);
  // The field method reads only the tissue's spheres: a tree without slabs refits in about half the time.
  if (!tool) tree.set_slabs(g_method == CollisionMethod::kDualDescent);
}

Collider collider_for(const TriangleMesh& tool) {
  Collider collider;
  collider.set_method(g_method);
  collider.prepare_tool(tool);  // built once per tool, as its tree is
  return collider;
}

// The same query shared by two threads, set up as collider_for() sets up one.
void prepare_shared(ParallelCollider& shared, const TriangleMesh& tool) {
  shared.set_method(g_method);
  shared.prepare_tool(tool);
  shared.reserve(1 << 16, 1 << 16);
}

// One line of a two-thread block beside a table: our one-thread CPU time, the two-thread wall time,
// FCL's, and the poses or frames whose two-thread pairs differed.
struct TwoThreadLine {
  int triangles;
  double one_us, two_us, fcl_us;
  std::size_t mismatch;
};
void print_two_thread_block(const char* what, const char* one_label, const char* fcl_label, const char* ratio_label,
                            const std::vector<TwoThreadLine>& lines) {
  std::printf("\nthe same %s, alternated with the above, shared by two threads (ParallelCollider), wall time, against the "
              "one-thread CPU times above\n", what);
  std::printf("%8s | %9s %11s | %9s %7s | %5s\n", "tissue", one_label, "2 threads", "FCL", "FCL/", "diff");
  std::printf("%8s | %9s %11s | %9s %7s | %5s\n", "tris", "CPU us", "wall us", fcl_label, ratio_label, "");
  for (const TwoThreadLine& l : lines) {
    std::printf("%8d | %9.1f %11.1f | %9.1f %7.1f | %5zu\n", l.triangles, l.one_us, l.two_us, l.fcl_us, l.fcl_us / l.two_us, l.mismatch);
  }
  std::printf("diff: %s whose two-thread pairs differ from the one-thread ones (must be 0).\n", what);
}

// The resectoscope and its tree, as every table uses them.
struct BenchTool {
  TriangleMesh mesh;
  SphereTree tree;
};
BenchTool make_bench_tool() {
  BenchTool tool{combined_resectoscope_mesh(generate_resectoscope()), {}};
  configure(tool.tree, true);
  tool.tree.build(tool.mesh);
  return tool;
}

double elapsed_us(double start_us) { return Clock::now() - start_us; }
// Wall time, for a query shared by two threads: one thread's CPU time would leave out the other's.
double wall_now_us() { return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

// Writes poses in the `resecto collide` format, in millimetres (the unit `resecto mesh` writes).
void write_poses(const std::string& path, const std::vector<RigidPose>& poses) {
  std::FILE* out = std::fopen(path.c_str(), "w");
  if (!out) {
    std::fprintf(stderr, "%s: cannot write\n", path.c_str());
    std::exit(1);
  }
  for (const RigidPose& p : poses) {
    std::array<double, 12> m = to_row_major_3x4(p);
    for (int i = 0; i < 3; ++i) m[static_cast<std::size_t>(4 * i + 3)] *= 1000.0;
    for (std::size_t e = 0; e < 12; ++e) std::fprintf(out, "%.17g%s", m[e], e == 11 ? "\n" : " ");
  }
  std::fclose(out);
}

// ---- FCL --------------------------------------------------------------------------------------

template <class BV>
std::shared_ptr<fcl::BVHModel<BV>> fcl_model(const TriangleMesh& mesh) {
  auto model = std::make_shared<fcl::BVHModel<BV>>();
  std::vector<fcl::Vector3d> points;
  std::vector<fcl::Triangle> triangles;
  for (const Vec3& p : mesh.positions) points.emplace_back(p.x, p.y, p.z);
  for (const Triangle& t : mesh.triangles) triangles.emplace_back(t[0], t[1], t[2]);
  model->beginModel();
  model->addSubModel(points, triangles);
  model->endModel();
  return model;
}

fcl::Transform3d fcl_pose(const RigidPose& pose) {
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  fcl::Matrix3d r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = pose.rotation[j][i];  // glm is column-major
  tf.linear() = r;
  tf.translation() = fcl::Vector3d(pose.translation.x, pose.translation.y, pose.translation.z);
  return tf;
}

template <class BV>
std::vector<TrianglePair> fcl_pairs(const fcl::CollisionObjectd& tissue, fcl::CollisionObjectd& tool, const RigidPose& pose,
                                    double* time_us) {
  tool.setTransform(fcl_pose(pose));
  tool.computeAABB();
  fcl::CollisionRequestd request(1u << 20, false);
  fcl::CollisionResultd result;
  const auto start = Clock::now();
  fcl::collide(&tissue, &tool, request, result);
  if (time_us) *time_us = elapsed_us(start);
  std::vector<TrianglePair> pairs;
  for (std::size_t i = 0; i < result.numContacts(); ++i) {
    const fcl::Contactd& c = result.getContact(i);
    pairs.push_back({static_cast<std::uint32_t>(c.b1), static_cast<std::uint32_t>(c.b2)});
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

// A smooth displacement of the whole surface, about 1.5 mm at most.
void deform(const std::vector<Vec3>& rest, std::vector<Vec3>& out, double phase) {
  for (std::size_t v = 0; v < rest.size(); ++v) {
    const Vec3& p = rest[v];
    out[v] = p + 0.0015 * Vec3(std::sin(170 * p.z + phase), std::cos(140 * p.x - phase), std::sin(110 * p.y + phase));
  }
}

struct Row {
  int triangles = 0;
  double paper_hz = 0;
  double ours_us = 0;
  double fcl_us = 0;
  double brute_us = 0;
  std::size_t ours_pairs = 0;
  std::size_t fcl_pairs = 0;
  std::size_t fcl_missing = 0;  // pairs we found that FCL did not
  std::size_t fcl_extra = 0;    // pairs FCL reported that we did not
  std::size_t brute_mismatch = 0;
  double shared_us = 0;             // the same query on two threads (ParallelCollider), wall time
  std::size_t shared_mismatch = 0;  // poses whose two-thread pairs differ from the one-thread ones
  double refit_us = 0;
  double fcl_refit_us = 0;
  double insert_us = 0;
  double remove_us = 0;
  double sphere_tests = 0;
  double triangle_tests = 0;
  double leaf_pairs = 0;
  int tissue_leaves = 0;
  bool deformed_checked = false;       // the after-deformation comparison ran for this size
  std::size_t deformed_pairs = 0;      // brute-force pairs on the deformed surface, summed over poses
  std::size_t deformed_ours_missing = 0;
  std::size_t deformed_fcl_missing = 0;  // FCL OBBRSS after its bottom-up refit
  std::size_t deformed_fcl_extra = 0;
};

Row measure(int target_triangles, double paper_hz, const TriangleMesh& tool, const SphereTree& tool_tree,
            const std::vector<RigidPose>& poses, int repetitions, bool with_brute) {
  Row row;
  row.paper_hz = paper_hz;
  ProstateModel gland = generate_prostate(target_triangles);
  TriangleMesh& tissue = gland.surface;
  row.triangles = static_cast<int>(tissue.triangle_count());
  SphereTree tissue_tree;
  configure(tissue_tree);
  tissue_tree.build(tissue);
  Collider collider = collider_for(tool);
  collider.reserve(1 << 16, 1 << 16);
  ParallelCollider shared(2);
  prepare_shared(shared, tool);

  // Our query (alone, and shared by two threads) and FCL OBBRSS (all contacts), every pose `repetitions` times, alternated pose by pose
  // so that both see the same machine load; the median over all.
  fcl::CollisionObjectd fcl_tissue(fcl_model<fcl::OBBRSSd>(tissue));
  fcl::CollisionObjectd fcl_tool(fcl_model<fcl::OBBRSSd>(tool));
  std::vector<double> ours, fcl_times, shared_times;
  std::vector<std::vector<TrianglePair>> ours_found(poses.size());
  double sphere_tests = 0, triangle_tests = 0, leaf_pairs = 0;
  for (int r = 0; r < repetitions; ++r) {
    for (std::size_t p = 0; p < poses.size(); ++p) {
      const auto start = Clock::now();
      collider.collide(tissue_tree, tissue, tool_tree, tool, poses[p]);
      ours.push_back(elapsed_us(start));
      double t = 0;
      const auto found = fcl_pairs<fcl::OBBRSSd>(fcl_tissue, fcl_tool, poses[p], &t);
      fcl_times.push_back(t);
      const double shared_start = wall_now_us();
      shared.collide(tissue_tree, tissue, tool_tree, tool, poses[p]);
      shared_times.push_back(wall_now_us() - shared_start);
      // Asleep while the others are timed (spinning, it could slow them), so each shared query
      // also pays for waking it.
      shared.release_helper();
      if (r > 0) continue;
      ours_found[p].assign(collider.pairs().begin(), collider.pairs().end());
      if (!std::equal(shared.pairs().begin(), shared.pairs().end(), ours_found[p].begin(), ours_found[p].end())) ++row.shared_mismatch;
      sphere_tests += static_cast<double>(collider.stats().sphere_tests);
      triangle_tests += static_cast<double>(collider.stats().triangle_tests);
      leaf_pairs += static_cast<double>(collider.stats().leaf_pairs);
      row.fcl_pairs += found.size();
      std::vector<TrianglePair> diff;
      std::set_difference(ours_found[p].begin(), ours_found[p].end(), found.begin(), found.end(), std::back_inserter(diff));
      row.fcl_missing += diff.size();
      diff.clear();
      std::set_difference(found.begin(), found.end(), ours_found[p].begin(), ours_found[p].end(), std::back_inserter(diff));
      row.fcl_extra += diff.size();
    }
  }
  row.ours_us = quantile(ours, 0.5);
  row.fcl_us = quantile(fcl_times, 0.5);
  row.shared_us = quantile(shared_times, 0.5);
  row.sphere_tests = sphere_tests / static_cast<double>(poses.size());
  row.triangle_tests = triangle_tests / static_cast<double>(poses.size());
  row.leaf_pairs = leaf_pairs / static_cast<double>(poses.size());
  row.tissue_leaves = tissue_tree.leaf_count();
  for (const auto& f : ours_found) row.ours_pairs += f.size();

  if (with_brute) {
    std::vector<double> brute;
    for (std::size_t p = 0; p < poses.size(); ++p) {
      const auto start = Clock::now();
      const auto found = collide_brute_force(tissue, tool, poses[p]);
      brute.push_back(elapsed_us(start));
      if (found != ours_found[p]) ++row.brute_mismatch;
    }
    row.brute_us = quantile(brute, 0.5);
  }

  // Refit after a full-surface deformation: ours vs FCL's bottom-up AABB refit.
  const std::vector<Vec3> rest = tissue.positions;
  auto fcl_aabb = fcl_model<fcl::AABBd>(tissue);
  std::vector<fcl::Vector3d> moved(rest.size());
  std::vector<double> refit, fcl_refit;
  for (int r = 0; r < 2 * repetitions + 1; ++r) {
    deform(rest, tissue.positions, 0.3 * r);
    for (std::size_t v = 0; v < rest.size(); ++v) moved[v] = fcl::Vector3d(tissue.positions[v].x, tissue.positions[v].y, tissue.positions[v].z);
    auto start = Clock::now();
    tissue_tree.refit(tissue);
    refit.push_back(elapsed_us(start));
    start = Clock::now();
    fcl_aabb->beginUpdateModel();
    fcl_aabb->updateSubModel(moved);
    fcl_aabb->endUpdateModel(true, true);
    fcl_refit.push_back(elapsed_us(start));
  }
  row.refit_us = quantile(refit, 0.5);
  row.fcl_refit_us = quantile(fcl_refit, 0.5);
  // After the refit, still exact: the deformed surface against the poses, vs brute force.
  // The same poses through FCL's OBBRSS tree built on the rest surface and refitted bottom-up to
  // the deformed one (its update path), against brute force on the deformed surface.
  if (with_brute && target_triangles <= 8640) {
    TriangleMesh rest_mesh = tissue;
    rest_mesh.positions = rest;
    auto fcl_refitted = fcl_model<fcl::OBBRSSd>(rest_mesh);
    fcl_refitted->beginUpdateModel();
    fcl_refitted->updateSubModel(moved);
    fcl_refitted->endUpdateModel(true, true);
    fcl::CollisionObjectd fcl_deformed(fcl_refitted);
    fcl::CollisionObjectd fcl_tool_obj(fcl_model<fcl::OBBRSSd>(tool));
    row.deformed_checked = true;
    for (const RigidPose& pose : poses) {
      collider.collide(tissue_tree, tissue, tool_tree, tool, pose);
      const auto expected = collide_brute_force(tissue, tool, pose);
      row.deformed_pairs += expected.size();
      if (!std::equal(collider.pairs().begin(), collider.pairs().end(), expected.begin(), expected.end())) {
        ++row.brute_mismatch;
      }
      std::vector<TrianglePair> diff;
      std::set_difference(expected.begin(), expected.end(), collider.pairs().begin(), collider.pairs().end(),
                          std::back_inserter(diff));
      row.deformed_ours_missing += diff.size();
      const auto fcl_found = fcl_pairs<fcl::OBBRSSd>(fcl_deformed, fcl_tool_obj, pose, nullptr);
      diff.clear();
      std::set_difference(expected.begin(), expected.end(), fcl_found.begin(), fcl_found.end(), std::back_inserter(diff));
      row.deformed_fcl_missing += diff.size();
      diff.clear();
      std::set_difference(fcl_found.begin(), fcl_found.end(), expected.begin(), expected.end(), std::back_inserter(diff));
      row.deformed_fcl_extra += diff.size();
    }
  }

  // One remove and one insert (cutting), averaged over many triangles; each pair leaves the tree
  // as it was.
  std::vector<double> removes, inserts;
  const std::uint32_t step = std::max<std::uint32_t>(1, static_cast<std::uint32_t>(tissue.triangle_count() / 500));
  for (std::uint32_t t = 0; t < tissue.triangle_count(); t += step) {
    auto start = Clock::now();
    tissue_tree.remove_triangle(t);
    removes.push_back(elapsed_us(start));
    start = Clock::now();
    tissue_tree.insert_triangle(tissue, t);
    inserts.push_back(elapsed_us(start));
  }
  row.remove_us = quantile(removes, 0.5);
  row.insert_us = quantile(inserts, 0.5);
  return row;
}

// The 60 Hz trajectory at one size: each frame's query alone (collide), the same frames as a sequence
// (collide_sequence, the front of the previous frame seeding the next), and FCL OBBRSS; every frame's
// pairs compared across the three and with brute force.
struct SequenceRow {
  int triangles = 0;
  std::size_t frames = 0;
  double fresh_us = 0, sequence_us = 0, sequence_mean_us = 0, fcl_us = 0, fcl_mean_us = 0;
  std::size_t pairs = 0;
  std::size_t brute_mismatch = 0, fresh_mismatch = 0, fcl_mismatch = 0;
  double kept = 0, renewed = 0;  // front pairs per frame
  double shared_us = 0;             // the sequence on two threads (ParallelCollider), wall time, median
  std::size_t shared_mismatch = 0;  // frames whose two-thread pairs differ from the fresh query's
};

SequenceRow measure_sequence(int target_triangles, const TriangleMesh& tool, const SphereTree& tool_tree,
                             const std::vector<RigidPose>& frames, int repetitions) {
  SequenceRow row;
  ProstateModel gland = generate_prostate(target_triangles);
  const TriangleMesh& tissue = gland.surface;
  row.triangles = static_cast<int>(tissue.triangle_count());
  row.frames = frames.size();
  SphereTree tissue_tree;
  configure(tissue_tree);
  tissue_tree.build(tissue);
  Collider fresh = collider_for(tool), sequence = collider_for(tool);
  fresh.reserve(1 << 16, 1 << 16);
  sequence.reserve(1 << 16, 1 << 16);
  ParallelCollider shared(2);
  prepare_shared(shared, tool);
  fcl::CollisionObjectd fcl_tissue(fcl_model<fcl::OBBRSSd>(tissue));
  fcl::CollisionObjectd fcl_tool(fcl_model<fcl::OBBRSSd>(tool));
  std::vector<double> fresh_times, sequence_times, fcl_times, shared_times;
  std::vector<std::vector<TrianglePair>> fresh_found(frames.size());
  // Alternated frame by frame, so the four see the same machine load.
  for (int r = 0; r < repetitions; ++r) {
    sequence.reset_sequence();
    shared.reset_sequence();
    for (std::size_t f = 0; f < frames.size(); ++f) {
      auto start = Clock::now();
      fresh.collide(tissue_tree, tissue, tool_tree, tool, frames[f]);
      fresh_times.push_back(elapsed_us(start));
      start = Clock::now();
      sequence.collide_sequence(tissue_tree, tissue, tool_tree, tool, frames[f]);
      sequence_times.push_back(elapsed_us(start));
      double t = 0;
      const auto fcl_found = fcl_pairs<fcl::OBBRSSd>(fcl_tissue, fcl_tool, frames[f], &t);
      fcl_times.push_back(t);
      const double shared_start = wall_now_us();
      shared.collide_sequence(tissue_tree, tissue, tool_tree, tool, frames[f]);
      shared_times.push_back(wall_now_us() - shared_start);
      // Asleep while the others are timed (spinning, it could slow them), so each shared query
      // also pays for waking it.
      shared.release_helper();
      if (r > 0) continue;
      fresh_found[f].assign(fresh.pairs().begin(), fresh.pairs().end());
      if (!std::equal(shared.pairs().begin(), shared.pairs().end(), fresh_found[f].begin(), fresh_found[f].end())) ++row.shared_mismatch;
      row.pairs += fresh_found[f].size();
      if (!std::equal(sequence.pairs().begin(), sequence.pairs().end(), fresh_found[f].begin(), fresh_found[f].end())) {
        ++row.fresh_mismatch;
      }
      if (fcl_found != fresh_found[f]) ++row.fcl_mismatch;
      row.kept += static_cast<double>(sequence.stats().front_kept);
      row.renewed += static_cast<double>(sequence.stats().front_renewed);
    }
  }
  for (std::size_t f = 0; f < frames.size(); ++f) {
    if (collide_brute_force(tissue, tool, frames[f]) != fresh_found[f]) ++row.brute_mismatch;
  }
  const auto mean = [](const std::vector<double>& v) {
    double sum = 0;
    for (double x : v) sum += x;
    return sum / static_cast<double>(v.size());
  };
  row.fresh_us = quantile(fresh_times, 0.5);
  row.sequence_us = quantile(sequence_times, 0.5);
  row.sequence_mean_us = mean(sequence_times);
  row.fcl_us = quantile(fcl_times, 0.5);
  row.fcl_mean_us = mean(fcl_times);
  row.shared_us = quantile(shared_times, 0.5);
  row.kept /= static_cast<double>(frames.size());
  row.renewed /= static_cast<double>(frames.size());
  return row;
}

int run_sequence_table(int repetitions, int only_size) {
  const BenchTool tool = make_bench_tool();
  const auto frames = pressing_trajectory();
  std::printf("\n60 Hz trajectory: %zu consecutive frames (sheath along the wall, loop through the lobe), %d runs of the "
              "whole trajectory, medians and means over every frame of every run (the first frame of a run starts afresh)\n",
              frames.size(), repetitions);
  std::printf("%8s | %9s | %9s %9s | %9s %9s | %7s %7s | %7s | %5s %5s %5s | %8s %8s\n", "tissue", "ours", "ours seq",
              "ours seq", "FCL", "FCL", "FCL/", "FCL/", "pairs", "brute", "fresh", "FCL", "front", "front");
  std::printf("%8s | %9s | %9s %9s | %9s %9s | %7s %7s | %7s | %5s %5s %5s | %8s %8s\n", "tris", "fresh us", "median",
              "mean", "median", "mean", "seq med", "seq mean", "", "diff", "diff", "diff", "kept", "renewed");
  std::vector<SequenceRow> rows;
  for (const int size : {1296, 8640, 34560, 138240}) {
    if (only_size > 0 && size != only_size) continue;
    rows.push_back(measure_sequence(size, tool.mesh, tool.tree, frames, size > 40000 ? 3 : repetitions));
    const SequenceRow& row = rows.back();
    std::printf("%8d | %9.1f | %9.1f %9.1f | %9.1f %9.1f | %7.1f %7.1f | %7zu | %5zu %5zu %5zu | %8.0f %8.0f\n", row.triangles,
                row.fresh_us, row.sequence_us, row.sequence_mean_us, row.fcl_us, row.fcl_mean_us, row.fcl_us / row.sequence_us,
                row.fcl_mean_us / row.sequence_mean_us, row.pairs, row.brute_mismatch, row.fresh_mismatch, row.fcl_mismatch,
                row.kept, row.renewed);
    std::fflush(stdout);
  }
  std::printf("diff: frames whose sequence pairs differ from brute force / from the fresh query / FCL's (must be 0, 0, 0); "
              "front kept/renewed: cached node pairs per frame whose certificate held / that were walked again.\n");
  std::vector<TwoThreadLine> lines;
  for (const SequenceRow& row : rows) lines.push_back({row.triangles, row.sequence_us, row.shared_us, row.fcl_us, row.shared_mismatch});
  print_two_thread_block("frames", "seq 1 thr", "median", "seq 2", lines);
  return 0;
}

// The paper's Figure 13 (../shared/reference/paper-figure13-collision-rates.csv): prostate
// triangles and the mean collision rate in Hz with the 488-triangle tool, 3 GHz PC, 2006.
const std::vector<std::pair<int, double>> kFigure13 = {
    {1296, 64.09}, {1482, 64.08}, {1560, 64.25}, {2069, 64.58}, {2816, 63.35}, {3128, 63.15},
    {3744, 51.45}, {5292, 52.48}, {5670, 55.28}, {7260, 50.93}, {8640, 52.23}};

int run_table(int repetitions, int only_size) {
  auto sizes = kFigure13;
  sizes.emplace_back(34560, 0.0);
  sizes.emplace_back(138240, 0.0);
  const BenchTool bench_tool = make_bench_tool();
  const TriangleMesh& tool = bench_tool.mesh;
  const SphereTree& tool_tree = bench_tool.tree;
  const auto poses = pressing_poses();
  std::printf("collision benchmark: resectoscope %zu triangles (%d leaf spheres), %zu poses pressing into the wall, "
              "median of %d repetitions of every pose\n",
              tool.triangle_count(), tool_tree.leaf_count(), poses.size(), repetitions);
  std::printf("%8s %8s | %9s %9s | %9s %7s | %9s %7s | %7s %7s %6s %6s %5s | %8s %8s %6s | %6s %6s | %8s %7s %7s %6s\n", "tissue",
              "paper", "ours", "ours", "FCL", "FCL/", "brute", "brute/", "pairs", "pairs", "FCL", "FCL", "brute", "refit",
              "FCL", "FCL/", "insert", "remove", "sphere", "leaf", "tri", "tissue");
  std::printf("%8s %8s | %9s %9s | %9s %7s | %9s %7s | %7s %7s %6s %6s %5s | %8s %8s %6s | %6s %6s | %8s %7s %7s %6s\n", "tris",
              "Hz", "us", "Hz", "OBBRSS us", "ours", "us", "ours", "ours", "FCL", "miss", "extra", "diff", "ours us",
              "AABB us", "ours", "us", "us", "tests", "pairs", "tests", "leaves");
  std::vector<Row> rows;
  for (const auto& [triangles, paper_hz] : sizes) {
    if (only_size > 0 && triangles != only_size) continue;
    rows.push_back(measure(triangles, paper_hz, tool, tool_tree, poses, triangles > 40000 ? 3 : repetitions, true));
    const Row& row = rows.back();
    char paper[16];
    if (paper_hz > 0) std::snprintf(paper, sizeof paper, "%.2f", paper_hz); else std::snprintf(paper, sizeof paper, "-");
    std::printf("%8d %8s | %9.1f %9.0f | %9.1f %7.1f | %9.1f %7.1f | %7zu %7zu %6zu %6zu %5zu | %8.1f %8.1f %6.1f | %6.2f %6.2f | %8.0f %7.0f %7.0f %6d\n",
                row.triangles, paper, row.ours_us, 1e6 / row.ours_us, row.fcl_us, row.fcl_us / row.ours_us, row.brute_us,
                row.brute_us / row.ours_us, row.ours_pairs, row.fcl_pairs, row.fcl_missing, row.fcl_extra, row.brute_mismatch,
                row.refit_us, row.fcl_refit_us, row.fcl_refit_us / row.refit_us, row.insert_us, row.remove_us, row.sphere_tests,
                row.leaf_pairs, row.triangle_tests, row.tissue_leaves);
    std::fflush(stdout);
  }
  std::printf("pairs: summed over the poses; FCL miss/extra: pairs we found that FCL did not / the reverse; brute diff: "
              "poses where our pairs differ from brute force (before and after the deformation refit; must be 0).\n");
  std::vector<TwoThreadLine> lines;
  for (const Row& row : rows) lines.push_back({row.triangles, row.ours_us, row.shared_us, row.fcl_us, row.shared_mismatch});
  print_two_thread_block("poses", "ours 1 thr", "OBBRSS us", "ours 2", lines);
  std::printf("\nafter a smooth deformation of up to 1.5 mm and a refit (ours: SphereTree::refit; FCL: OBBRSS built at rest, "
              "endUpdateModel(refit, bottom-up)), pairs vs brute force on the deformed surface, summed over the poses:\n");
  std::printf("%8s | %8s | %12s | %12s %10s\n", "tissue", "brute", "ours missing", "FCL missing", "FCL extra");
  for (const Row& row : rows) {
    if (!row.deformed_checked) continue;
    std::printf("%8d | %8zu | %12zu | %12zu %10zu\n", row.triangles, row.deformed_pairs, row.deformed_ours_missing,
                row.deformed_fcl_missing, row.deformed_fcl_extra);
  }
  return 0;
}

// ---- Google Benchmark cases (--gbench) ----------------------------------------------------------

void query_case(benchmark::State& state, CollisionMethod method, bool slabs) {
  const ProstateModel gland = generate_prostate(static_cast<int>(state.range(0)));
  const TriangleMesh tool = combined_resectoscope_mesh(generate_resectoscope());
  SphereTree tissue_tree, tool_tree;
  tissue_tree.set_slabs(method == CollisionMethod::kDualDescent);
  tissue_tree.build(gland.surface);
  tool_tree.build(tool);
  const auto poses = pressing_poses();
  Collider collider;
  collider.set_method(method);
  collider.set_slabs(slabs);
  collider.prepare_tool(tool);  // built once per tool, as its tree is
  std::size_t p = 0;
  CollisionStats work;
  for (auto _ : state) {
    collider.collide(tissue_tree, gland.surface, tool_tree, tool, poses[p++ % poses.size()]);
    benchmark::DoNotOptimize(collider.pairs().data());
    work.sphere_tests += collider.stats().sphere_tests;
    work.leaf_pairs += collider.stats().leaf_pairs;
    work.triangle_tests += collider.stats().triangle_tests;
  }
  // The work per query, to read beside the time.
  const auto per_query = [&](std::int64_t total) { return benchmark::Counter(static_cast<double>(total), benchmark::Counter::kAvgIterations); };
  state.counters["bound_tests"] = per_query(work.sphere_tests);
  state.counters["leaf_pairs"] = per_query(work.leaf_pairs);
  state.counters["triangle_tests"] = per_query(work.triangle_tests);
}
// The tool field (the default method).
void BM_Query(benchmark::State& state) { query_case(state, CollisionMethod::kToolField, false); }
// The paper's dual descent with the slabs beside the spheres, and with the spheres alone (the paper's test).
void BM_QueryDualDescent(benchmark::State& state) { query_case(state, CollisionMethod::kDualDescent, true); }
void BM_QueryPaperSpheres(benchmark::State& state) { query_case(state, CollisionMethod::kDualDescent, false); }
BENCHMARK(BM_QueryPaperSpheres)->Arg(8640)->Arg(138240)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_QueryDualDescent)->Arg(8640)->Arg(138240)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Query)->Arg(8640)->Arg(138240)->Unit(benchmark::kMicrosecond);
// The tool field's query shared by the caller's thread and a helper (wall time: UseRealTime).
void BM_QueryTwoThreads(benchmark::State& state) {
  const ProstateModel gland = generate_prostate(static_cast<int>(state.range(0)));
  const TriangleMesh tool = combined_resectoscope_mesh(generate_resectoscope());
  SphereTree tissue_tree, tool_tree;
  tissue_tree.set_slabs(false);
  tissue_tree.build(gland.surface);
  tool_tree.build(tool);
  const auto poses = pressing_poses();
  ParallelCollider shared(2);
  shared.prepare_tool(tool);
  std::size_t p = 0;
  for (auto _ : state) {
    shared.collide(tissue_tree, gland.surface, tool_tree, tool, poses[p++ % poses.size()]);
    benchmark::DoNotOptimize(shared.pairs().data());
  }
}
BENCHMARK(BM_QueryTwoThreads)->Arg(8640)->Arg(138240)->Unit(benchmark::kMicrosecond)->UseRealTime();

// The 60 Hz trajectory as a sequence (collide_sequence) over the 8640-triangle gland, frame after
// frame, looping, with one Collider or shared by two threads.
template <class Sequencer>
void sequence_case(benchmark::State& state, Sequencer& sequencer) {
  const ProstateModel gland = generate_prostate(8640);
  const BenchTool tool = make_bench_tool();
  SphereTree tissue_tree;
  configure(tissue_tree);
  tissue_tree.build(gland.surface);
  const auto frames = pressing_trajectory();
  sequencer.prepare_tool(tool.mesh);
  std::size_t f = 0;
  for (auto _ : state) {
    if (f % frames.size() == 0) sequencer.reset_sequence();
    sequencer.collide_sequence(tissue_tree, gland.surface, tool.tree, tool.mesh, frames[f++ % frames.size()]);
    benchmark::DoNotOptimize(sequencer.pairs().data());
  }
}
void BM_Sequence8640(benchmark::State& state) {
  Collider collider;
  collider.set_method(g_method);
  sequence_case(state, collider);
}
BENCHMARK(BM_Sequence8640);
// Wall time: the helper spins between back-to-back frames (the table's two-thread column pays for waking it).
void BM_SequenceTwoThreads8640(benchmark::State& state) {
  ParallelCollider shared(2);
  shared.set_method(g_method);
  sequence_case(state, shared);
}
BENCHMARK(BM_SequenceTwoThreads8640)->UseRealTime();

// The refit after a deformation, ours and FCL's AABB tree: the spheres alone (what the tool field
// reads) and with the slabs (what the dual descent reads).
void refit_case(benchmark::State& state, bool slabs) {
  ProstateModel gland = generate_prostate(static_cast<int>(state.range(0)));
  TriangleMesh& mesh = gland.surface;
  SphereTree tree;
  tree.set_slabs(slabs);
  tree.build(mesh);
  const std::vector<Vec3> rest = mesh.positions;
  deform(rest, mesh.positions, 0.7);
  for (auto _ : state) {
    tree.refit(mesh);
    benchmark::DoNotOptimize(tree.spheres().data());
  }
}
void BM_Refit(benchmark::State& state) { refit_case(state, false); }
void BM_RefitWithSlabs(benchmark::State& state) { refit_case(state, true); }
BENCHMARK(BM_RefitWithSlabs)->Arg(8640)->Arg(138240)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Refit)->Arg(1296)->Arg(8640)->Arg(138240)->Unit(benchmark::kMicrosecond);

// The rebuild a tree decayed by cuts gets (SphereTree::rebuild, as the tissue's collision job runs it),
// of the spheres alone as the tissue's tree keeps them: it shares the collision period with a search.
// With the second argument 1, also the refit that follows it in the job, which first lays out its
// orders for the new shape (MassSpringTissue::refit_surface_tree): what the job pays in all.
void BM_Rebuild(benchmark::State& state) {
  ProstateModel gland = generate_prostate(static_cast<int>(state.range(0)));
  const bool then_refit = state.range(1) != 0;
  SphereTree tree;
  tree.set_slabs(false);
  tree.build(gland.surface);
  for (auto _ : state) {
    tree.rebuild(gland.surface);
    if (then_refit) tree.refit(gland.surface);
    benchmark::DoNotOptimize(tree.spheres().data());
  }
  state.SetLabel(then_refit ? "then refit" : "alone");
}
BENCHMARK(BM_Rebuild)->ArgsProduct({{8640, 138240}, {0, 1}})->Unit(benchmark::kMicrosecond);

void BM_FclAabbRefit(benchmark::State& state) {
  ProstateModel gland = generate_prostate(static_cast<int>(state.range(0)));
  TriangleMesh& mesh = gland.surface;
  auto model = fcl_model<fcl::AABBd>(mesh);
  const std::vector<Vec3> rest = mesh.positions;
  deform(rest, mesh.positions, 0.7);
  std::vector<fcl::Vector3d> moved(rest.size());
  for (std::size_t v = 0; v < rest.size(); ++v) moved[v] = fcl::Vector3d(mesh.positions[v].x, mesh.positions[v].y, mesh.positions[v].z);
  for (auto _ : state) {
    model->beginUpdateModel();
    model->updateSubModel(moved);
    model->endUpdateModel(true, true);
    benchmark::DoNotOptimize(model.get());
  }
}
BENCHMARK(BM_FclAabbRefit)->Arg(1296)->Arg(8640)->Arg(138240)->Unit(benchmark::kMicrosecond);

}  // namespace

int main(int argc, char** argv) {
  int repetitions = 7;
  int only_size = 0;  // --size N: one row only
  bool sequence_only = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) {
      std::printf(
          "usage: collision_bench [--size N] [--repetitions N] [--sequence-only] [--dual-descent] [--slice-aspect X]\n"
          "                       [--tool-slice-aspect X] | --write-poses PREFIX | --gbench [Google Benchmark flags]\n"
          "Prints the query table (ours against FCL OBBRSS and brute force, alternated pose by pose, with the refit\n"
          "against FCL's AABB refit) and the 60 Hz trajectory table; --gbench runs the Google Benchmark cases instead.\n");
      return 0;
    }
    if (std::strcmp(argv[i], "--gbench") == 0) {
      benchmark::Initialize(&argc, argv);
      benchmark::RunSpecifiedBenchmarks();
      return 0;
    }
    if (std::strcmp(argv[i], "--tool-slice-aspect") == 0 && i + 1 < argc) g_tool_slice_aspect = std::atof(argv[++i]);
    if (std::strcmp(argv[i], "--slice-aspect") == 0 && i + 1 < argc) g_slice_aspect = std::atof(argv[++i]);
    if (std::strcmp(argv[i], "--size") == 0 && i + 1 < argc) only_size = std::atoi(argv[++i]);
    if (std::strcmp(argv[i], "--repetitions") == 0 && i + 1 < argc) repetitions = std::max(1, std::atoi(argv[++i]));
    if (std::strcmp(argv[i], "--sequence-only") == 0) sequence_only = true;
    if (std::strcmp(argv[i], "--dual-descent") == 0) g_method = CollisionMethod::kDualDescent;
    if (std::strcmp(argv[i], "--write-poses") == 0 && i + 1 < argc) {
      // The bench's poses for `resecto collide`: PREFIX-independent.txt and PREFIX-trajectory.txt (mm).
      const std::string prefix = argv[++i];
      write_poses(prefix + "-independent.txt", pressing_poses());
      write_poses(prefix + "-trajectory.txt", pressing_trajectory());
      return 0;
    }
  }
  if (!sequence_only) run_table(repetitions, only_size);
  return run_sequence_table(repetitions, only_size);
}

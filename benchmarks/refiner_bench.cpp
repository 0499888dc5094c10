// TetRefiner::plan() on the 1296 .. 34560-triangle glands: the ~20 tetrahedra nearest a point in the
// left lateral lobe (where the loop cuts) marked, as resection marks them ahead of the loop. Then a
// table of repeated refinement at that point over 4 rounds: tetrahedra and nodes added per marked
// tetrahedron and the smallest dihedral angle before and after. Run: build/release/benchmarks/refiner_bench
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <numbers>

#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/resection/tet_refiner.h"
#include "rtcore/scenes/prostate_tissue.h"

namespace resecto {
namespace {

constexpr std::size_t kMarked = 20;
constexpr int kRounds = 4;

/// The tissue in the flat arrays a simulation holds; refinement edits are applied to it in place.
struct LiveMesh {
  std::vector<Vec3> rest;
  std::vector<Tetrahedron> tets;
  std::vector<std::uint8_t> alive;
  std::vector<TissueRegion> regions;
  Vec3 lobe_point{0.0};  ///< in the left lateral lobe, 4 mm out from the channel, mid-length

  TetMeshView view() const { return {rest, tets, alive, regions}; }

  /// As resection applies an edit: midpoints appended, children into the freed slots first.
  void apply(const RefinementEdit& edit) {
    for (const auto& p : edit.new_node_parents) rest.push_back((rest[p[0]] + rest[p[1]]) * 0.5);
    for (std::uint32_t s : edit.removed_tetrahedra) alive[s] = 0;
    for (std::size_t c = 0; c < edit.added_tetrahedra.size(); ++c) {
      const std::uint32_t s = c < edit.removed_tetrahedra.size() ? edit.removed_tetrahedra[c] : static_cast<std::uint32_t>(tets.size());
      if (s == tets.size()) tets.emplace_back(), regions.emplace_back(), alive.emplace_back();
      tets[s] = edit.added_tetrahedra[c];
      regions[s] = edit.added_regions[c];
      alive[s] = 1;
    }
  }

  /// The `count` live slots with centroids nearest the lobe point, nearest first (ties by slot).
  std::vector<std::uint32_t> nearest(std::size_t count) const {
    std::vector<std::pair<double, std::uint32_t>> by_distance;
    for (std::uint32_t s = 0; s < tets.size(); ++s) {
      if (!alive[s]) continue;
      const Tetrahedron& t = tets[s];
      by_distance.emplace_back(length_squared((rest[t[0]] + rest[t[1]] + rest[t[2]] + rest[t[3]]) * 0.25 - lobe_point), s);
    }
    std::partial_sort(by_distance.begin(), by_distance.begin() + static_cast<std::ptrdiff_t>(count), by_distance.end());
    std::vector<std::uint32_t> slots;
    for (std::size_t i = 0; i < count; ++i) slots.push_back(by_distance[i].second);
    return slots;
  }

  double min_dihedral_deg(const Tetrahedron& t) const {
    TetMesh one;
    one.positions = {rest[t[0]], rest[t[1]], rest[t[2]], rest[t[3]]};
    one.tetrahedra = {{0, 1, 2, 3}};
    return dihedral_angles(one, 0).front() * 180.0 / std::numbers::pi;
  }
};

const LiveMesh& gland(int triangles) {
  static std::map<int, std::unique_ptr<LiveMesh>> meshes;
  auto& slot = meshes[triangles];
  if (!slot) {
    const ProstateModel anatomy = generate_prostate(triangles);
    const ProstateShape shape = anatomy.shape;
    Result<ProstateTissueModel> built = build_prostate_tissue_model(anatomy, generate_resectoscope().loop);
    if (!built) {
      std::fprintf(stderr, "%s\n", built.error().c_str());
      std::abort();
    }
    slot = std::make_unique<LiveMesh>();
    slot->rest = built->mesh.positions;
    slot->tets = built->mesh.tetrahedra;
    slot->regions = built->mesh.regions;
    slot->alive.assign(slot->tets.size(), 1);
    slot->lobe_point = {shape.channel_radius_m + 0.004, 0.0, 0.5 * shape.length_m};
  }
  return *slot;
}

/// One plan for the ~20 tetrahedra nearest the lobe point, with the refiner warmed up (its scratch
/// grown) as in a running simulation.
void BM_Plan(benchmark::State& state) {
  const LiveMesh& mesh = gland(static_cast<int>(state.range(0)));
  const std::vector<std::uint32_t> marked = mesh.nearest(kMarked);
  TetRefiner refiner(mesh.rest.size(), mesh.tets.size());
  const RefinementEdit* edit = &refiner.plan(mesh.view(), marked);
  for (auto _ : state) {
    edit = &refiner.plan(mesh.view(), marked);
    benchmark::DoNotOptimize(edit);
  }
  state.counters["tetrahedra"] = static_cast<double>(mesh.tets.size());
  state.counters["red"] = edit->red_tetrahedra;
  state.counters["closure"] = edit->closure_tetrahedra;
  state.counters["nodes_added"] = static_cast<double>(edit->new_node_parents.size());
  state.counters["tets_added_net"] = static_cast<double>(edit->added_tetrahedra.size() - edit->removed_tetrahedra.size());
}
BENCHMARK(BM_Plan)->Arg(1296)->Arg(8640)->Arg(34560)->Unit(benchmark::kMicrosecond)->MinTime(0.5)->Repetitions(5)->ReportAggregatesOnly(true);

/// Repeated refinement at the lobe point: each round marks the 20 live tetrahedra nearest it again.
void print_rounds(int triangles) {
  LiveMesh mesh = gland(triangles);
  TetRefiner refiner(mesh.rest.size(), mesh.tets.size());
  double mesh_min = 180.0;
  for (const Tetrahedron& t : mesh.tets) mesh_min = std::min(mesh_min, mesh.min_dihedral_deg(t));
  std::printf("\n%d triangles, %zu tetrahedra, smallest dihedral in the whole mesh %.2f deg\n", triangles, mesh.tets.size(), mesh_min);
  std::printf("%5s %5s %7s %10s %10s %9s | %14s %14s %14s %14s %14s\n", "round", "red", "closure", "nodes/mark", "tets/mark", "plan us",
              "marked min deg", "region before", "red child min", "red child/par", "closure min");
  for (int round = 1; round <= kRounds; ++round) {
    const std::vector<std::uint32_t> marked = mesh.nearest(kMarked);
    double marked_min = 180.0;
    for (std::uint32_t s : marked) marked_min = std::min(marked_min, mesh.min_dihedral_deg(mesh.tets[s]));
    const auto start = std::chrono::steady_clock::now();
    const RefinementEdit& edit = refiner.plan(mesh.view(), marked);
    const double plan_us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
    std::map<std::uint32_t, double> parent_min;  // each removed slot's smallest dihedral, before
    double region_min = 180.0, red_min = 180.0, closure_min = 180.0, red_ratio = 1e300;
    for (std::uint32_t s : edit.removed_tetrahedra) {
      parent_min[s] = mesh.min_dihedral_deg(mesh.tets[s]);
      region_min = std::min(region_min, parent_min[s]);
    }
    mesh.apply(edit);  // the children's new corners exist from here
    std::map<std::uint32_t, int> children;
    for (std::uint32_t p : edit.added_parent) ++children[p];
    for (std::size_t c = 0; c < edit.added_tetrahedra.size(); ++c) {
      const std::uint32_t parent = edit.added_parent[c];
      const double child = mesh.min_dihedral_deg(edit.added_tetrahedra[c]);
      if (children[parent] == 8) {
        red_min = std::min(red_min, child);
        red_ratio = std::min(red_ratio, child / parent_min[parent]);
      } else {
        closure_min = std::min(closure_min, child);
      }
    }
    std::printf("%5d %5d %7d %10.2f %10.2f %9.1f | %14.2f %14.2f %14.2f %14.3f %14.2f\n", round, edit.red_tetrahedra, edit.closure_tetrahedra,
                static_cast<double>(edit.new_node_parents.size()) / kMarked,
                static_cast<double>(edit.added_tetrahedra.size() - edit.removed_tetrahedra.size()) / kMarked, plan_us, marked_min,
                region_min, red_min, red_ratio, closure_min);
  }
  double after_min = 180.0;
  for (std::size_t s = 0; s < mesh.tets.size(); ++s) {
    if (mesh.alive[s]) after_min = std::min(after_min, mesh.min_dihedral_deg(mesh.tets[s]));
  }
  std::printf("after %d rounds: %zu tetrahedra, %zu nodes, smallest dihedral in the whole mesh %.2f deg\n", kRounds, mesh.tets.size(),
              mesh.rest.size(), after_min);
}

}  // namespace
}  // namespace resecto

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  for (int triangles : {8640, 34560}) resecto::print_rounds(triangles);
  return 0;
}

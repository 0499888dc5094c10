// Cost of building the anatomy: procedural prostate generation and TetGen tetrahedralization, at the
// paper's finest model (8640 triangles) and beyond. Run: build/release/benchmarks/anatomy_bench
#include <benchmark/benchmark.h>

#include "rtcore/anatomy/prostate.h"
#include "rtcore/mesh/mesh_validation.h"
#include "rtcore/tissue/tetrahedralize.h"

namespace resecto {
namespace {

void BM_GenerateProstate(benchmark::State& state) {
  const int triangles = static_cast<int>(state.range(0));
  for (auto _ : state) {
    ProstateModel model = generate_prostate(triangles);
    benchmark::DoNotOptimize(model.surface.positions.data());
  }
  state.counters["triangles"] = static_cast<double>(generate_prostate(triangles).surface.triangle_count());
}
BENCHMARK(BM_GenerateProstate)->Arg(8640)->Arg(34560)->Arg(138240)->Unit(benchmark::kMillisecond);

void BM_ValidateSurface(benchmark::State& state) {
  const ProstateModel model = generate_prostate(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    Result<SurfaceReport> report = validate_closed_surface(model.surface);
    benchmark::DoNotOptimize(report.ok());
  }
}
BENCHMARK(BM_ValidateSurface)->Arg(8640)->Arg(138240)->Unit(benchmark::kMillisecond);

void BM_Tetrahedralize(benchmark::State& state) {
  const ProstateModel model = generate_prostate(static_cast<int>(state.range(0)));
  TetrahedralizeOptions options;
  options.channel_axis = {{0.0, 0.0, 0.0}, {0.0, 0.0, model.shape.length_m}};
  std::size_t tetrahedra = 0;
  for (auto _ : state) {
    Result<TetMesh> tetra = tetrahedralize(model.surface, options);
    if (!tetra) {
      state.SkipWithError(tetra.error().c_str());
      break;
    }
    tetrahedra = tetra->tetrahedron_count();
  }
  state.counters["tetrahedra"] = static_cast<double>(tetrahedra);
}
BENCHMARK(BM_Tetrahedralize)->Arg(8640)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace resecto

BENCHMARK_MAIN();

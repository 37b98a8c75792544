// Paraxial speed: ParaxialSpectralTable (64 wavelengths, 380-780 nm) and ParaxialSystem construction,
// on Smith's Cooke triplet (7 surfaces, model glasses) and Angenieux's double Gauss (US 2,701,982,
// 15 surfaces, Schott catalogue glasses). Figures and the 1 ms budget: docs/performance.md.
#include <benchmark/benchmark.h>

#include <cmath>
#include <optional>

#include "lensmith/glass/glass_catalog.h"
#include "lensmith/paraxial/paraxial_spectral_table.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "reference_lenses.h"

namespace {

using namespace lensmith;
using lensmith::testing::angenieux_double_gauss;
using lensmith::testing::smith_cooke_triplet;

void BM_SpectralTable(benchmark::State& state, Prescription (*make)()) {
  const Prescription lens = make();
  for (auto _ : state) {
    ParaxialSpectralTable table(lens);
    benchmark::DoNotOptimize(table.samples().data());
  }
  state.counters["surfaces"] = static_cast<double>(lens.surfaces.size());
  state.counters["wavelengths"] = 64;
}

void BM_SystemConstruction(benchmark::State& state, Prescription (*make)()) {
  const Prescription lens = make();
  for (auto _ : state) {
    ParaxialSystem system(lens);
    benchmark::DoNotOptimize(system.efl_mm());
  }
  state.counters["surfaces"] = static_cast<double>(lens.surfaces.size());
}

// A finite object (2 m) exercises the image-conjugate path of the kernel.
void BM_SpectralTableFiniteObject(benchmark::State& state) {
  const Prescription lens = angenieux_double_gauss();
  SpectralTableOptions options;
  options.object_distance_mm = 2000.0;
  for (auto _ : state) {
    ParaxialSpectralTable table(lens, options);
    benchmark::DoNotOptimize(table.samples().data());
  }
}

}  // namespace

BENCHMARK_CAPTURE(BM_SpectralTable, smith_triplet_7_surfaces, smith_cooke_triplet)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_SpectralTable, double_gauss_15_surfaces, angenieux_double_gauss)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SpectralTableFiniteObject)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_SystemConstruction, smith_triplet_7_surfaces, smith_cooke_triplet)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_SystemConstruction, double_gauss_15_surfaces, angenieux_double_gauss)
    ->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();

// Wavefront and FFT MTF speed (issue 19): Angenieux's double Gauss (US 2,701,982, 15 surfaces, Schott glasses)
// at 3 fields x 3 wavelengths, its field 20 degrees; the pupil grid 64 (the default) and 256 across (the
// issue's budget case), the MTF's transform 4x (default) and 2x padded. Figures: docs/performance.md.
#include <benchmark/benchmark.h>

#include "lensmith/analysis/mtf.h"
#include "lensmith/analysis/wavefront.h"
#include "reference_lenses.h"

namespace {

using namespace lensmith;

AnalysisContext double_gauss() {
  AnalysisOptions o;
  o.max_field_angle_deg = 20.0;  // the patent's half field; the lentil entry gives none
  return AnalysisContext(testing::angenieux_double_gauss(), o);
}

void BM_Wavefront(benchmark::State& state) {
  const AnalysisContext context = double_gauss();
  WavefrontOptions options;
  options.grid = static_cast<int>(state.range(0));
  for (auto _ : state) {
    const Wavefront w = compute_wavefront(context, options);
    benchmark::DoNotOptimize(w.maps.data());
  }
  state.counters["rays"] = 9.0 * options.grid * options.grid * 0.785;
}

void BM_Mtf(benchmark::State& state) {
  const AnalysisContext context = double_gauss();
  MtfOptions options;
  options.pupil_samples = static_cast<int>(state.range(0));
  options.padding = static_cast<int>(state.range(1));
  for (auto _ : state) {
    const Mtf m = compute_mtf(context, options);
    benchmark::DoNotOptimize(m.fields.data());
  }
}

}  // namespace

BENCHMARK(BM_Wavefront)->Arg(64)->Arg(256)->Unit(benchmark::kMillisecond)->Repetitions(3)->ReportAggregatesOnly(true);
BENCHMARK(BM_Mtf)->Args({64, 4})->Args({256, 2})->Unit(benchmark::kMillisecond)->Repetitions(3)->ReportAggregatesOnly(true);

BENCHMARK_MAIN();

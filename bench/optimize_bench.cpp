// Optimisation speed (issue 19): one merit evaluation, one iteration, and a whole run. The merit: RMS spot
// over 3 fields x F, d, C with 61 rays each (4 hexapolar rings), the EFL solved on the last curvature.
// Lenses: the Sasian triplet spoilt as in tests/design (8 variables) and Angenieux's double Gauss (15
// surfaces; its 10 curvatures but the last and 4 air spaces free). Figures: docs/performance.md.
#include <benchmark/benchmark.h>

#include "lensmith/design/optimizer.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "reference_lenses.h"

namespace {

using namespace lensmith;

DesignVariable variable(DesignVariable::Kind kind, int surface) {
  DesignVariable v;
  v.kind = kind;
  v.surface = surface;
  return v;
}

Operand spot() {
  Operand o;
  o.kind = Operand::Kind::SpotRms;
  o.rings = 4;
  return o;
}

struct Problem {
  Prescription lens;
  MeritFunction merit;
};

Problem rough_triplet() {
  Problem p;
  p.lens = testing::sasian_triplet();
  p.lens.image_at_paraxial_focus = false;
  p.lens.surfaces.back().thickness_mm = ParaxialSystem(p.lens).image_distance_mm();
  const double factors[] = {1.12, 0.9, 1.15, 0.88, 1.1, 0.92};
  for (int k = 0; k < 6; ++k) p.lens.surfaces[static_cast<std::size_t>(k)].curvature_per_mm *= factors[k];
  p.lens.surfaces[1].thickness_mm *= 1.2;
  p.lens.surfaces[3].thickness_mm *= 0.8;
  for (int k = 1; k <= 5; ++k) p.merit.variables.push_back(variable(DesignVariable::Kind::Curvature, k));
  for (int k : {2, 4, 6}) p.merit.variables.push_back(variable(DesignVariable::Kind::Thickness, k));
  p.merit.efl_solve = EflSolve{6, 50.0};
  p.merit.operands = {spot()};
  return p;
}

Problem double_gauss() {
  Problem p;
  p.lens = testing::angenieux_double_gauss();
  p.merit.field_angle_deg = 20.0;  // the patent's half field
  const int last = static_cast<int>(p.lens.surfaces.size());
  for (int k = 1; k < last; ++k) {
    const Surface& s = p.lens.surfaces[static_cast<std::size_t>(k - 1)];
    if (!s.is_plane() && !s.is_stop) p.merit.variables.push_back(variable(DesignVariable::Kind::Curvature, k));
  }
  for (int k = 1; k < last; ++k) {
    const Surface& s = p.lens.surfaces[static_cast<std::size_t>(k - 1)];
    if (s.medium.is_air() && p.merit.variables.size() < 14) p.merit.variables.push_back(variable(DesignVariable::Kind::Thickness, k));
  }
  p.merit.efl_solve = EflSolve{last, ParaxialSystem(p.lens).efl_mm()};
  p.merit.operands = {spot()};
  return p;
}

Problem problem(int which) { return which == 0 ? rough_triplet() : double_gauss(); }

void BM_MeritEvaluation(benchmark::State& state) {
  const Problem p = problem(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    const MeritEvaluation e = evaluate_merit(p.lens, p.merit);
    benchmark::DoNotOptimize(e.merit);
  }
  state.counters["variables"] = static_cast<double>(p.merit.variables.size());
}

// One Levenberg-Marquardt iteration (a Jacobian of 2n evaluations, the step's evaluation) and one BFGS
// iteration after it.
void BM_OptimizeOneIteration(benchmark::State& state) {
  const Problem p = problem(static_cast<int>(state.range(0)));
  OptimizeOptions options;
  options.max_iterations = 1;
  options.threads = static_cast<int>(state.range(1));
  std::size_t evaluations = 0;
  for (auto _ : state) {
    const OptimizeResult r = optimize(p.lens, p.merit, options);
    evaluations = r.evaluations;
    benchmark::DoNotOptimize(r.after.merit);
  }
  state.counters["evaluations"] = static_cast<double>(evaluations);
  state.counters["variables"] = static_cast<double>(p.merit.variables.size());
}

void BM_OptimizeTriplet(benchmark::State& state) {
  const Problem p = rough_triplet();
  OptimizeOptions options;
  options.threads = static_cast<int>(state.range(0));
  std::size_t evaluations = 0;
  int iterations = 0;
  for (auto _ : state) {
    const OptimizeResult r = optimize(p.lens, p.merit, options);
    evaluations = r.evaluations;
    iterations = r.iterations;
    benchmark::DoNotOptimize(r.after.merit);
  }
  state.counters["evaluations"] = static_cast<double>(evaluations);
  state.counters["iterations"] = iterations;
}

}  // namespace

BENCHMARK(BM_MeritEvaluation)->ArgName("lens")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OptimizeOneIteration)->ArgNames({"lens", "threads"})->Args({0, 1})->Args({0, 2})->Args({1, 1})->Args({1, 2})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_OptimizeTriplet)->ArgName("threads")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_MAIN();

// lensmith bokeh at 1920 x 1080: per ray model, blur size and thread count (docs/performance.md).
// The scene: a textured image with highlights; the left half on the focus plane, the right half in
// front of it at the depth whose thin-lens blur diameter is the benchmark's argument (pixels of the pinhole image).
#include <benchmark/benchmark.h>

#include <cmath>

#include "lensmith/core/units.h"
#include "lensmith/prescription/lens_library.h"
#include "lensmith/render/bokeh_renderer.h"
#include "lensmith/render/ewa_renderer.h"
#include "lensmith/render/gather_renderer.h"
#include "lensmith/render/lightfield_renderer.h"

using namespace lensmith;

namespace {

constexpr int kWidth = 1920, kHeight = 1080;
constexpr double kFocalMm = 50.0, kFNumber = 2.0, kFocusMm = 2000.0, kSensorMm = 36.0;

struct BenchScene {
  Image image{kWidth, kHeight, 3};
  DepthMap depth{kWidth, kHeight, 2.0f};
};

// Depth (m) in front of the focus plane whose thin-lens blur is `blur_px` output pixels.
double depth_for_blur(double blur_px) {
  const double pitch = kSensorMm / kWidth, a = kFocalMm / kFNumber;
  // A f (s - z) / (z s) = b p  ->  z = A f s / (A f + b p s)
  return m_from_mm(a * kFocalMm * kFocusMm / (a * kFocalMm + blur_px * pitch * kFocusMm));
}

BenchScene make_scene(double blur_px) {
  BenchScene s;
  const auto far_m = static_cast<float>(depth_for_blur(blur_px));
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const float checker = ((x / 24 + y / 24) % 2) ? 0.8f : 0.2f;
      s.image.at(x, y, 0) = checker * (0.5f + 0.5f * std::sin(0.01f * static_cast<float>(x)));
      s.image.at(x, y, 1) = checker;
      s.image.at(x, y, 2) = checker * (0.5f + 0.5f * std::cos(0.013f * static_cast<float>(y)));
      if (x % 97 == 0 && y % 89 == 0) {
        for (int c = 0; c < 3; ++c) s.image.at(x, y, c) = 100.0f;
      }
      s.depth.at(x, y) = x < kWidth / 2 ? static_cast<float>(m_from_mm(kFocusMm)) : far_m;
    }
  }
  return s;
}

// The thin lens, or the shipped pbrt-dgauss-50mm through `kind`, at f/2 focused at the scene's focus.
auto bench_model(RayModelKind kind) {
  CameraOptions o;
  o.focus_distance_m = m_from_mm(kFocusMm);
  o.f_number = kFNumber;
  o.framing.sensor_width_mm = kSensorMm;
  o.framing.focal_length_mm = kFocalMm;
  const Camera camera = kind == RayModelKind::Thin
                            ? Camera::thin_lens(kFocalMm, o, kWidth, kHeight)
                            : Camera::from_lens(LensLibrary::load("pbrt-dgauss-50mm").prescription, o, kWidth, kHeight);
  RayModelOptions mo;
  mo.nearest_depth_m = 0.2;
  return make_ray_model(kind, camera, mo);
}

// `light_images` false: the exact and poly models' footprints as their mesh triangles (for comparison).
void run_with(benchmark::State& state, RayModelKind kind, bool light_images) {
  const double blur = static_cast<double>(state.range(0));
  const BenchScene scene = make_scene(blur);
  const auto model = bench_model(kind);
  BokehOptions options;
  options.threads = static_cast<int>(state.range(1));
  options.light_images = light_images;
  BokehStatistics stats;
  for (auto _ : state) {
    Image out = render_bokeh(scene.image, scene.depth, *model, Aperture::circular(), options, &stats);
    benchmark::DoNotOptimize(out.data.data());
  }
  state.counters["Mpixel/s"] = benchmark::Counter(static_cast<double>(kWidth) * kHeight * 1e-6,
                                                  benchmark::Counter::kIsIterationInvariantRate);
  // What the deposit had to do: footprints (one per wavelength group) and mesh triangles per pixel.
  const double pixels = static_cast<double>(kWidth) * kHeight;
  state.counters["footprints/px"] = static_cast<double>(stats.footprints) / pixels;
  state.counters["triangles/px"] = static_cast<double>(stats.triangles) / pixels;
  state.counters["reused/px"] = static_cast<double>(stats.reused_shapes) / pixels;
  state.counters["light_images"] = static_cast<double>(stats.light_images);
}

void run(benchmark::State& state, RayModelKind kind) { run_with(state, kind, true); }
void run_meshes(benchmark::State& state, RayModelKind kind) { run_with(state, kind, false); }

// Yu et al.'s light-field synthesis on the same scene (36 views, their default): its cost is the
// views' warps, which the blur should not change (their table 1 scales with the views alone).
void run_lightfield(benchmark::State& state, RayModelKind kind) {
  const double blur = static_cast<double>(state.range(0));
  const BenchScene scene = make_scene(blur);
  const auto model = bench_model(kind);
  LightfieldOptions options;
  options.threads = static_cast<int>(state.range(1));
  options.views = static_cast<int>(state.range(2));
  for (auto _ : state) {
    Image out = render_lightfield(scene.image, scene.depth, *model, Aperture::circular(), options);
    benchmark::DoNotOptimize(out.data.data());
  }
  state.counters["Mpixel/s"] = benchmark::Counter(static_cast<double>(kWidth) * kHeight * 1e-6,
                                                  benchmark::Counter::kIsIterationInvariantRate);
}

// Křivánek et al.'s EWA splatting on the same scene: with the level of detail its cost should stay
// nearly flat as the blur grows (their table 1), without it grow with the blur's area.
void run_ewa(benchmark::State& state, RayModelKind kind) {
  const double blur = static_cast<double>(state.range(0));
  const BenchScene scene = make_scene(blur);
  const auto model = bench_model(kind);
  EwaOptions options;
  options.threads = static_cast<int>(state.range(1));
  options.level_of_detail = state.range(2) != 0;
  for (auto _ : state) {
    Image out = render_ewa(scene.image, scene.depth, *model, Aperture::circular(), options);
    benchmark::DoNotOptimize(out.data.data());
  }
  state.counters["Mpixel/s"] = benchmark::Counter(static_cast<double>(kWidth) * kHeight * 1e-6,
                                                  benchmark::Counter::kIsIterationInvariantRate);
}

// Jimenez's half-resolution gather on the same scene: a fixed number of taps per pixel (49 or 81),
// so its cost should not grow with the blur, as in the real-time engines it comes from.
void run_gather(benchmark::State& state, RayModelKind kind) {
  const double blur = static_cast<double>(state.range(0));
  const BenchScene scene = make_scene(blur);
  const auto model = bench_model(kind);
  GatherOptions options;
  options.threads = static_cast<int>(state.range(1));
  options.rings = static_cast<int>(state.range(2));
  for (auto _ : state) {
    Image out = render_gather(scene.image, scene.depth, *model, Aperture::circular(), options);
    benchmark::DoNotOptimize(out.data.data());
  }
  state.counters["Mpixel/s"] = benchmark::Counter(static_cast<double>(kWidth) * kHeight * 1e-6,
                                                  benchmark::Counter::kIsIterationInvariantRate);
}

void gather_args(benchmark::internal::Benchmark* b) {
  for (int blur : {4, 16, 48, 128}) b->Args({blur, 2, 3});
  b->Args({48, 2, 4});
  b->ArgNames({"blur_px", "threads", "rings"})->Unit(benchmark::kSecond)->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(true)->UseRealTime();
}

void ewa_args(benchmark::internal::Benchmark* b) {
  for (int blur : {4, 16, 48, 128}) b->Args({blur, 2, 1});
  for (int blur : {4, 16, 48}) b->Args({blur, 2, 0});
  b->ArgNames({"blur_px", "threads", "lod"})->Unit(benchmark::kSecond)->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(true)->UseRealTime();
}

void lightfield_args(benchmark::internal::Benchmark* b) {
  for (int blur : {4, 16, 48, 128}) b->Args({blur, 2, 36});
  b->Args({16, 2, 12});
  b->ArgNames({"blur_px", "threads", "views"})->Unit(benchmark::kSecond)->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(true)->UseRealTime();
}

void args(benchmark::internal::Benchmark* b) {
  for (int threads : {1, 2}) {
    for (int blur : {4, 16, 48, 128}) b->Args({blur, threads});
  }
  b->ArgNames({"blur_px", "threads"})->Unit(benchmark::kSecond)->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(true)->UseRealTime();
}

void aimed_args(benchmark::internal::Benchmark* b) {
  for (const int blur : {4, 16, 128}) b->Args({blur, 2});
  b->ArgNames({"blur_px", "threads"})->Unit(benchmark::kSecond)->Iterations(1)->Repetitions(1)->UseRealTime();
}

}  // namespace

BENCHMARK_CAPTURE(run, thin, RayModelKind::Thin)->Apply(args);
BENCHMARK_CAPTURE(run, paraxial, RayModelKind::Paraxial)->Apply(args);
BENCHMARK_CAPTURE(run, seidel, RayModelKind::Seidel)->Apply(args);
// The models that aim every ray (poly: on the fit, made in the run before timing; exact: through the
// prescription), drawn from light images, take seconds a frame here: one blur, 2 threads, one run each.
BENCHMARK_CAPTURE(run, poly, RayModelKind::Poly)->Apply(aimed_args);
BENCHMARK_CAPTURE(run, exact, RayModelKind::Exact)->Apply(aimed_args);
// The same two models with every footprint's mesh triangles deposited (BokehOptions::light_images
// off): what they took before light images, about ten times as long.
BENCHMARK_CAPTURE(run_meshes, poly, RayModelKind::Poly)->Apply(aimed_args);
BENCHMARK_CAPTURE(run_meshes, exact, RayModelKind::Exact)->Apply(aimed_args);
BENCHMARK_CAPTURE(run_lightfield, thin, RayModelKind::Thin)->Apply(lightfield_args);
BENCHMARK_CAPTURE(run_lightfield, seidel, RayModelKind::Seidel)->Apply(lightfield_args);
BENCHMARK_CAPTURE(run_ewa, thin, RayModelKind::Thin)->Apply(ewa_args);
BENCHMARK_CAPTURE(run_ewa, seidel, RayModelKind::Seidel)->Apply(ewa_args);
BENCHMARK_CAPTURE(run_gather, thin, RayModelKind::Thin)->Apply(gather_args);
BENCHMARK_CAPTURE(run_gather, seidel, RayModelKind::Seidel)->Apply(gather_args);

BENCHMARK_MAIN();

// lensmith bokeh --method multiview at 1920 x 1080 (issue 13; docs/performance.md): 8 depth layers,
// 32 lens rays per pixel, the double Gauss at f/2 through the exact tracer and through its
// polynomial fit, 2 threads; the scatter method on the same scene's flat picture in the same run
// as the reference. Lee, Eisemann & Seidel (2009) report 32 to 62 frames/s for 800 x 600, 32
// samples and 8 layers on a GTX 285 (their table 1).
//
// The scene, a layered image like `lensmith scene render --pinhole --layers` writes: a textured
// wall at 6 m with highlights, bright slats at 1 m every 120 px (20 px wide) with the wall behind
// them as a second sample, and small lights at 3 m between them; focus 3 m.
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>

#include "lensmith/core/units.h"
#include "lensmith/polyfit/lens_fit.h"
#include "lensmith/prescription/lens_library.h"
#include "lensmith/render/bokeh_renderer.h"
#include "lensmith/render/multiview_renderer.h"

using namespace lensmith;

namespace {

constexpr int kWidth = 1920, kHeight = 1080;

struct BenchScene {
  DeepImage deep;
  Image flat{kWidth, kHeight, 3};
  DepthMap depth{kWidth, kHeight, 6.0f};
};

const BenchScene& scene() {
  static const BenchScene s = [] {
    BenchScene b;
    b.deep = DeepImage(kWidth, kHeight);
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        const float t = 0.04f + 0.03f * std::sin(0.021f * static_cast<float>(x)) * std::cos(0.017f * static_cast<float>(y));
        const bool highlight = x % 97 == 0 && y % 89 == 0;
        const std::array<float, 3> wall_rgb = highlight ? std::array<float, 3>{60.0f, 50.0f, 40.0f} : std::array<float, 3>{t, t, 0.9f * t};
        const DeepSample wall{wall_rgb, 1.0f, 6.0f, 6.0f};
        const bool slat = x % 120 < 20, light = !slat && x % 120 == 60 && y % 180 == 90;
        std::array<float, 3> shown = wall_rgb;
        float z = 6.0f;
        if (slat) {
          const DeepSample front{{0.55f, 0.42f, 0.3f}, 1.0f, 1.0f, 1.0f};
          b.deep.push_pixel({front, wall});
          shown = front.rgb;
          z = 1.0f;
        } else if (light) {
          const DeepSample lamp{{200.0f, 180.0f, 120.0f}, 1.0f, 3.0f, 3.0f};
          b.deep.push_pixel({lamp, wall});
          shown = lamp.rgb;
          z = 3.0f;
        } else {
          b.deep.push_pixel({wall});
        }
        for (int c = 0; c < 3; ++c) b.flat.at(x, y, c) = shown[static_cast<std::size_t>(c)];
        b.depth.at(x, y) = z;
      }
    }
    return b;
  }();
  return s;
}

Camera dgauss_camera() {
  CameraOptions o;
  o.focus_distance_m = 3.0;
  o.f_number = 2.0;
  return Camera::from_lens(LensLibrary::load("pbrt-dgauss-50mm").prescription, o, kWidth, kHeight);
}

std::unique_ptr<RayModel> model_for(RayModelKind kind, const Camera& camera) {
  RayModelOptions mo;
  mo.nearest_depth_m = 1.0;
  if (kind == RayModelKind::Poly) mo.fit = std::make_shared<const LensFit>(LensFit::fit(*camera.lens(), lens_fit_options_for(camera)));
  return make_ray_model(kind, camera, mo);
}

void multiview(benchmark::State& state, RayModelKind kind) {
  const BenchScene& s = scene();
  const Camera camera = dgauss_camera();
  const auto model = model_for(kind, camera);
  MultiviewOptions options;
  options.samples = 32;
  options.layers = 8;
  options.threads = static_cast<int>(state.range(0));
  for (auto _ : state) {
    Image out = render_multiview(s.deep, *model, Aperture::circular(), options);
    benchmark::DoNotOptimize(out.data.data());
  }
  state.counters["Mpixel/s"] = benchmark::Counter(static_cast<double>(kWidth) * kHeight * 1e-6, benchmark::Counter::kIsIterationInvariantRate);
}

// The reference in the same run: the scatter method (Seidel, the default model) on the flat picture.
void scatter(benchmark::State& state) {
  const BenchScene& s = scene();
  const Camera camera = dgauss_camera();
  const auto model = model_for(RayModelKind::Seidel, camera);
  BokehOptions options;
  options.threads = static_cast<int>(state.range(0));
  for (auto _ : state) {
    Image out = render_bokeh(s.flat, s.depth, *model, Aperture::circular(), options);
    benchmark::DoNotOptimize(out.data.data());
  }
}

void args(benchmark::internal::Benchmark* b) {
  b->Arg(2)->ArgName("threads")->Unit(benchmark::kSecond)->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(true)->UseRealTime();
}

}  // namespace

BENCHMARK_CAPTURE(multiview, poly, RayModelKind::Poly)->Apply(args);
BENCHMARK_CAPTURE(multiview, exact, RayModelKind::Exact)->Apply(args);
BENCHMARK_CAPTURE(multiview, seidel, RayModelKind::Seidel)->Apply(args);
BENCHMARK(scatter)->Apply(args);

BENCHMARK_MAIN();

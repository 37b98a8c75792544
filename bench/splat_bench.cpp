// SplatBuffer speed: ns per add_polygon for 64-gon discs 2, 20 and 200 px across (full-height buffer
// and a 32-row band, as one renderer thread sees it), per 3-px triangle (a mapped pupil mesh), and
// per pixel for the prefix-sum resolve. Default 4 sub-rows; a disc costs O(its height in sub-rows).
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "lensmith/render/splat_buffer.h"

namespace {

using namespace lensmith;

constexpr int kSize = 512;         // px, square image
constexpr int kVariants = 64;      // sub-pixel placements cycled through, so no branch is always taken
constexpr std::array<float, 4> kValue = {1.0f, 0.8f, 0.6f, 1.0f};

std::vector<Point2f> disc(double cx, double cy, double diameter_px) {
  std::vector<Point2f> v;
  for (int k = 0; k < 64; ++k) {
    const double t = 2.0 * std::numbers::pi * k / 64;
    v.push_back({static_cast<float>(cx + 0.5 * diameter_px * std::cos(t)),
                 static_cast<float>(cy + 0.5 * diameter_px * std::sin(t))});
  }
  return v;
}

std::vector<std::vector<Point2f>> discs(double diameter_px) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> jitter(-0.5, 0.5);
  std::vector<std::vector<Point2f>> out;
  for (int k = 0; k < kVariants; ++k) {
    out.push_back(disc(kSize / 2 + jitter(rng), kSize / 2 + jitter(rng), diameter_px));
  }
  return out;
}

// range(0): disc diameter in px; range(1): band height in rows (the band is centred on the disc).
void BM_SplatDisc(benchmark::State& state) {
  const auto diameter_px = static_cast<double>(state.range(0));
  const auto band_rows = static_cast<int>(state.range(1));
  const auto polygons = discs(diameter_px);
  SplatBuffer buffer(kSize, kSize / 2 - band_rows / 2, kSize / 2 - band_rows / 2 + band_rows);
  std::size_t k = 0;
  for (auto _ : state) {
    buffer.add_polygon(polygons[k++ % kVariants], kValue);
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());  // one polygon per iteration: Time is ns per polygon
}

// range(0): the px square the triangles' centres are spread over: 40 is one source pixel's mapped
// pupil mesh (its rows stay in cache), 500 scatters them over the whole 8 MB buffer (cache misses).
void BM_SplatTriangle(benchmark::State& state) {
  const auto spread_px = static_cast<double>(state.range(0));
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> pos(0.5 * (kSize - spread_px), 0.5 * (kSize + spread_px));
  std::uniform_real_distribution<double> angle(0.0, 2.0 * std::numbers::pi);
  std::vector<std::array<Point2f, 3>> triangles;
  for (int k = 0; k < 4096; ++k) {
    const double cx = pos(rng);
    const double cy = pos(rng);
    const double a = angle(rng);
    std::array<Point2f, 3> t;
    for (int v = 0; v < 3; ++v) {  // equilateral, 3 px across
      const double t_v = a + 2.0 * std::numbers::pi * v / 3;
      t[static_cast<std::size_t>(v)] = {static_cast<float>(cx + 1.5 * std::cos(t_v)),
                                        static_cast<float>(cy + 1.5 * std::sin(t_v))};
    }
    triangles.push_back(t);
  }
  SplatBuffer buffer(kSize, 0, kSize);
  std::size_t k = 0;
  for (auto _ : state) {
    const auto& t = triangles[k++ % triangles.size()];
    buffer.add_triangle(t[0], t[1], t[2], kValue);
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());  // one polygon per iteration: Time is ns per polygon
}

// A 3840 x 64 band resolved into a 4-channel float image.
void BM_Resolve(benchmark::State& state) {
  constexpr int kWidth = 3840;
  constexpr int kRows = 64;
  SplatBuffer buffer(kWidth, 0, kRows);
  buffer.add_polygon(disc(1000.0, 32.0, 50.0), kValue);
  std::vector<float> image(static_cast<std::size_t>(kWidth) * kRows * 4, 0.0f);
  for (auto _ : state) {
    buffer.resolve_into(image.data());
    benchmark::DoNotOptimize(image.data());
  }
  state.SetItemsProcessed(state.iterations() * kWidth * kRows);  // pixels
}

}  // namespace

BENCHMARK(BM_SplatDisc)->ArgNames({"diameter_px", "band_rows"})
    ->Args({2, kSize})->Args({20, kSize})->Args({200, kSize})->Args({200, 32});
BENCHMARK(BM_SplatTriangle)->ArgName("spread_px")->Arg(40)->Arg(500);
BENCHMARK(BM_Resolve);

BENCHMARK_MAIN();

// SplatBuffer against its definition: a polygon carrying v deposits v/A * integral of the separable
// unit tent T(x - c_i) T(y - c_j) over it (exact in x, S midpoint sub-rows in y), checked by
// independent brute-force integration, energy conservation, flat fields and band independence.
#include "lensmith/render/splat_buffer.h"

#include <catch2/catch.hpp>
#include <algorithm>
#include <functional>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "lensmith/core/errors.h"
#include "lensmith/render/image.h"

using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using namespace lensmith;

namespace {

using Rgba = std::array<float, 4>;
constexpr Rgba kValue = {1.0f, 0.5f, 0.25f, 2.0f};  // a different energy per channel

// The output image is float: summing a deposit over many pixels carries their float rounding
// (relative 6e-8 each) and the double geometry's; 1e-6 is far above both and far below any loss.
constexpr double kEnergyRoundoff = 1e-6;

// A regular n-gon inscribed in the circle of diameter_px about centre, first vertex at angle phase.
std::vector<Point2f> disc(double cx, double cy, double diameter_px, int n = 64, double phase = 0.0) {
  std::vector<Point2f> v;
  for (int k = 0; k < n; ++k) {
    const double t = phase + 2.0 * std::numbers::pi * k / n;
    v.push_back({static_cast<float>(cx + 0.5 * diameter_px * std::cos(t)),
                 static_cast<float>(cy + 0.5 * diameter_px * std::sin(t))});
  }
  return v;
}

Image resolved(const SplatBuffer& buffer, int height) {
  Image image(buffer.width(), height, 4);
  buffer.resolve_into(image);
  return image;
}

double channel_sum(const Image& image, int c) {
  double sum = 0.0;
  for (std::size_t p = 0; p < image.pixel_count(); ++p) sum += image.data[p * 4 + c];
  return sum;
}

double max_abs_difference(const Image& a, const Image& b) {
  double worst = 0.0;
  for (std::size_t k = 0; k < a.data.size(); ++k) worst = std::max(worst, std::abs(double{a.data[k]} - b.data[k]));
  return worst;
}

double tent(double u) { return std::max(0.0, 1.0 - std::abs(u)); }

// Integral of T(x - c) over [a, b], independent of the library's Phi: T is linear between the kinks
// c - 1, c, c + 1, where the midpoint rule is exact.
double tent_integral(double a, double b, double c) {
  const double cuts[] = {a, std::clamp(c - 1.0, a, b), std::clamp(c, a, b), std::clamp(c + 1.0, a, b), b};
  double sum = 0.0;
  for (int k = 0; k < 4; ++k) sum += (cuts[k + 1] - cuts[k]) * tent(0.5 * (cuts[k] + cuts[k + 1]) - c);
  return sum;
}

// The x-intervals of any simple polygon at height y: its edge crossings (half-open in y), sorted,
// paired inside-outside.
std::vector<std::pair<double, double>> spans_at(const std::vector<Point2f>& poly, double y) {
  std::vector<double> xs;
  for (std::size_t k = 0; k < poly.size(); ++k) {
    const Point2f p = poly[k];
    const Point2f q = poly[(k + 1) % poly.size()];
    const double y0 = std::min(p.y, q.y);
    const double y1 = std::max(p.y, q.y);
    if (!(y >= y0 && y < y1)) continue;
    xs.push_back(p.x + (q.x - p.x) * (y - p.y) / (q.y - p.y));
  }
  std::sort(xs.begin(), xs.end());
  std::vector<std::pair<double, double>> spans;
  for (std::size_t j = 0; j + 1 < xs.size(); j += 2) spans.emplace_back(xs[j], xs[j + 1]);
  return spans;
}

// Brute-force tent-filtered deposit of value 1 into a width x height image, y sampled at
// samples_per_px midpoints per pixel row, normalised by `area` (0: by the sampled area).
std::vector<double> reference_deposit(const std::vector<Point2f>& poly, int width, int height, int samples_per_px,
                                      double area) {
  std::vector<double> image(static_cast<std::size_t>(width) * height, 0.0);
  double sampled_area = 0.0;
  for (int s = 0; s < height * samples_per_px; ++s) {
    const double y = (s + 0.5) / samples_per_px;
    for (const auto& [a, b] : spans_at(poly, y)) {
      sampled_area += (b - a) / samples_per_px;
      for (int j = 0; j < height; ++j) {
        const double wy = tent(y - (j + 0.5)) / samples_per_px;
        if (wy == 0.0) continue;
        for (int i = 0; i < width; ++i) {
          image[static_cast<std::size_t>(j) * width + i] += wy * tent_integral(a, b, i + 0.5);
        }
      }
    }
  }
  const double norm = area > 0.0 ? area : sampled_area;
  for (double& v : image) v /= norm;
  return image;
}

// Largest |image(c) / value(c) - reference| over pixels and channels.
double max_deviation(const Image& image, const std::vector<double>& reference) {
  double worst = 0.0;
  for (std::size_t p = 0; p < image.pixel_count(); ++p) {
    for (int c = 0; c < 4; ++c) {
      worst = std::max(worst, std::abs(image.data[p * 4 + c] / kValue[static_cast<std::size_t>(c)] - reference[p]));
    }
  }
  return worst;
}

}  // namespace

TEST_CASE("splat buffer: a disc deposits exactly its value when inside the image, 0.3 to 200 px across", "[render][splat]") {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> jitter(-0.5, 0.5);
  for (const double diameter_px : {0.3, 1.0, 2.5, 10.0, 200.0}) {
    for (int trial = 0; trial < 5; ++trial) {
      const double cx = 128.0 + jitter(rng);
      const double cy = 128.0 + jitter(rng);
      SplatBuffer buffer(256, 0, 256);
      buffer.add_polygon(disc(cx, cy, diameter_px), kValue);
      const Image image = resolved(buffer, 256);
      for (int c = 0; c < 4; ++c) {
        INFO("diameter " << diameter_px << " px at (" << cx << ", " << cy << "), channel " << c);
        const double value = kValue[static_cast<std::size_t>(c)];
        CHECK_THAT(channel_sum(image, c), WithinRel(value, kEnergyRoundoff));
      }
    }
  }
}

TEST_CASE("splat buffer: a point-like square on a pixel centre fills that pixel, and shifted a quarter pixel it splits 0.75 / 0.25", "[render][splat]") {
  constexpr double kRoundoff = 1e-7;  // float image, double weights
  auto square = [](double cx, double cy, double side) {
    const auto h = static_cast<float>(side / 2);
    const auto x = static_cast<float>(cx);
    const auto y = static_cast<float>(cy);
    return std::vector<Point2f>{{x - h, y - h}, {x + h, y - h}, {x + h, y + h}, {x - h, y + h}};
  };
  SplatBuffer centred(12, 0, 12);
  centred.add_polygon(square(5.5, 7.5, 1e-3), kValue);
  const Image a = resolved(centred, 12);
  CHECK_THAT(a.at(5, 7, 0), WithinAbs(1.0, kRoundoff));
  CHECK_THAT(a.at(5, 7, 3), WithinAbs(2.0, kRoundoff));
  CHECK_THAT(channel_sum(a, 0) - a.at(5, 7, 0), WithinAbs(0.0, kRoundoff));

  SplatBuffer shifted(12, 0, 12);
  shifted.add_polygon(square(5.75, 7.5, 1e-3), kValue);
  const Image b = resolved(shifted, 12);
  CHECK_THAT(b.at(5, 7, 0), WithinAbs(0.75, kRoundoff));
  CHECK_THAT(b.at(6, 7, 0), WithinAbs(0.25, kRoundoff));
  CHECK_THAT(channel_sum(b, 0) - b.at(5, 7, 0) - b.at(6, 7, 0), WithinAbs(0.0, kRoundoff));

  SplatBuffer down(12, 0, 12);
  down.add_point({5.5f, 7.25f}, kValue);
  const Image d = resolved(down, 12);
  CHECK_THAT(d.at(5, 6, 0), WithinAbs(0.25, kRoundoff));
  CHECK_THAT(d.at(5, 7, 0), WithinAbs(0.75, kRoundoff));
}

// A crescent opening upwards (a cat's eye's mapped ring that turns back in y): the outer arc of a
// circle about (cx, cy) below the horizontal, the inner arc of a smaller circle back.
std::vector<Point2f> crescent(double cx, double cy) {
  std::vector<Point2f> v;
  for (int k = 0; k <= 16; ++k) {
    const double t = std::numbers::pi * (0.1 + 0.8 * k / 16.0);
    v.push_back({static_cast<float>(cx + 11.3 * std::cos(t)), static_cast<float>(cy + 11.3 * std::sin(t))});
  }
  for (int k = 16; k >= 0; --k) {
    const double t = std::numbers::pi * (0.15 + 0.7 * k / 16.0);
    v.push_back({static_cast<float>(cx + 7.9 * std::cos(t)), static_cast<float>(cy - 1.7 + 7.9 * std::sin(t))});
  }
  return v;
}

TEST_CASE("splat buffer: a triangle, a pentagon, a U and a crescent match a brute-force integral of the tent-filter definition", "[render][splat]") {
  constexpr int kWidth = 48;
  constexpr int kHeight = 40;
  const std::vector<Point2f> triangle = {{10.3f, 8.7f}, {25.1f, 12.2f}, {14.6f, 27.9f}};
  const std::vector<Point2f> pentagon = disc(30.37, 21.81, 14.6, 5, 0.3);
  // Not y-monotone (SplatBuffer's even-odd scan): horizontal lines through the arms cross 4 edges.
  const std::vector<Point2f> u_shape = {{10.3f, 8.2f},  {16.1f, 8.2f},  {16.1f, 24.35f}, {30.6f, 24.35f},
                                        {30.6f, 6.9f},  {36.2f, 6.9f},  {36.2f, 30.7f},  {10.3f, 30.7f}};
  const std::vector<Point2f> moon = crescent(23.4, 17.2);
  const std::pair<const std::vector<Point2f>*, const char*> shapes[] = {
      {&triangle, "triangle"}, {&pentagon, "pentagon"}, {&u_shape, "U"}, {&moon, "crescent"}};
  for (const auto& [poly, name] : shapes) {
    INFO(name);
    for (const int subrows : {4, 16}) {
      INFO(subrows << " sub-rows");
      SplatOptions options;
      options.subrows = subrows;
      SplatBuffer buffer(kWidth, 0, kHeight, options);
      buffer.add_polygon(*poly, kValue);
      const Image image = resolved(buffer, kHeight);

      // Same sampling as the definition (sub-row midpoints, exact x, rasterised area), but every
      // edge intersected per sample and the x integral done piecewise: equal up to the float
      // rounding of pixel values below 0.01 (observed 1.3e-9).
      constexpr double kSameSampling = 1e-8;
      CHECK(max_deviation(image, reference_deposit(*poly, kWidth, kHeight, subrows, 0.0)) < kSameSampling);

      // The true integral (1024 samples per pixel in y, exact area). Sampling y at sub-row centres
      // moves a near-horizontal edge by up to half a sub-row, 1/(2S) px, which changes a pixel by at
      // most that times the density 1/A. Observed: 7.7% of the peak pixel at S = 4 and 1.1% at
      // S = 16 (the pentagon's top edge at y = 15.92 lies between sub-rows); 0.6% and 0.04% for the
      // triangle, whose edges are steeper.
      const double exact_area = polygon_area(*poly);
      const double quadrature = 1.0 / (2.0 * subrows * exact_area);
      CHECK(max_deviation(image, reference_deposit(*poly, kWidth, kHeight, 1024, exact_area)) < quadrature);
      CHECK_THAT(channel_sum(image, 0), WithinRel(1.0, kEnergyRoundoff));
    }
  }
}

TEST_CASE("splat buffer: a polygon at its own sub-row count deposits what a buffer of that count deposits, beside others", "[render][splat]") {
  // The renderer scans tall footprints at fewer sub-rows inside one buffer (footprint_subrows): each
  // polygon must come out as a buffer of its own count would make it, whatever else the buffer holds.
  constexpr int kWidth = 48, kHeight = 40;
  const std::vector<Point2f> moon = crescent(23.4, 17.2);
  const std::vector<Point2f> square{{3.2f, 4.1f}, {12.7f, 4.1f}, {12.7f, 13.9f}, {3.2f, 13.9f}};
  for (const int own : {1, 2, 4, 8}) {
    INFO(own << " sub-rows in a 4-sub-row buffer");
    SplatBuffer mixed(kWidth, 0, kHeight);
    mixed.add_polygon(moon, kValue, own);
    mixed.add_polygon(square, kValue);  // the buffer's own 4
    SplatOptions options;
    options.subrows = own;
    SplatBuffer alone(kWidth, 0, kHeight, options);
    alone.add_polygon(moon, kValue);
    SplatBuffer four(kWidth, 0, kHeight);
    four.add_polygon(square, kValue);
    const Image a = resolved(mixed, kHeight), b = resolved(alone, kHeight), c = resolved(four, kHeight);
    double worst = 0.0;
    for (std::size_t i = 0; i < a.data.size(); ++i) worst = std::max(worst, static_cast<double>(std::abs(a.data[i] - b.data[i] - c.data[i])));
    // Float rounding of the resolved pixels (values below 0.05).
    CHECK(worst < 1e-7);
    // Sampled at `own` sub-rows, the brute-force definition agrees to the same sampling.
    CHECK(max_deviation(b, reference_deposit(moon, kWidth, kHeight, own, 0.0)) < 1e-8);
  }
  SplatBuffer buffer(kWidth, 0, kHeight);
  CHECK_THROWS_WITH(buffer.add_polygon(moon, kValue, 17), Contains("17 sub-rows: must lie in [1, 16], or 0 for the buffer's own"));
  CHECK_THROWS_AS(buffer.add_polygon(moon, kValue, -1), OptionsError);
}

TEST_CASE("splat buffer: unit squares on every pixel give a flat field of 1 across a 3840-px row", "[render][splat]") {
  constexpr int kWidth = 3840;
  constexpr int kHeight = 6;
  constexpr double kFlat = 1e-5;  // the renderer's flat-field bar; observed exactly 1 (the squares are exact in float)
  SplatBuffer buffer(kWidth, 0, kHeight);
  for (int j = 0; j < kHeight; ++j) {
    for (int i = 0; i < kWidth; ++i) {
      const auto x = static_cast<float>(i);
      const auto y = static_cast<float>(j);
      buffer.add_polygon(std::vector<Point2f>{{x, y}, {x + 1, y}, {x + 1, y + 1}, {x, y + 1}}, {1, 1, 1, 1});
    }
  }
  const Image image = resolved(buffer, kHeight);
  double worst = 0.0;
  for (int j = 1; j < kHeight - 1; ++j) {
    for (int i = 1; i < kWidth - 1; ++i) worst = std::max(worst, std::abs(image.at(i, j, 0) - 1.0));
  }
  CHECK(worst < kFlat);
}

TEST_CASE("splat buffer: 7-px discs of value 1 on every pixel give a flat field of 1 away from the border", "[render][splat]") {
  constexpr int kWidth = 3840;
  constexpr int kHeight = 16;
  // The tent-filtered sum of translated normalised discs is exactly 1, but float vertices at
  // x = 2048..3840 round by up to 1.2e-4 px, so the discs are not exact translates: observed 6.9e-6
  // there, 5e-7 below x = 512. 1e-5 is the renderer's flat-field bar.
  constexpr double kFlat = 1e-5;
  constexpr int kMargin = 5;       // a disc (radius 3.5) and the tent (1) reach 4.5 px
  SplatBuffer buffer(kWidth, 0, kHeight);
  for (int j = 0; j < kHeight; ++j) {
    for (int i = 0; i < kWidth; ++i) buffer.add_polygon(disc(i + 0.5, j + 0.5, 7.0), {1, 1, 1, 1});
  }
  const Image image = resolved(buffer, kHeight);
  double worst = 0.0;
  for (int j = kMargin; j < kHeight - kMargin; ++j) {
    for (int i = kMargin; i < kWidth - kMargin; ++i) worst = std::max(worst, std::abs(image.at(i, j, 1) - 1.0));
  }
  CHECK(worst < kFlat);
}

TEST_CASE("splat buffer: a highlight 1e6 times the background leaves the rest of its 3840-px row unchanged", "[render][splat]") {
  // Why the differences are double: in float, the highlight's entries (~1e4) round by ~1e-3 and the
  // prefix sum carries that error along the whole row, a visible streak on a 0.01 background.
  constexpr int kWidth = 3840;
  constexpr double kBackground = 0.01;
  constexpr double kStreak = 1e-4;  // relative to the background: far below one 8-bit code value
  SplatBuffer buffer(kWidth, 0, 3);
  for (int i = 0; i < kWidth; ++i) {
    const auto x = static_cast<float>(i);
    buffer.add_polygon(std::vector<Point2f>{{x, 0}, {x + 1, 0}, {x + 1, 3}, {x, 3}}, {0.03f, 0.03f, 0.03f, 0.03f});
  }
  for (int k = 0; k < 20; ++k) buffer.add_polygon(disc(20.0 + 0.37 * k, 1.5, 9.0 + 0.1 * k), {5e4f, 5e4f, 5e4f, 5e4f});
  const Image image = resolved(buffer, 3);
  double worst = 0.0;
  for (int i = 40; i < kWidth - 1; ++i) worst = std::max(worst, std::abs(image.at(i, 1, 0) / kBackground - 1.0));
  CHECK(worst < kStreak);
}

TEST_CASE("splat buffer: bands of rows 0-36, 37-79 and 80-99 filled separately equal one full-height buffer", "[render][splat]") {
  constexpr int kWidth = 120;
  constexpr int kHeight = 100;
  constexpr double kBandRoundoff = 1e-6;  // same sub-rows, same order: only float output rounding
  SplatBuffer full(kWidth, 0, kHeight);
  std::vector<SplatBuffer> bands;
  bands.emplace_back(kWidth, 0, 37);
  bands.emplace_back(kWidth, 37, 80);
  bands.emplace_back(kWidth, 80, kHeight);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pos(-10.0, 130.0);
  std::uniform_real_distribution<double> size(0.2, 40.0);
  std::uniform_real_distribution<double> step(-3.0, 3.0);
  auto add_everywhere = [&](auto&& add) {
    add(full);
    for (SplatBuffer& b : bands) add(b);
  };
  for (int k = 0; k < 300; ++k) {
    const std::vector<Point2f> d = disc(pos(rng), pos(rng), size(rng), 64, step(rng));
    add_everywhere([&](SplatBuffer& b) { b.add_polygon(d, kValue); });
    const auto x = static_cast<float>(pos(rng));
    const auto y = static_cast<float>(pos(rng));
    const Point2f a{x, y};
    const Point2f b2{x + static_cast<float>(step(rng)), y + static_cast<float>(step(rng))};
    const Point2f c{x + static_cast<float>(step(rng)), y + static_cast<float>(step(rng))};
    add_everywhere([&](SplatBuffer& b) { b.add_triangle(a, b2, c, kValue); });
    add_everywhere([&](SplatBuffer& b) { b.add_point(c, kValue); });
  }
  const Image one = resolved(full, kHeight);
  Image banded(kWidth, kHeight, 4);
  for (const SplatBuffer& b : bands) b.resolve_into(banded);
  CHECK(max_abs_difference(one, banded) < kBandRoundoff);
  CHECK(channel_sum(one, 0) > 10.0);  // the scene did land in the image
  // Each band resolved into rows of its own (a renderer's band-sized layer image) holds exactly its
  // rows of the whole.
  for (const SplatBuffer& b : bands) {
    std::vector<float> rows(static_cast<std::size_t>(b.row_end() - b.row_begin()) * kWidth * 4, 0.0f);
    b.resolve_rows_into(rows.data());
    CHECK(std::equal(rows.begin(), rows.end(), banded.data.begin() + static_cast<std::ptrdiff_t>(b.row_begin()) * kWidth * 4));
  }
}

TEST_CASE("splat buffer: reset from band to band it resolves what a fresh buffer does, and rows it was not drawn in stay 0", "[render][splat]") {
  // A buffer zeroes and resolves only the rows drawn in since its last reset (touched_rows): a
  // renderer's layer reaches a few rows of a band. Drawn in a stripe of each band, by a polygon, a
  // point, points and (at full resolution) a stamp; the previous band's deposits must not survive.
  constexpr int kWidth = 90, kHeight = 120;
  for (const int k : {1, 2}) {
    SplatOptions options;
    options.downsample = k;
    SplatBuffer reused(kWidth, 0, 40, options);
    for (const auto& [begin, end] : std::vector<std::pair<int, int>>{{0, 40}, {40, 100}, {10, 30}, {100, kHeight}, {0, kHeight}}) {
      INFO("1/" << k << " resolution, rows " << begin << " to " << end);
      reused.reset(begin, end);
      SplatBuffer fresh(kWidth, begin, end, options);
      const double y = begin + 0.3 * (end - begin);
      const std::array<std::array<float, 3>, 2> points{{{0.0f, 0.0f, 0.5f}, {1.5f, 0.7f, 0.5f}}};
      const DifferenceStamp stamp = SplatBuffer::record(disc(0.3, 0.2, 3.0), 4);
      const std::vector<std::function<void(SplatBuffer&)>> kinds{
          [&](SplatBuffer& b) { b.add_polygon(disc(20.4, y, 5.0), kValue); },
          [&](SplatBuffer& b) { b.add_point({60.2f, static_cast<float>(y + 2.6)}, kValue); },
          [&](SplatBuffer& b) { b.add_points(points, {1.0f, 0.0f, 0.0f, 1.0f}, {40.3f, static_cast<float>(y)}, kValue); },
          [&](SplatBuffer& b) {
            if (k == 1) b.add_stamp(stamp, 70, static_cast<int>(y), kValue);
          }};
      // Each kind alone, inside the band, keeps its whole value (a deposit whose rows were not marked
      // would resolve to nothing).
      for (std::size_t kind = 0; kind < kinds.size(); ++kind) {
        if (k > 1 && kind == 3) continue;  // stamps are for full-resolution buffers
        SplatBuffer alone(kWidth, begin, end, options);
        kinds[kind](alone);
        INFO("deposit kind " << kind);
        CHECK_THAT(channel_sum(resolved(alone, kHeight), 0), WithinRel(double{kValue[0]}, kEnergyRoundoff));
      }
      auto draw = [&](SplatBuffer& b) {
        for (const auto& add : kinds) add(b);
      };
      draw(reused);
      draw(fresh);
      const Image got = resolved(reused, kHeight), want = resolved(fresh, kHeight);
      CHECK(got.data == want.data);
      CHECK(channel_sum(got, 0) > 1.0);
      // The stripe's rows, and nothing resolved outside them: about 9 px drawn (the 5-px disc, the
      // point 2.6 px below), 2 cells of margin either side (touch_cells) and the cell a coarse grid
      // interpolates from: at most 9 + 4 k + 2 k px, well short of the 60- and 120-row bands.
      const auto [first, last] = reused.touched_rows();
      CHECK(first < last);
      CHECK(last - first <= 9 + 6 * k);
      for (int row = 0; row < kHeight; ++row) {
        if (row >= first && row < last) continue;
        for (int x = 0; x < kWidth; ++x) CHECK(got.at(x, row, 0) == 0.0f);
      }
    }
  }
}

TEST_CASE("splat buffer: a disc over the image edge keeps only the part inside", "[render][splat]") {
  // A 64-gon symmetric about the edge keeps exactly half (the tent and the sub-rows are symmetric
  // about pixel edges too); observed 1.4e-8 from float vertex rounding.
  constexpr double kClip = 1e-6;
  struct Case {
    double cx;
    double cy;
    double kept;
    const char* where;
  };
  for (const Case& k : {Case{0.0, 50.0, 0.5, "left edge"}, Case{100.0, 50.0, 0.5, "right edge"},
                        Case{50.0, 0.0, 0.5, "top edge"}, Case{50.0, 100.0, 0.5, "bottom edge"},
                        Case{0.0, 0.0, 0.25, "top-left corner"}, Case{-30.0, 50.0, 0.0, "outside"}}) {
    INFO(k.where);
    SplatBuffer buffer(100, 0, 100);
    buffer.add_polygon(disc(k.cx, k.cy, 40.0), kValue);
    CHECK_THAT(channel_sum(resolved(buffer, 100), 0), WithinAbs(k.kept, kClip));
  }
}

TEST_CASE("splat buffer: non-finite vertices and values are skipped and counted", "[render][splat]") {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  SplatBuffer buffer(16, 0, 16);
  buffer.add_triangle({1, 1}, {nan, 5}, {8, 8}, kValue);
  buffer.add_polygon(disc(8, 8, 4), {1, inf, 1, 1});
  buffer.add_triangle({1, 1}, {5, -inf}, {8, 8}, kValue);
  buffer.add_point({inf, 3}, kValue);
  buffer.add_polygon({}, kValue);
  CHECK(buffer.skipped() == 5);
  const Image image = resolved(buffer, 16);
  CHECK(channel_sum(image, 0) == 0.0);
  buffer.clear();
  CHECK(buffer.skipped() == 0);
}

TEST_CASE("splat buffer: degenerate polygons (collinear, 1 or 2 vertices) deposit as a point at the vertex centroid", "[render][splat]") {
  constexpr double kRoundoff = 1e-7;
  const std::vector<std::vector<Point2f>> degenerate = {
      {{3.0f, 4.25f}, {6.0f, 4.25f}, {9.0f, 4.25f}},  // horizontal: crosses no sub-row
      {{4.0f, 1.25f}, {6.0f, 4.25f}, {8.0f, 7.25f}},  // collinear diagonal (exact in float): zero width
      {{6.0f, 4.25f}},                                // one vertex
      {{4.0f, 2.25f}, {8.0f, 6.25f}},                 // two vertices
  };
  SplatBuffer point(16, 0, 16);
  point.add_point({6.0f, 4.25f}, kValue);
  const Image expected = resolved(point, 16);
  for (std::size_t k = 0; k < degenerate.size(); ++k) {
    INFO("degenerate polygon " << k);
    SplatBuffer buffer(16, 0, 16);
    buffer.add_polygon(degenerate[k], kValue);
    CHECK(buffer.skipped() == 0);
    const Image image = resolved(buffer, 16);
    CHECK(max_abs_difference(image, expected) < kRoundoff);
  }
  // Bilinear weights of (6.0, 4.25): columns 5 and 6 half each, rows 3 and 4 a quarter and 3/4.
  CHECK_THAT(expected.at(5, 3, 0), WithinAbs(0.125, kRoundoff));
  CHECK_THAT(expected.at(6, 4, 0), WithinAbs(0.375, kRoundoff));
}

TEST_CASE("splat buffer: either winding deposits the same", "[render][splat]") {
  constexpr double kRoundoff = 1e-7;
  std::vector<Point2f> poly = disc(20.3, 17.9, 13.0, 7, 0.2);
  SplatBuffer ccw(40, 0, 40);
  ccw.add_polygon(poly, kValue);
  std::reverse(poly.begin(), poly.end());
  SplatBuffer cw(40, 0, 40);
  cw.add_polygon(poly, kValue);
  const Image a = resolved(ccw, 40);
  const Image b = resolved(cw, 40);
  CHECK(max_abs_difference(a, b) < kRoundoff);
  CHECK_THAT(channel_sum(a, 0), WithinRel(1.0, kEnergyRoundoff));
}

TEST_CASE("splat buffer: a disc's half-maximum contour has the disc's diameter (20, 80, 200 px)", "[render][splat]") {
  constexpr double kContour = 1.0;  // px, from the area of pixels at or above half the interior level
  constexpr int kSize = 240;
  for (const double diameter_px : {20.0, 80.0, 200.0}) {
    SplatBuffer buffer(kSize, 0, kSize);
    buffer.add_polygon(disc(120.3, 119.8, diameter_px), kValue);
    const Image image = resolved(buffer, kSize);
    const double interior = image.at(120, 120, 0);
    int count = 0;
    for (int j = 0; j < kSize; ++j) {
      for (int i = 0; i < kSize; ++i) count += image.at(i, j, 0) >= 0.5 * interior ? 1 : 0;
    }
    const double measured = 2.0 * std::sqrt(count / std::numbers::pi);
    INFO("diameter " << diameter_px << " px: " << count << " px at or above half of " << interior);
    CHECK_THAT(measured, WithinAbs(diameter_px, kContour));
  }
}

TEST_CASE("splat buffer: clear() zeroes the deposits and the same calls then give the same image", "[render][splat]") {
  SplatBuffer buffer(30, 0, 30);
  buffer.add_polygon(disc(15.2, 14.7, 11.0), kValue);
  const Image first = resolved(buffer, 30);
  buffer.clear();
  CHECK(channel_sum(resolved(buffer, 30), 0) == 0.0);
  buffer.add_polygon(disc(15.2, 14.7, 11.0), kValue);
  const Image second = resolved(buffer, 30);
  CHECK(first.data == second.data);
}

TEST_CASE("splat options: subrows outside [1, 16] and bad buffer sizes are rejected, naming the field", "[render][splat]") {
  SplatOptions options;
  CHECK_NOTHROW(options.validate());
  CHECK(options.to_string() == "SplatOptions(subrows 4)");
  options.subrows = 0;
  CHECK_THROWS_WITH(options.validate(), Contains("SplatOptions::subrows = 0: must lie in [1, 16]"));
  options.subrows = 17;
  CHECK_THROWS_AS(SplatBuffer(10, 0, 10, options), OptionsError);
  CHECK_THROWS_AS(SplatBuffer(0, 0, 10), OptionsError);
  CHECK_THROWS_AS(SplatBuffer(10, 5, 4), OptionsError);
  CHECK_THROWS_AS(SplatBuffer(10, -1, 4), OptionsError);
  const SplatBuffer buffer(10, 2, 7);
  CHECK(buffer.to_string() == "SplatBuffer(10 px wide, rows [2, 7), 4 sub-rows, 0 skipped)");
  Image rgb(10, 7, 3);
  CHECK_THROWS_AS(buffer.resolve_into(rgb), OptionsError);
  Image short_image(10, 6, 4);
  CHECK_THROWS_AS(buffer.resolve_into(short_image), OptionsError);
}

TEST_CASE("polygon area: the shoelace formula for either winding", "[render][splat]") {
  const std::vector<Point2f> square = {{1, 1}, {4, 1}, {4, 3}, {1, 3}};
  CHECK(polygon_area(square) == 6.0);
  const std::vector<Point2f> reversed(square.rbegin(), square.rend());
  CHECK(polygon_area(reversed) == 6.0);
  CHECK(polygon_area(std::vector<Point2f>{{1, 1}, {2, 2}}) == 0.0);
}

TEST_CASE("splat buffer: a non-convex star still deposits exactly its value", "[render][splat]") {
  // Not a supported input, but it must neither crash nor create or lose energy: the rasterised area
  // and the deposit come from the same chains.
  std::vector<Point2f> star;
  for (int k = 0; k < 10; ++k) {
    const double t = 2.0 * std::numbers::pi * k / 10;
    const double r = k % 2 == 0 ? 12.0 : 4.0;
    star.push_back({static_cast<float>(30.3 + r * std::cos(t)), static_cast<float>(29.6 + r * std::sin(t))});
  }
  SplatBuffer buffer(60, 0, 60);
  buffer.add_polygon(star, kValue);
  CHECK_THAT(channel_sum(resolved(buffer, 60), 0), WithinRel(1.0, kEnergyRoundoff));
}

TEST_CASE("splat buffer at 1/2 and 1/4 resolution: a large disc keeps its value and its shape, bands stay independent", "[render][splat]") {
  // Away from its edge a 120-px disc's interior is flat at any resolution; its edge softens by about
  // the grid cell (the tent is one cell wide, the upsampling bilinear), so the half-maximum contour
  // still has the disc's diameter within a cell. Energy is kept exactly up to float rounding.
  constexpr int kWidth = 203, kHeight = 170;  // not multiples of the cell size
  constexpr double kDiameterPx = 120.0;
  SplatBuffer reference(kWidth, 0, kHeight);
  reference.add_polygon(disc(101.3, 84.8, kDiameterPx), kValue);
  const Image sharp = resolved(reference, kHeight);
  for (const int k : {2, 4}) {
    SplatOptions options;
    options.downsample = k;
    options.subrows = 1;
    SplatBuffer coarse(kWidth, 0, kHeight, options);
    coarse.add_polygon(disc(101.3, 84.8, kDiameterPx), kValue);
    const Image image = resolved(coarse, kHeight);
    INFO("1/" << k << " resolution");
    for (int c = 0; c < 4; ++c) CHECK_THAT(channel_sum(image, c), WithinRel(double{kValue[static_cast<std::size_t>(c)]}, kEnergyRoundoff));
    // The interior within 40 px of the centre: the same level as the full-resolution deposit, up to
    // the rasterised area each normalises by (60 cell rows of 1 sub-row vs 480 sub-rows): 0.1 %.
    for (int j = 50; j <= 120; j += 7) {
      for (int i = 70; i <= 130; i += 6) CHECK_THAT(double{image.at(i, j, 0)}, WithinRel(double{sharp.at(i, j, 0)}, 2e-3));
    }
    int count = 0;
    const double interior = image.at(101, 85, 0);
    for (std::size_t p = 0; p < image.pixel_count(); ++p) count += image.data[p * 4] >= 0.5 * interior ? 1 : 0;
    CHECK_THAT(2.0 * std::sqrt(count / std::numbers::pi), WithinAbs(kDiameterPx, 1.0 * k));
    // Bands of rows 0-36, 37-99, 100-169 filled separately give the same image: each band's grid
    // holds every cell row its output rows interpolate from.
    Image banded(kWidth, kHeight, 4);
    for (const auto& [begin, end] : std::vector<std::pair<int, int>>{{0, 37}, {37, 100}, {100, kHeight}}) {
      SplatBuffer band(kWidth, begin, end, options);
      band.add_polygon(disc(101.3, 84.8, kDiameterPx), kValue);
      band.add_point({3.2f, 168.9f}, kValue);
      band.resolve_into(banded);
      // Resolved into its own rows: the same values as its rows of the whole.
      std::vector<float> rows(static_cast<std::size_t>(end - begin) * kWidth * 4, 0.0f);
      band.resolve_rows_into(rows.data());
      CHECK(std::equal(rows.begin(), rows.end(), banded.data.begin() + static_cast<std::ptrdiff_t>(begin) * kWidth * 4));
    }
    coarse.add_point({3.2f, 168.9f}, kValue);
    CHECK(max_abs_difference(resolved(coarse, kHeight), banded) < 1e-6);
  }
  SplatOptions bad;
  bad.downsample = 9;
  CHECK_THROWS_WITH(bad.validate(), Contains("SplatOptions::downsample = 9: must lie in [1, 8]"));
}

TEST_CASE("difference stamp: added at whole-pixel anchors it deposits what add_polygon deposits for the polygon moved there, edges and bands included", "[render][splat][stamp]") {
  // The same sub-rows at the same global positions and the same span ends (moved by whole pixels;
  // vertices on a 1/1024 px grid, so that moving them is exact in float): only the order of the
  // double additions and float output rounding differ.
  constexpr double kStampRoundoff = 1e-6;
  auto snapped = [](std::vector<Point2f> polygon) {
    for (Point2f& p : polygon) p = {std::round(p.x * 1024.0f) / 1024.0f, std::round(p.y * 1024.0f) / 1024.0f};
    return polygon;
  };
  constexpr int kWidth = 90;
  constexpr int kHeight = 70;
  for (const int subrows : {1, 4, 8, 16}) {
    INFO("sub-rows " << subrows);
    SplatOptions options;
    options.subrows = subrows;
    const std::vector<Point2f> polygons[] = {snapped(disc(0.5, 0.5, 13.0, 48)), snapped(disc(0.5, 0.5, 0.9, 12, 0.3)),
                                             {{0.5f, -6.0f}, {9.0f, 4.5f}, {-3.25f, 2.0f}}};
    for (const std::vector<Point2f>& polygon : polygons) {
      const DifferenceStamp stamp = SplatBuffer::record(polygon, subrows);
      REQUIRE(stamp.entries() > 0);
      // Anchors inside, over the left, right, top and bottom edges, and wholly outside.
      const int anchors[][2] = {{40, 30}, {1, 20}, {88, 50}, {30, 0}, {60, 69}, {-40, 30}, {45, 120}};
      SplatBuffer by_polygon(kWidth, 0, kHeight, options);
      std::vector<SplatBuffer> by_stamp_bands;
      by_stamp_bands.emplace_back(kWidth, 0, 23, options);
      by_stamp_bands.emplace_back(kWidth, 23, kHeight, options);
      for (const auto& a : anchors) {
        std::vector<Point2f> moved = polygon;
        for (Point2f& p : moved) p = {p.x + static_cast<float>(a[0]), p.y + static_cast<float>(a[1])};
        by_polygon.add_polygon(moved, kValue);
        for (SplatBuffer& band : by_stamp_bands) band.add_stamp(stamp, a[0], a[1], kValue);
      }
      const Image expected = resolved(by_polygon, kHeight);
      Image got(kWidth, kHeight, 4);
      for (const SplatBuffer& band : by_stamp_bands) band.resolve_into(got);
      CHECK(max_abs_difference(expected, got) < kStampRoundoff);
      CHECK(channel_sum(got, 0) > 1.0);  // some of it landed
    }
  }
}

TEST_CASE("difference stamp: a stamp sums to its value, records nothing for a non-finite polygon, and only full-resolution buffers take it", "[render][splat][stamp]") {
  const DifferenceStamp stamp = SplatBuffer::record(disc(0.5, 0.5, 21.0), 8);
  SplatBuffer buffer(64, 0, 64);
  buffer.add_stamp(stamp, 30, 30, kValue);
  CHECK_THAT(channel_sum(resolved(buffer, 64), 3), WithinAbs(kValue[3], kEnergyRoundoff));
  CHECK_THAT(stamp.to_string(), Contains("rows") && Contains("entries"));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  CHECK(SplatBuffer::record(std::vector<Point2f>{{0.0f, 0.0f}, {nan, 1.0f}, {1.0f, 1.0f}}, 4).entries() == 0);
  SplatOptions half;
  half.downsample = 2;
  SplatBuffer coarse(64, 0, 64, half);
  CHECK_THROWS_AS(coarse.add_stamp(stamp, 30, 30, kValue), OptionsError);
  buffer.add_stamp(stamp, 30, 30, {nan, 0.0f, 0.0f, 0.0f});
  CHECK(buffer.skipped() == 1);
}

namespace {

// A mesh for add_mesh, with its edge list found by brute force.
struct TestMesh {
  std::vector<Point2f> vertices;
  std::vector<std::vector<std::uint32_t>> corners;
  std::vector<float> light, coverage;

  void edges(std::vector<std::array<std::uint32_t, 2>>& edges, std::vector<MeshCell>& cells) const {
    edges.clear();
    cells.clear();
    for (std::size_t t = 0; t < corners.size(); ++t) {
      MeshCell m;
      m.corners = static_cast<std::uint32_t>(corners[t].size());
      m.light = light[t];
      m.coverage = coverage[t];
      for (std::size_t k = 0; k < corners[t].size(); ++k) {
        const std::uint32_t p = corners[t][k], q = corners[t][(k + 1) % corners[t].size()];
        m.corner[k] = p;
        auto it = std::find_if(edges.begin(), edges.end(), [&](const auto& e) { return (e[0] == p && e[1] == q) || (e[0] == q && e[1] == p); });
        if (it == edges.end()) it = edges.insert(edges.end(), {p, q});
        m.edge[k] = static_cast<std::uint32_t>(it - edges.begin());
        m.direction[k] = (*it)[0] == p ? std::int8_t{1} : std::int8_t{-1};
      }
      cells.push_back(m);
    }
  }
  std::vector<Point2f> polygon(std::size_t t, Point2f offset = {}) const {
    std::vector<Point2f> v;
    for (const std::uint32_t c : corners[t]) v.push_back({vertices[c].x + offset.x, vertices[c].y + offset.y});
    return v;
  }
};

// A hexagonal fan about (cx, cy), radius r px, each triangle with its own light and coverage; then a
// triangle folded back over two others (as a mapped mesh folds at a caustic), a sliver of no area and
// a triangle between two sub-rows (both points for add_polygon).
TestMesh fan_mesh(double cx, double cy, double r) {
  TestMesh m;
  m.vertices.push_back({static_cast<float>(cx), static_cast<float>(cy)});
  for (int k = 0; k < 6; ++k) {
    const double t = 0.37 + std::numbers::pi * k / 3.0;
    m.vertices.push_back({static_cast<float>(cx + r * std::cos(t)), static_cast<float>(cy + r * std::sin(t))});
  }
  for (std::uint32_t k = 0; k < 6; ++k) {
    m.corners.push_back({0, 1 + k, 1 + (k + 1) % 6});
    m.light.push_back(0.5f + 0.3f * static_cast<float>(k));
    m.coverage.push_back(1.0f + 0.1f * static_cast<float>(k));
  }
  m.vertices.push_back({static_cast<float>(cx + 0.2 * r), static_cast<float>(cy + 0.3 * r)});  // 7
  m.corners.push_back({1, 2, 7});
  m.light.push_back(0.9f);
  m.coverage.push_back(0.7f);
  m.vertices.push_back({static_cast<float>(cx - 0.5 * r), static_cast<float>(cy - 0.5 * r)});  // 8
  m.corners.push_back({0, 8, 0});
  m.light.push_back(0.4f);
  m.coverage.push_back(0.3f);
  m.vertices.push_back({static_cast<float>(cx + 0.05), 10.3f});  // 9, 10, 11: between sub-rows 10.125 and 10.375
  m.vertices.push_back({static_cast<float>(cx + 0.3), 10.33f});
  m.vertices.push_back({static_cast<float>(cx + 0.1), 10.36f});
  m.corners.push_back({9, 10, 11});
  m.light.push_back(0.2f);
  m.coverage.push_back(0.1f);
  // A quadrilateral (a triangle a clear aperture cut) sharing the fan's edge 3-4 from outside.
  const Point2f v3 = m.vertices[3], v4 = m.vertices[4];
  const auto outward = [&](Point2f v) { return Point2f{v.x - static_cast<float>(0.3 * r), v.y - static_cast<float>(0.35 * r)}; };
  m.vertices.push_back(outward(v3));  // 12
  m.vertices.push_back(outward(v4));  // 13
  m.corners.push_back({3, 12, 13, 4});
  m.light.push_back(0.6f);
  m.coverage.push_back(0.5f);
  return m;
}

}  // namespace

TEST_CASE("splat buffer: a mesh deposits what its cells one by one deposit, folds, slivers, quadrilaterals, moves, bands and coarse grids included",
          "[render][splat][mesh]") {
  constexpr int kWidth = 48, kHeight = 40;
  const TestMesh mesh = fan_mesh(22.3, 19.6, 11.7);
  std::vector<std::array<std::uint32_t, 2>> edges;
  std::vector<MeshCell> cells;
  mesh.edges(edges, cells);
  const Rgba value{1.0f, 0.5f, 0.25f, 2.0f};
  for (const int downsample : {1, 2}) {
    for (const int subrows : {4, 16}) {
      for (const Point2f offset : {Point2f{}, Point2f{1.25f, -0.375f}}) {
        INFO("downsample " << downsample << ", " << subrows << " sub-rows, moved by " << offset);
        SplatOptions options;
        options.subrows = subrows;
        options.downsample = downsample;
        SplatBuffer one_by_one(kWidth, 0, kHeight, options);
        for (std::size_t t = 0; t < mesh.corners.size(); ++t) {
          one_by_one.add_polygon(mesh.polygon(t, offset), {value[0] * mesh.light[t], value[1] * mesh.light[t], value[2] * mesh.light[t],
                                                            value[3] * mesh.coverage[t]});
        }
        Image together(kWidth, kHeight, 4);
        for (const auto& [begin, end] : {std::pair{0, 20}, std::pair{20, kHeight}}) {
          SplatBuffer band(kWidth, begin, end, options);
          band.add_mesh(mesh.vertices, edges, cells, value, offset);
          CHECK(band.skipped() == 0);
          band.resolve_into(together);
        }
        // The same spans at the same densities, summed in another order (pixels up to about 0.1;
        // observed differences below 1e-7).
        CHECK(max_abs_difference(resolved(one_by_one, kHeight), together) < 1e-6);
      }
    }
  }
}

TEST_CASE("splat buffer: a mesh conserves each triangle's value and rejects bad indices and non-finite vertices", "[render][splat][mesh]") {
  const TestMesh mesh = fan_mesh(20.4, 18.1, 9.3);
  std::vector<std::array<std::uint32_t, 2>> edges;
  std::vector<MeshCell> cells;
  mesh.edges(edges, cells);
  SplatBuffer buffer(48, 0, 40);
  buffer.add_mesh(mesh.vertices, edges, cells, kValue);
  double light = 0.0, coverage = 0.0;
  for (std::size_t t = 0; t < mesh.corners.size(); ++t) {
    light += mesh.light[t];
    coverage += mesh.coverage[t];
  }
  const Image image = resolved(buffer, 40);
  CHECK_THAT(channel_sum(image, 0), WithinRel(light, kEnergyRoundoff));
  CHECK_THAT(channel_sum(image, 3), WithinRel(2.0 * coverage, kEnergyRoundoff));

  std::vector<MeshCell> bad = cells;
  bad[0].edge[1] = 99;
  CHECK_THROWS_WITH(buffer.add_mesh(mesh.vertices, edges, bad, kValue), Contains("names edge 99 of"));
  std::vector<std::array<std::uint32_t, 2>> bad_edges = edges;
  bad_edges[0][1] = 42;
  CHECK_THROWS_WITH(buffer.add_mesh(mesh.vertices, bad_edges, cells, kValue), Contains("names vertex 42 of 14"));
  std::vector<Point2f> nan_vertex = mesh.vertices;
  nan_vertex[1].x = std::numeric_limits<float>::quiet_NaN();
  SplatBuffer clean(48, 0, 40);
  clean.add_mesh(nan_vertex, edges, cells, kValue);
  CHECK(clean.skipped() == 3);  // the fan's two triangles on vertex 1 and the fold
  std::vector<MeshCell> five = cells;
  five[0].corners = 5;
  CHECK_THROWS_WITH(buffer.add_mesh(mesh.vertices, edges, five, kValue), Contains("a cell of 5 corners"));
}

namespace {

// A polygon's light filtered by the splat buffer's own tent, sampled every 1/kPhases px: the light
// that add_polygon gives an output pixel centred at each sample point, from add_polygon itself (the
// polygon moved by each sub-pixel phase, every pixel read). Sample (a, b) lies at
// (origin + a / kPhases, origin + b / kPhases) px, origin = 0.5.
struct TabulatedPolygon {
  static constexpr int kPhases = 8;
  int nx = 0, ny = 0;
  std::vector<float> samples;  // light per unit of value, row-major
};

TabulatedPolygon tabulate(const std::vector<Point2f>& polygon, int width, int height) {
  TabulatedPolygon t;
  constexpr int p = TabulatedPolygon::kPhases;
  t.nx = width * p;
  t.ny = height * p;
  t.samples.assign(static_cast<std::size_t>(t.nx) * static_cast<std::size_t>(t.ny), 0.0f);
  SplatOptions fine;
  fine.subrows = 16;
  for (int dy = 0; dy < p; ++dy) {
    for (int dx = 0; dx < p; ++dx) {
      std::vector<Point2f> moved = polygon;
      for (Point2f& v : moved) v = {v.x - static_cast<float>(dx) / p, v.y - static_cast<float>(dy) / p};
      SplatBuffer buffer(width, 0, height, fine);
      buffer.add_polygon(moved, {1.0f, 1.0f, 1.0f, 1.0f});
      const Image image = resolved(buffer, height);
      for (int j = 0; j < height; ++j) {
        for (int i = 0; i < width; ++i) {
          t.samples[static_cast<std::size_t>(j * p + dy) * static_cast<std::size_t>(t.nx) + static_cast<std::size_t>(i * p + dx)] =
              image.at(i, j, 0);
        }
      }
    }
  }
  return t;
}

}  // namespace

TEST_CASE("splat buffer: a polygon's light tabulated finely and drawn as an image, moved or turned a quarter turn, deposits what add_polygon of the polygon moved or turned deposits",
          "[render][splat][image]") {
  // add_image samples a light distribution already filtered by the buffer's tent bilinearly at each
  // output pixel's centre (FootprintScatter's light images). Tabulated every 1/8 px, the polygon's own
  // filtered light must come back as add_polygon draws it. The tent T(x) T(y) is the same turned by a
  // quarter turn, so the turned image must match add_polygon of the turned polygon too. Tolerances:
  // bilinear interpolation of samples 1/8 px apart misses a tent-filtered edge's curvature by
  // (1/8)^2 / 8 of its second derivative (about 1 / px^2 of the disc's density at its rim): measured
  // 3.1e-4 moved and 1.4e-4 turned (of a value of 2), 2e-3 a unit allowed; the image turned the wrong
  // way fails. The light drawn: within 1e-4 of the polygon's (measured 1e-7).
  constexpr double kInterpolation = 2e-3;
  constexpr double kLight = 1e-4;
  const int w = 40, h = 32;
  const std::vector<Point2f> polygon = disc(14.3, 12.6, 9.0, 48, 0.1);  // plus a notch: not symmetric
  std::vector<Point2f> notched = polygon;
  notched[5] = {13.0f, 11.0f};
  const TabulatedPolygon t = tabulate(notched, w, h);
  const std::array<float, 4> value{1.0f, 0.5f, 0.25f, 2.0f};
  const float origin = 0.5f, cell = 1.0f / TabulatedPolygon::kPhases;
  SECTION("moved by a fraction of a pixel") {
    const Point2f move{3.3f, 4.6f};
    SplatBuffer drawn(w, 0, h);
    drawn.add_image(t.samples, t.nx, t.ny, origin, origin, cell, {1.0f, 0.0f, 0.0f, 1.0f}, move, value);
    std::vector<Point2f> moved = notched;
    for (Point2f& v : moved) v = {v.x + move.x, v.y + move.y};
    SplatOptions fine;
    fine.subrows = 16;
    SplatBuffer reference(w, 0, h, fine);
    reference.add_polygon(moved, value);
    const Image a = resolved(drawn, h), b = resolved(reference, h);
    CHECK(max_abs_difference(a, b) < kInterpolation * 2.0);  // value's largest channel is 2
    CHECK_THAT(channel_sum(a, 0), WithinRel(channel_sum(b, 0), kLight));
  }
  SECTION("turned a quarter turn about a point") {
    // Output offset d = R(90 deg) u: the image is sampled at u = R(-90 deg) d = (d.y, -d.x).
    const Point2f about{20.0f, 16.0f};
    SplatBuffer drawn(w, 0, h);
    drawn.add_image(t.samples, t.nx, t.ny, origin - about.x, origin - about.y, cell, {0.0f, 1.0f, -1.0f, 0.0f}, about, value);
    std::vector<Point2f> turned = notched;
    for (Point2f& v : turned) v = {about.x - (v.y - about.y), about.y + (v.x - about.x)};
    SplatOptions fine;
    fine.subrows = 16;
    SplatBuffer reference(w, 0, h, fine);
    reference.add_polygon(turned, value);
    const Image a = resolved(drawn, h), b = resolved(reference, h);
    CHECK(max_abs_difference(a, b) < kInterpolation * 2.0);
    CHECK_THAT(channel_sum(a, 0), WithinRel(channel_sum(b, 0), kLight));
  }
}

TEST_CASE("splat buffer: an image drawn turned by any angle deposits exactly its light (a point-like one too), bands drawn apart or bounds on its empty corners change nothing, points equal add_point's",
          "[render][splat][image]") {
  // A turned tent is not the tent: sampled on the pixel grid, the tent-filtered light of a disc 9 px
  // across summed to its light within 1.3e-4 at these angles, a point's (below) to 1.17-1.34 of it at
  // 45 deg. add_image normalises what it deposits over every pixel the image reaches: within float
  // rounding of the light, 1e-6.
  constexpr double kTurnedLight = 1e-6;
  constexpr double kBandRoundoff = 1e-6;
  const int w = 40, h = 32;
  const TabulatedPolygon t = tabulate(disc(14.3, 12.6, 9.0, 48, 0.1), w, h);
  const float cell = 1.0f / TabulatedPolygon::kPhases;
  const std::array<float, 4> value{1.0f, 1.0f, 1.0f, 1.0f};
  for (const double angle : {0.3, 0.9, 2.2, 4.0}) {
    const auto c = static_cast<float>(std::cos(angle)), s = static_cast<float>(std::sin(angle));
    const std::array<float, 4> to_image{c, s, -s, c};
    const Point2f anchor{19.7f, 15.2f};
    SplatBuffer full(w, 0, h);
    full.add_image(t.samples, t.nx, t.ny, 0.5f - 14.3f, 0.5f - 12.6f, cell, to_image, anchor, value);
    const Image one = resolved(full, h);
    INFO("angle " << angle);
    CHECK_THAT(channel_sum(one, 0), WithinRel(1.0, kTurnedLight));
    Image banded(w, h, 4);
    for (const auto& [begin, end] : {std::pair{0, 13}, std::pair{13, 14}, std::pair{14, h}}) {
      SplatBuffer band(w, begin, end);
      band.add_image(t.samples, t.nx, t.ny, 0.5f - 14.3f, 0.5f - 12.6f, cell, to_image, anchor, value);
      band.resolve_into(banded);
    }
    CHECK(max_abs_difference(one, banded) < kBandRoundoff);
    // Bounded along the diagonals by the samples with light (widened by 2 samples, as
    // FootprintScatter does): the disc's empty corners are skipped, the picture is the same.
    float sum_lo = 1e30f, sum_hi = -1e30f, difference_lo = 1e30f, difference_hi = -1e30f;
    for (int b = 0; b < t.ny; ++b) {
      for (int a = 0; a < t.nx; ++a) {
        if (!(t.samples[static_cast<std::size_t>(b * t.nx + a)] > 0.0f)) continue;
        sum_lo = std::min(sum_lo, static_cast<float>(a + b));
        sum_hi = std::max(sum_hi, static_cast<float>(a + b));
        difference_lo = std::min(difference_lo, static_cast<float>(a - b));
        difference_hi = std::max(difference_hi, static_cast<float>(a - b));
      }
    }
    SplatBuffer bounded(w, 0, h);
    bounded.add_image(t.samples, t.nx, t.ny, 0.5f - 14.3f, 0.5f - 12.6f, cell, to_image, anchor, value,
                      {sum_lo - 2.0f, sum_hi + 2.0f, difference_lo - 2.0f, difference_hi + 2.0f});
    CHECK(max_abs_difference(one, resolved(bounded, h)) < kBandRoundoff);
    SplatBuffer too_tight(w, 0, h);  // the test can fail: bounds cutting into the light change the picture
    too_tight.add_image(t.samples, t.nx, t.ny, 0.5f - 14.3f, 0.5f - 12.6f, cell, to_image, anchor, value,
                        {sum_lo + 20.0f, sum_hi, difference_lo, difference_hi});
    CHECK(max_abs_difference(one, resolved(too_tight, h)) > 1e-3);
  }

  // A point-like image (a disc 0.6 px across) turned by 45 deg, at sub-pixel places: exactly its light;
  // half beyond the frame's left edge, only the part inside (the rest is not drawn).
  const TabulatedPolygon point = tabulate(disc(10.0, 10.0, 0.6, 16, 0.0), 20, 20);
  const float r = std::sqrt(0.5f);
  for (const float shift : {0.0f, 0.25f, 0.5f}) {
    SplatBuffer one_point(w, 0, h);
    one_point.add_image(point.samples, point.nx, point.ny, 0.5f - 10.0f, 0.5f - 10.0f, cell, {r, r, -r, r}, {20.0f + shift, 16.0f + shift},
                        value);
    INFO("shift " << shift);
    CHECK_THAT(channel_sum(resolved(one_point, h), 0), WithinRel(1.0, kTurnedLight));
  }
  SplatBuffer at_edge(w, 0, h);
  at_edge.add_image(t.samples, t.nx, t.ny, 0.5f - 14.3f, 0.5f - 12.6f, cell, {1.0f, 0.0f, 0.0f, 1.0f}, {0.0f, 15.0f}, value);
  const double inside = channel_sum(resolved(at_edge, h), 0);
  CHECK(inside > 0.4);
  CHECK(inside < 0.6);
  // Points, turned by 30 deg and moved: each as add_point of its place, with its weight.
  const std::vector<std::array<float, 3>> points{{0.0f, 0.0f, 0.5f}, {1.3f, -0.4f, 0.25f}, {-2.7f, 3.1f, 0.25f}, {30.0f, 0.0f, 1.0f}};
  const float c = std::cos(0.5236f), s = std::sin(0.5236f);
  const std::array<float, 4> from_image{c, -s, s, c};
  const Point2f anchor{10.4f, 9.9f};
  SplatBuffer drawn(w, 0, h), reference(w, 0, h);
  drawn.add_points(points, from_image, anchor, kValue);
  for (const auto& [x, y, weight] : points) {
    reference.add_point({anchor.x + c * x - s * y, anchor.y + s * x + c * y},
                        {kValue[0] * weight, kValue[1] * weight, kValue[2] * weight, kValue[3] * weight});
  }
  CHECK(max_abs_difference(resolved(drawn, h), resolved(reference, h)) < kBandRoundoff);
}

TEST_CASE("splat buffer: an image filtered by the tent of 2 x 2 px cells and drawn into a buffer of such cells deposits what add_polygon deposits there",
          "[render][splat][image]") {
  const int w = 40, h = 32;
  const float cell = 1.0f / TabulatedPolygon::kPhases;
  const std::array<float, 4> value{1.0f, 0.5f, 0.25f, 2.0f};
  // A coarse buffer's cell receives the light of the tent two pixels wide around its centre:
  // T(u / 2) = T(u + 1) / 2 + T(u) + T(u - 1) / 2, so the cells' image is the pixels' image summed
  // over whole-pixel shifts with those weights. Drawn unturned, it must give what add_polygon gives
  // in the same coarse buffer (the same cells, the same bilinear upsampling) up to interpolation
  // (measured 5.4e-5).
  constexpr double kCoarseInterpolation = 2e-3;
  const TabulatedPolygon fine_table = tabulate(disc(20.3, 16.6, 17.0, 64, 0.1), w, h);
  const int p = TabulatedPolygon::kPhases;
  std::vector<float> coarse(fine_table.samples.size(), 0.0f);
  for (int b = 0; b < fine_table.ny; ++b) {
    for (int a = 0; a < fine_table.nx; ++a) {
      double sum = 0.0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int aa = a + dx * p, bb = b + dy * p;
          if (aa < 0 || bb < 0 || aa >= fine_table.nx || bb >= fine_table.ny) continue;
          sum += (dx == 0 ? 1.0 : 0.5) * (dy == 0 ? 1.0 : 0.5) * fine_table.samples[static_cast<std::size_t>(bb * fine_table.nx + aa)];
        }
      }
      coarse[static_cast<std::size_t>(b * fine_table.nx + a)] = static_cast<float>(sum);
    }
  }
  SplatOptions two;
  two.downsample = 2;
  two.subrows = 16;
  SplatBuffer drawn(w, 0, h, two), reference(w, 0, h, two);
  drawn.add_image(coarse, fine_table.nx, fine_table.ny, 0.5f, 0.5f, cell, {1.0f, 0.0f, 0.0f, 1.0f}, {0.0f, 0.0f}, value);
  reference.add_polygon(disc(20.3, 16.6, 17.0, 64, 0.1), value);
  const Image a = resolved(drawn, h), b = resolved(reference, h);
  CHECK(max_abs_difference(a, b) < kCoarseInterpolation);
  CHECK_THAT(channel_sum(a, 0), WithinRel(channel_sum(b, 0), 1e-3));
}

TEST_CASE("splat buffer: an image needs at least 2 x 2 samples, and non-finite input is skipped and counted",
          "[render][splat][image]") {
  const std::vector<float> samples(9, 1.0f);
  const std::array<float, 4> identity{1.0f, 0.0f, 0.0f, 1.0f};
  SplatBuffer buffer(20, 0, 20);
  CHECK_THROWS_WITH(buffer.add_image(samples, 1, 9, 0.0f, 0.0f, 0.5f, identity, {5.0f, 5.0f}, kValue), Contains("at least 2 x 2"));
  CHECK_THROWS_WITH(buffer.add_image(samples, 4, 4, 0.0f, 0.0f, 0.5f, identity, {5.0f, 5.0f}, kValue), Contains("9 samples for a 4 x 4"));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  buffer.add_image(samples, 3, 3, 0.0f, 0.0f, 0.5f, identity, {nan, 5.0f}, kValue);
  buffer.add_image(samples, 3, 3, 0.0f, 0.0f, 0.5f, {1.0f, 0.0f, 0.0f, 0.0f}, {5.0f, 5.0f}, kValue);  // singular
  buffer.add_points(std::vector<std::array<float, 3>>{{0.0f, 0.0f, 1.0f}}, identity, {5.0f, 5.0f}, {nan, 1.0f, 1.0f, 1.0f});
  CHECK(buffer.skipped() == 3);
  CHECK(channel_sum(resolved(buffer, 20), 3) == 0.0);
}

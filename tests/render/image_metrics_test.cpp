// PSNR and SSIM against their closed forms (Wang, Bovik, Sheikh & Simoncelli, IEEE TIP 13(4), 2004,
// eq. 13) and a direct, non-separable evaluation of the windowed statistics; the depth-edge band
// against its definition checked pixel by pixel.
#include "lensmith/render/image_metrics.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "lensmith/core/errors.h"

using Catch::Matchers::WithinAbs;
using namespace lensmith;

namespace {
// Linear values are stored as float, so a tone-mapped value read back differs from the intended one
// by ~1e-7 relative; 1e-6 absolute on SSIM and 1e-4 dB on PSNR cover it with margin.
constexpr double kFloatStorage = 1e-6;
constexpr double kFloatStorageDb = 1e-4;
// The separable and the direct evaluation sum the same terms in a different order.
constexpr double kSummationOrder = 1e-12;
constexpr double kC1 = 0.01 * 0.01;  // (K1 L)^2, Wang et al. 2004
constexpr double kC2 = 0.03 * 0.03;  // (K2 L)^2

// The linear value whose Reinhard tone map is t (0 <= t < 1).
float linear_from_tone(double t) { return static_cast<float>(t / (1.0 - t)); }

// A deterministic texture in tone-mapped units, in [0.1, 0.7]: uniform draws from a fixed-seed
// mt19937 (whose output sequence the standard fixes) scaled by hand, not by a distribution.
std::vector<double> tone_texture(int width, int height, int channels, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<double> t(static_cast<std::size_t>(width) * height * channels);
  for (double& v : t) v = 0.1 + 0.6 * (static_cast<double>(rng()) / 4294967296.0);
  return t;
}

Image image_from_tone(int width, int height, int channels, const std::vector<double>& tone) {
  Image img(width, height, channels);
  for (std::size_t i = 0; i < tone.size(); ++i) img.data[i] = linear_from_tone(tone[i]);
  return img;
}

// Wang et al.'s statistics evaluated directly with the 2-D 11 x 11 Gaussian window (sigma 1.5),
// for one channel of tone-mapped data, averaged over the valid region.
double direct_ssim(const std::vector<double>& ta, const std::vector<double>& tb, int width, int height,
                   int channels, int c) {
  double w[11][11];
  double sum_w = 0.0;
  for (int j = 0; j < 11; ++j) {
    for (int i = 0; i < 11; ++i) {
      w[j][i] = std::exp(-((i - 5) * (i - 5) + (j - 5) * (j - 5)) / (2.0 * 1.5 * 1.5));
      sum_w += w[j][i];
    }
  }
  double total = 0.0;
  int count = 0;
  for (int y = 5; y < height - 5; ++y) {
    for (int x = 5; x < width - 5; ++x) {
      double ma = 0, mb = 0, saa = 0, sbb = 0, sab = 0;
      for (int j = 0; j < 11; ++j) {
        for (int i = 0; i < 11; ++i) {
          const std::size_t k = (static_cast<std::size_t>(y + j - 5) * width + (x + i - 5)) * channels + c;
          const double wk = w[j][i] / sum_w;
          ma += wk * ta[k];
          mb += wk * tb[k];
          saa += wk * ta[k] * ta[k];
          sbb += wk * tb[k] * tb[k];
          sab += wk * ta[k] * tb[k];
        }
      }
      const double va = saa - ma * ma, vb = sbb - mb * mb, cov = sab - ma * mb;
      total += ((2 * ma * mb + kC1) * (2 * cov + kC2)) / ((ma * ma + mb * mb + kC1) * (va + vb + kC2));
      ++count;
    }
  }
  return total / count;
}
}  // namespace

TEST_CASE("Reinhard tone map: x / (1 + x), negatives to 0 and infinity to 1", "[render][metrics]") {
  Image img(5, 1, 1);
  img.data = {0.0f, 1.0f, 3.0f, -2.0f, std::numeric_limits<float>::infinity()};
  const Image t = tone_map_reinhard(img);
  CHECK(t.data[0] == 0.0f);
  CHECK(t.data[1] == 0.5f);
  CHECK(t.data[2] == 0.75f);
  CHECK(t.data[3] == 0.0f);
  CHECK(t.data[4] == 1.0f);
}

TEST_CASE("identical images: PSNR is +infinity and SSIM is exactly 1", "[render][metrics]") {
  const Image a = image_from_tone(32, 24, 3, tone_texture(32, 24, 3, 7));
  CHECK(std::isinf(psnr(a, a)));
  CHECK(psnr(a, a) > 0.0);
  CHECK(ssim(a, a) == 1.0);
}

TEST_CASE("PSNR of a uniform tone-mapped offset d equals 10 log10(1 / d^2)", "[render][metrics]") {
  // Build b so that tone_map(b) = tone_map(a) + d in every channel: the MSE is d^2 exactly.
  const auto ta = tone_texture(40, 30, 3, 11);
  for (const double d : {0.1, 0.01, 0.003}) {
    std::vector<double> tb = ta;
    for (double& v : tb) v += d;
    const Image a = image_from_tone(40, 30, 3, ta);
    const Image b = image_from_tone(40, 30, 3, tb);
    const double expected_db = 10.0 * std::log10(1.0 / (d * d));
    INFO("offset " << d << ": expected " << expected_db << " dB");
    // Float storage moves each tone-mapped value by at most ~3e-8 (half an ulp of x, times
    // dt/dx = (1 - t)^2); at d = 0.003 that is 1e-5 of d, 8.7e-5 dB at worst: kFloatStorageDb.
    CHECK_THAT(psnr(a, b), WithinAbs(expected_db, kFloatStorageDb));
  }
}

TEST_CASE("PSNR is on tone-mapped values: linear 1 vs 3 is 0.5 vs 0.75, i.e. 12.04 dB", "[render][metrics]") {
  const Image a(16, 16, 3, 1.0f);
  const Image b(16, 16, 3, 3.0f);
  CHECK_THAT(psnr(a, b), WithinAbs(10.0 * std::log10(1.0 / (0.25 * 0.25)), 1e-9));
}

TEST_CASE("SSIM drops as noise grows and is symmetric in its arguments", "[render][metrics]") {
  const int w = 48, h = 36;
  const auto ta = tone_texture(w, h, 3, 3);
  const auto noise = tone_texture(w, h, 3, 5);  // values in [0.1, 0.7], centred to [-0.3, 0.3]
  double previous = 1.0;
  for (const double amplitude : {0.01, 0.05, 0.2}) {
    std::vector<double> tb = ta;
    for (std::size_t i = 0; i < tb.size(); ++i) tb[i] += amplitude * (noise[i] - 0.4) / 0.3;
    const Image a = image_from_tone(w, h, 3, ta);
    const Image b = image_from_tone(w, h, 3, tb);
    const double s_ab = ssim(a, b);
    INFO("noise amplitude " << amplitude << ": SSIM " << s_ab << ", previous " << previous);
    CHECK(s_ab < previous);
    CHECK_THAT(ssim(b, a), WithinAbs(s_ab, kSummationOrder));
    previous = s_ab;
  }
  // Independent zero-mean noise leaves the luminance term near 1 and makes the contrast-structure
  // term about 2 var_t / (2 var_t + var_n) = 0.82 (var_t = 0.6^2 / 12, var_n = 0.2^2 / 3); the
  // windowed estimates use ~30 effective samples, so allow 0.03.
  constexpr double kLocalSampleNoise = 0.03;
  const double var_t = 0.6 * 0.6 / 12.0, var_n = 0.2 * 0.2 / 3.0;
  CHECK_THAT(previous, WithinAbs((2 * var_t + kC2) / (2 * var_t + var_n + kC2), kLocalSampleNoise));
}

TEST_CASE("SSIM of two uniform images is the luminance term (2 mu_a mu_b + C1) / (mu_a^2 + mu_b^2 + C1)",
          "[render][metrics]") {
  // Variances and covariance vanish, so the contrast-structure factor is C2 / C2 = 1.
  for (const auto& [mu_a, mu_b] : {std::pair{0.5, 0.6}, std::pair{0.2, 0.05}, std::pair{0.01, 0.03}}) {
    const Image a(20, 15, 3, linear_from_tone(mu_a));
    const Image b(20, 15, 3, linear_from_tone(mu_b));
    const double expected = (2 * mu_a * mu_b + kC1) / (mu_a * mu_a + mu_b * mu_b + kC1);
    INFO("mu_a " << mu_a << ", mu_b " << mu_b << ": expected " << expected);
    CHECK_THAT(ssim(a, b), WithinAbs(expected, kFloatStorage));
  }
}

TEST_CASE("SSIM of a textured image and the same plus a constant: only the luminance term drops",
          "[render][metrics]") {
  // b = a + d in tone-mapped units leaves variances and covariance equal (contrast-structure = 1),
  // so SSIM is below 1 by exactly the luminance term at each window: compare with the direct form.
  const int w = 30, h = 22;
  const auto ta = tone_texture(w, h, 1, 17);
  std::vector<double> tb = ta;
  for (double& v : tb) v += 0.2;
  const double s = ssim(image_from_tone(w, h, 1, ta), image_from_tone(w, h, 1, tb));
  CHECK(s < 1.0);
  CHECK_THAT(s, WithinAbs(direct_ssim(ta, tb, w, h, 1, 0), kFloatStorage));
}

TEST_CASE("SSIM: the separable Gaussian filter equals the direct 11 x 11 windowed evaluation, per channel averaged",
          "[render][metrics]") {
  const int w = 27, h = 19, channels = 3;
  const auto ta = tone_texture(w, h, channels, 23);
  const auto tb = tone_texture(w, h, channels, 29);
  // Tone-map the stored floats, as the implementation sees them.
  const Image a = image_from_tone(w, h, channels, ta);
  const Image b = image_from_tone(w, h, channels, tb);
  std::vector<double> sa(ta.size()), sb(tb.size());
  for (std::size_t i = 0; i < ta.size(); ++i) {
    sa[i] = a.data[i] / (1.0 + a.data[i]);
    sb[i] = b.data[i] / (1.0 + b.data[i]);
  }
  double expected = 0.0;
  for (int c = 0; c < channels; ++c) expected += direct_ssim(sa, sb, w, h, channels, c) / channels;
  CHECK_THAT(ssim(a, b), WithinAbs(expected, kSummationOrder));
}

TEST_CASE("depth edge band of two planes covers exactly the columns within the radius of the step", "[render][metrics]") {
  // Columns 0..9 at 1 m, 10..29 at 3 m: the edge pixels are columns 9 and 10.
  const int w = 30, h = 8, step = 10;
  DepthMap depth(w, h, 3.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < step; ++x) depth.at(x, y) = 1.0f;
  for (const double radius : {0.0, 1.0, 2.5, 4.0}) {
    const auto band = depth_edge_band(depth, radius);
    const int reach = static_cast<int>(std::floor(radius));
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const bool expected = x >= step - 1 - reach && x <= step + reach;
        INFO("radius " << radius << " px, pixel (" << x << ", " << y << ")");
        CHECK((band[static_cast<std::size_t>(y * w + x)] == 1) == expected);
      }
    }
  }
}

TEST_CASE("depth edge band is the Euclidean disc around every edge pixel", "[render][metrics]") {
  // A 3 x 2 near patch and an infinite sky corner in a 2 m field; brute force over all edge pixels.
  const int w = 25, h = 20;
  DepthMap depth(w, h, 2.0f);
  for (int y = 8; y < 10; ++y)
    for (int x = 6; x < 9; ++x) depth.at(x, y) = 0.5f;
  for (int y = 0; y < 3; ++y)
    for (int x = 20; x < w; ++x) depth.at(x, y) = std::numeric_limits<float>::infinity();
  auto is_edge = [&](int x, int y) {
    auto differs = [&](int x2, int y2) {
      if (x2 < 0 || y2 < 0 || x2 >= w || y2 >= h) return false;
      return depth.at(x, y) != depth.at(x2, y2);  // every step here is far above 5 %
    };
    return differs(x - 1, y) || differs(x + 1, y) || differs(x, y - 1) || differs(x, y + 1);
  };
  const double radius = 3.2;
  const auto band = depth_edge_band(depth, radius);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      bool expected = false;
      for (int ey = 0; ey < h; ++ey)
        for (int ex = 0; ex < w; ++ex)
          if (is_edge(ex, ey) && (ex - x) * (ex - x) + (ey - y) * (ey - y) <= radius * radius) expected = true;
      INFO("pixel (" << x << ", " << y << ")");
      CHECK((band[static_cast<std::size_t>(y * w + x)] == 1) == expected);
    }
  }
}

TEST_CASE("depth edge band: a step below the relative jump is no edge, finite next to infinity is", "[render][metrics]") {
  DepthMap depth(12, 12, 3.0f);
  for (int y = 0; y < 12; ++y)
    for (int x = 6; x < 12; ++x) depth.at(x, y) = 3.1f;  // 3.3 % of 3 m
  const auto no_edge = depth_edge_band(depth, 2.0);
  CHECK(std::count(no_edge.begin(), no_edge.end(), std::uint8_t{1}) == 0);
  const auto with_2_percent = depth_edge_band(depth, 0.0, 0.02);
  CHECK(std::count(with_2_percent.begin(), with_2_percent.end(), std::uint8_t{1}) == 2 * 12);
  for (int y = 0; y < 12; ++y)
    for (int x = 6; x < 12; ++x) depth.at(x, y) = std::numeric_limits<float>::infinity();
  const auto sky = depth_edge_band(depth, 0.0);
  CHECK(std::count(sky.begin(), sky.end(), std::uint8_t{1}) == 2 * 12);
  CHECK_THROWS_AS(depth_edge_band(depth, -1.0), OptionsError);
  depth.at(0, 0) = 0.0f;
  CHECK_THROWS_WITH(depth_edge_band(depth, 1.0), Catch::Contains("pixel (0, 0)"));
}

TEST_CASE("masks restrict PSNR and SSIM to the selected pixels", "[render][metrics]") {
  // a and b differ (uniform tone offset 0.1) only in columns >= 20 of a 40 x 30 image.
  const int w = 40, h = 30, split = 20;
  Image a(w, h, 3, linear_from_tone(0.4));
  Image b = a;
  for (int y = 0; y < h; ++y)
    for (int x = split; x < w; ++x)
      for (int c = 0; c < 3; ++c) b.at(x, y, c) = linear_from_tone(0.5);
  std::vector<std::uint8_t> left(static_cast<std::size_t>(w * h), 0), right = left;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      // Keep the left mask one SSIM window radius (5 px) clear of the change.
      if (x < split - 5) left[static_cast<std::size_t>(y * w + x)] = 1;
      if (x >= split + 5) right[static_cast<std::size_t>(y * w + x)] = 1;
    }
  }
  CHECK(std::isinf(psnr(a, b, &left)));
  CHECK(ssim(a, b, &left) == 1.0);
  CHECK_THAT(psnr(a, b, &right), WithinAbs(20.0, kFloatStorageDb));  // MSE = 0.1^2
  const double luminance = (2 * 0.4 * 0.5 + kC1) / (0.4 * 0.4 + 0.5 * 0.5 + kC1);
  CHECK_THAT(ssim(a, b, &right), WithinAbs(luminance, kFloatStorage));
  CHECK_THAT(psnr(a, b), WithinAbs(10.0 * std::log10(1.0 / (0.5 * 0.01)), kFloatStorageDb));  // half the pixels

  const std::vector<std::uint8_t> none(static_cast<std::size_t>(w * h), 0);
  CHECK_THROWS_AS(psnr(a, b, &none), OptionsError);
  CHECK_THROWS_AS(ssim(a, b, &none), OptionsError);
  const std::vector<std::uint8_t> short_mask(10, 1);
  CHECK_THROWS_WITH(psnr(a, b, &short_mask), Catch::Contains("10 values for 1200 pixels"));
}

TEST_CASE("metrics refuse images of different size or channel count", "[render][metrics]") {
  const Image a(16, 16, 3);
  CHECK_THROWS_AS(psnr(a, Image(16, 15, 3)), OptionsError);
  CHECK_THROWS_AS(ssim(a, Image(16, 16, 1)), OptionsError);
  CHECK_THROWS_AS(error_map(a, Image(15, 16, 3)), OptionsError);
  CHECK_THROWS_WITH(ssim(Image(10, 30, 1), Image(10, 30, 1)), Catch::Contains("at least 11 x 11"));
}

TEST_CASE("error map: absolute tone-mapped difference, grey inputs repeated into 3 channels", "[render][metrics]") {
  Image a(2, 1, 1), b(2, 1, 1);
  a.data = {1.0f, 3.0f};  // 0.5, 0.75
  b.data = {3.0f, 0.0f};  // 0.75, 0
  const Image e = error_map(a, b);
  REQUIRE(e.channels == 3);
  for (int c = 0; c < 3; ++c) {
    CHECK(e.at(0, 0, c) == 0.25f);
    CHECK(e.at(1, 0, c) == 0.75f);
  }
}

TEST_CASE("compare_images: errors along a depth edge score worse in the edge band than over the frame",
          "[render][metrics]") {
  const int w = 64, h = 48, step = 32;
  DepthMap depth(w, h, 3.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < step; ++x) depth.at(x, y) = 1.2f;
  const Image reference = image_from_tone(w, h, 3, tone_texture(w, h, 3, 31));
  Image result = reference;
  for (int y = 0; y < h; ++y)
    for (int x = step - 2; x < step + 2; ++x)
      for (int c = 0; c < 3; ++c) result.at(x, y, c) *= 1.5f;
  const ImageComparison cmp = compare_images(result, reference, depth, 3.0);
  INFO(cmp);
  CHECK(cmp.edge_pixels == static_cast<std::size_t>(h * 8));  // columns 28..35
  CHECK(cmp.edge_psnr_db < cmp.psnr_db);
  CHECK(cmp.edge_ssim < cmp.ssim);
  CHECK(cmp.ssim < 1.0);
  CHECK_THAT(cmp.to_string(), Catch::Contains("edge band 384 px"));

  const ImageComparison flat = compare_images(result, reference, DepthMap(w, h, 3.0f), 3.0);
  CHECK(flat.edge_pixels == 0);
  CHECK(std::isnan(flat.edge_psnr_db));
  CHECK(std::isnan(flat.edge_ssim));
  CHECK_THROWS_AS(compare_images(result, reference, DepthMap(w, h + 1, 3.0f), 3.0), OptionsError);
}

// PSNR, SSIM (Wang, Bovik, Sheikh & Simoncelli, IEEE TIP 13(4):600-612, 2004) and the depth-edge
// band; the band's distance transform is Felzenszwalb & Huttenlocher's exact squared Euclidean
// transform ("Distance transforms of sampled functions", Theory of Computing 8(19), 2012).
#include "lensmith/render/image_metrics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"

namespace lensmith {
namespace {

double reinhard(float x) {
  if (std::isnan(x)) return x;
  if (!(x > 0.0f)) return 0.0;
  if (std::isinf(x)) return 1.0;
  const double v = x;
  return v / (1.0 + v);
}

std::string size_text(int width, int height, int channels) {
  return std::to_string(width) + " x " + std::to_string(height) + ", " + std::to_string(channels) + " channels";
}

void check_same_shape(const Image& a, const Image& b, const char* who) {
  if (a.width != b.width || a.height != b.height || a.channels != b.channels) {
    throw OptionsError(std::string(who) + ": images differ in size or channels (" +
                       size_text(a.width, a.height, a.channels) + " vs " + size_text(b.width, b.height, b.channels) +
                       ")");
  }
  if (a.pixel_count() == 0 || a.channels < 1) throw OptionsError(std::string(who) + ": images are empty");
}

void check_mask_size(const Image& a, const std::vector<std::uint8_t>* mask, const char* who) {
  if (mask != nullptr && mask->size() != a.pixel_count()) {
    throw OptionsError(std::string(who) + ": mask has " + std::to_string(mask->size()) + " values for " +
                       std::to_string(a.pixel_count()) + " pixels (" + std::to_string(a.width) + " x " +
                       std::to_string(a.height) + "); it needs one per pixel");
  }
}

bool selected(const std::vector<std::uint8_t>* mask, std::size_t pixel) {
  return mask == nullptr || (*mask)[pixel] != 0;
}

// Wang et al. 2004, section III-C: sigma 1.5 px, 11 x 11 window, K1 = 0.01, K2 = 0.03, L = 1.
constexpr int kSsimRadiusPx = 5;
constexpr int kSsimWindowPx = 2 * kSsimRadiusPx + 1;
constexpr double kSsimSigmaPx = 1.5;
constexpr double kSsimC1 = (0.01 * 1.0) * (0.01 * 1.0);
constexpr double kSsimC2 = (0.03 * 1.0) * (0.03 * 1.0);

std::array<double, kSsimWindowPx> ssim_kernel() {
  std::array<double, kSsimWindowPx> w{};
  double sum = 0.0;
  for (int k = -kSsimRadiusPx; k <= kSsimRadiusPx; ++k) {
    w[static_cast<std::size_t>(k + kSsimRadiusPx)] = std::exp(-(k * k) / (2.0 * kSsimSigmaPx * kSsimSigmaPx));
    sum += w[static_cast<std::size_t>(k + kSsimRadiusPx)];
  }
  for (double& v : w) v /= sum;
  return w;
}

struct SsimResult {
  double mean = 0.0;        // mean over channels of the per-channel map means
  std::size_t pixels = 0;   // selected pixels at least kSsimRadiusPx from the border
};

// The separable Gaussian statistics: a horizontal pass into five (W - 10) x H planes, then a
// vertical pass that forms the SSIM map on the (W - 10) x (H - 10) valid region and sums it.
SsimResult ssim_over_mask(const Image& a, const Image& b, const std::vector<std::uint8_t>* mask) {
  check_same_shape(a, b, "ssim");
  check_mask_size(a, mask, "ssim");
  if (a.width < kSsimWindowPx || a.height < kSsimWindowPx) {
    throw OptionsError("ssim: image is " + std::to_string(a.width) + " x " + std::to_string(a.height) +
                       " px; the 11 x 11 SSIM window needs at least 11 x 11");
  }
  const auto w = ssim_kernel();
  const int width = a.width;
  const int height = a.height;
  const int channels = a.channels;
  const int valid_w = width - 2 * kSsimRadiusPx;
  const int valid_h = height - 2 * kSsimRadiusPx;
  const std::size_t plane = static_cast<std::size_t>(valid_w) * static_cast<std::size_t>(height);
  std::vector<double> mu_a(plane), mu_b(plane), aa(plane), bb(plane), ab(plane);
  std::vector<double> row_sum(static_cast<std::size_t>(valid_h));
  std::vector<std::size_t> row_count(static_cast<std::size_t>(valid_h));

  double channel_sum = 0.0;
  std::size_t pixels = 0;
  for (int c = 0; c < channels; ++c) {
#pragma omp parallel for schedule(static)
    for (int y = 0; y < height; ++y) {
      std::vector<double> ta(static_cast<std::size_t>(width)), tb(static_cast<std::size_t>(width));
      for (int x = 0; x < width; ++x) {
        ta[static_cast<std::size_t>(x)] = reinhard(a.at(x, y, c));
        tb[static_cast<std::size_t>(x)] = reinhard(b.at(x, y, c));
      }
      for (int xo = 0; xo < valid_w; ++xo) {
        double sa = 0.0, sb = 0.0, saa = 0.0, sbb = 0.0, sab = 0.0;
        for (int k = 0; k < kSsimWindowPx; ++k) {
          const double wk = w[static_cast<std::size_t>(k)];
          const double va = ta[static_cast<std::size_t>(xo + k)];
          const double vb = tb[static_cast<std::size_t>(xo + k)];
          sa += wk * va;
          sb += wk * vb;
          saa += wk * va * va;
          sbb += wk * vb * vb;
          sab += wk * va * vb;
        }
        const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(valid_w) + static_cast<std::size_t>(xo);
        mu_a[i] = sa;
        mu_b[i] = sb;
        aa[i] = saa;
        bb[i] = sbb;
        ab[i] = sab;
      }
    }
#pragma omp parallel for schedule(static)
    for (int yo = 0; yo < valid_h; ++yo) {
      double sum = 0.0;
      std::size_t count = 0;
      const int y = yo + kSsimRadiusPx;
      for (int xo = 0; xo < valid_w; ++xo) {
        const int x = xo + kSsimRadiusPx;
        if (!selected(mask, static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x))) {
          continue;
        }
        double ma = 0.0, mb = 0.0, saa = 0.0, sbb = 0.0, sab = 0.0;
        for (int k = 0; k < kSsimWindowPx; ++k) {
          const double wk = w[static_cast<std::size_t>(k)];
          const std::size_t i =
              static_cast<std::size_t>(yo + k) * static_cast<std::size_t>(valid_w) + static_cast<std::size_t>(xo);
          ma += wk * mu_a[i];
          mb += wk * mu_b[i];
          saa += wk * aa[i];
          sbb += wk * bb[i];
          sab += wk * ab[i];
        }
        const double var_a = saa - ma * ma;
        const double var_b = sbb - mb * mb;
        const double cov = sab - ma * mb;
        // Wang et al. 2004, eq. 13.
        sum += ((2.0 * ma * mb + kSsimC1) * (2.0 * cov + kSsimC2)) /
               ((ma * ma + mb * mb + kSsimC1) * (var_a + var_b + kSsimC2));
        ++count;
      }
      row_sum[static_cast<std::size_t>(yo)] = sum;
      row_count[static_cast<std::size_t>(yo)] = count;
    }
    // Sum the rows in order so the result does not depend on the thread count.
    double sum = 0.0;
    pixels = 0;
    for (int yo = 0; yo < valid_h; ++yo) {
      sum += row_sum[static_cast<std::size_t>(yo)];
      pixels += row_count[static_cast<std::size_t>(yo)];
    }
    if (pixels == 0) return {std::numeric_limits<double>::quiet_NaN(), 0};
    channel_sum += sum / static_cast<double>(pixels);
  }
  return {channel_sum / channels, pixels};
}

// One-dimensional squared distance transform of f (Felzenszwalb & Huttenlocher 2012, Algorithm
// DT(f)): d[q] = min_p (q - p)^2 + f[p]. v and z are scratch of sizes n and n + 1.
void distance_transform_1d(const double* f, int n, std::ptrdiff_t stride, double* d, int* v, double* z) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  auto at = [&](int i) { return f[i * stride]; };
  int k = 0;
  v[0] = 0;
  z[0] = -kInf;
  z[1] = kInf;
  for (int q = 1; q < n; ++q) {
    double s = ((at(q) + double(q) * q) - (at(v[k]) + double(v[k]) * v[k])) / (2.0 * q - 2.0 * v[k]);
    while (s <= z[k]) {
      --k;
      s = ((at(q) + double(q) * q) - (at(v[k]) + double(v[k]) * v[k])) / (2.0 * q - 2.0 * v[k]);
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = kInf;
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[k + 1] < q) ++k;
    const double dq = q - v[k];
    d[q * stride] = dq * dq + at(v[k]);
  }
}

bool depth_jump(float z1, float z2, double relative_jump) {
  const bool inf1 = std::isinf(z1);
  const bool inf2 = std::isinf(z2);
  if (inf1 || inf2) return inf1 != inf2;
  return std::abs(double(z1) - double(z2)) > relative_jump * std::min(double(z1), double(z2));
}

}  // namespace

Image tone_map_reinhard(const Image& image) {
  Image out = image;
  for (float& v : out.data) v = static_cast<float>(reinhard(v));
  return out;
}

double psnr(const Image& a, const Image& b, const std::vector<std::uint8_t>* mask) {
  check_same_shape(a, b, "psnr");
  check_mask_size(a, mask, "psnr");
  double sum = 0.0;
  std::size_t pixels = 0;
  const auto channels = static_cast<std::size_t>(a.channels);
  for (std::size_t p = 0; p < a.pixel_count(); ++p) {
    if (!selected(mask, p)) continue;
    ++pixels;
    for (std::size_t c = 0; c < channels; ++c) {
      const double d = reinhard(a.data[p * channels + c]) - reinhard(b.data[p * channels + c]);
      sum += d * d;
    }
  }
  if (pixels == 0) throw OptionsError("psnr: the mask selects no pixel");
  const double mse = sum / (static_cast<double>(pixels) * static_cast<double>(channels));
  if (mse == 0.0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(1.0 / mse);
}

double ssim(const Image& a, const Image& b, const std::vector<std::uint8_t>* mask) {
  const SsimResult r = ssim_over_mask(a, b, mask);
  if (r.pixels == 0) {
    throw OptionsError("ssim: the mask selects no pixel at least 5 px from the border (" + std::to_string(a.width) +
                       " x " + std::to_string(a.height) + " image; the 11 x 11 window must fit)");
  }
  return r.mean;
}

std::vector<std::uint8_t> depth_edge_band(const DepthMap& depth, double band_radius_px, double relative_jump) {
  if (!(std::isfinite(band_radius_px) && band_radius_px >= 0.0)) {
    throw OptionsError("depth_edge_band: band_radius_px = " + format_number(band_radius_px) +
                       ": must be finite and >= 0");
  }
  if (!(std::isfinite(relative_jump) && relative_jump > 0.0)) {
    throw OptionsError("depth_edge_band: relative_jump = " + format_number(relative_jump) + ": must be finite and > 0");
  }
  const int width = depth.width;
  const int height = depth.height;
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (width < 1 || height < 1 || depth.z_m.size() != n) {
    throw OptionsError("depth_edge_band: depth map is " + std::to_string(width) + " x " + std::to_string(height) +
                       " with " + std::to_string(depth.z_m.size()) + " values");
  }
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const float z = depth.at(x, y);
      if (std::isnan(z) || !(z > 0.0f)) {
        throw OptionsError("depth_edge_band: depth at pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                           ") = " + format_number(z) + " m: must be > 0 (or +inf)");
      }
    }
  }

  // Edge pixels: both pixels of every 4-neighbour pair with a depth jump.
  // Felzenszwalb's "infinity" must stay finite so that parabola intersections stay finite.
  constexpr double kFar = 1e20;
  std::vector<double> f(n, kFar);
  bool any_edge = false;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
      if (x + 1 < width && depth_jump(depth.at(x, y), depth.at(x + 1, y), relative_jump)) {
        f[i] = f[i + 1] = 0.0;
        any_edge = true;
      }
      if (y + 1 < height && depth_jump(depth.at(x, y), depth.at(x, y + 1), relative_jump)) {
        f[i] = f[i + static_cast<std::size_t>(width)] = 0.0;
        any_edge = true;
      }
    }
  }
  std::vector<std::uint8_t> band(n, 0);
  if (!any_edge) return band;
  const double diagonal_sq = double(width) * width + double(height) * height;
  const double radius_sq = band_radius_px * band_radius_px;
  if (radius_sq >= diagonal_sq) {
    std::fill(band.begin(), band.end(), std::uint8_t{1});
    return band;
  }

  // Exact squared Euclidean distance to the nearest edge pixel: columns, then rows.
  const int longest = std::max(width, height);
  std::vector<double> d(n);
  std::vector<int> v(static_cast<std::size_t>(longest));
  std::vector<double> z(static_cast<std::size_t>(longest) + 1);
  for (int x = 0; x < width; ++x) {
    distance_transform_1d(f.data() + x, height, width, d.data() + x, v.data(), z.data());
  }
  for (int y = 0; y < height; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(width);
    distance_transform_1d(d.data() + row, width, 1, f.data() + row, v.data(), z.data());
  }
  for (std::size_t i = 0; i < n; ++i) band[i] = f[i] <= radius_sq ? 1 : 0;
  return band;
}

Image error_map(const Image& a, const Image& b) {
  check_same_shape(a, b, "error_map");
  if (a.channels == 2) {
    throw OptionsError("error_map: images have 2 channels; need 1 (grey) or at least 3 (RGB)");
  }
  Image out(a.width, a.height, 3);
  const auto channels = static_cast<std::size_t>(a.channels);
  for (std::size_t p = 0; p < a.pixel_count(); ++p) {
    for (std::size_t c = 0; c < 3; ++c) {
      const std::size_t src = p * channels + (channels == 1 ? 0 : c);
      out.data[p * 3 + c] = static_cast<float>(std::abs(reinhard(a.data[src]) - reinhard(b.data[src])));
    }
  }
  return out;
}

std::string ImageComparison::to_string() const {
  std::ostringstream os;
  os << std::fixed << "ImageComparison(PSNR " << std::setprecision(2) << psnr_db << " dB, SSIM "
     << std::setprecision(4) << ssim << "; edge band " << edge_pixels << " px: PSNR " << std::setprecision(2)
     << edge_psnr_db << " dB, SSIM " << std::setprecision(4) << edge_ssim << ")";
  return os.str();
}

ImageComparison compare_images(const Image& result, const Image& reference, const DepthMap& depth,
                               double band_radius_px) {
  check_same_shape(result, reference, "compare_images");
  if (depth.width != result.width || depth.height != result.height) {
    throw OptionsError("compare_images: depth map is " + std::to_string(depth.width) + " x " +
                       std::to_string(depth.height) + " but the images are " + std::to_string(result.width) +
                       " x " + std::to_string(result.height));
  }
  ImageComparison out;
  out.psnr_db = psnr(result, reference);
  out.ssim = ssim(result, reference);
  const std::vector<std::uint8_t> band = depth_edge_band(depth, band_radius_px);
  out.edge_pixels = static_cast<std::size_t>(std::count(band.begin(), band.end(), std::uint8_t{1}));
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  out.edge_psnr_db = out.edge_pixels > 0 ? psnr(result, reference, &band) : kNaN;
  out.edge_ssim = out.edge_pixels > 0 ? ssim_over_mask(result, reference, &band).mean : kNaN;
  return out;
}

}  // namespace lensmith

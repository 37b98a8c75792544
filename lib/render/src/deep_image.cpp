#include "lensmith/render/deep_image.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/imageio/deep_raster.h"

namespace lensmith {

namespace fs = std::filesystem;

DeepImage::DeepImage(int w, int h) : width(w), height(h) {
  if (w < 1 || h < 1) throw OptionsError("a deep image needs at least 1 x 1 pixels, got " + std::to_string(w) + " x " + std::to_string(h));
  first_sample.reserve(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) + 1);
  first_sample.push_back(0);
}

std::span<const DeepSample> DeepImage::pixel(int x, int y) const {
  const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
  return {samples.data() + first_sample[p], samples.data() + first_sample[p + 1]};
}

void DeepImage::push_pixel(std::span<const DeepSample> pixel_samples) {
  if (first_sample.size() > static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {
    throw OptionsError("DeepImage::push_pixel: all " + std::to_string(width) + " x " + std::to_string(height) + " pixels are already there");
  }
  const auto begin = static_cast<std::ptrdiff_t>(samples.size());
  samples.insert(samples.end(), pixel_samples.begin(), pixel_samples.end());
  // Most pixels hold one sample, or samples already in order.
  const auto by_depth = [](const DeepSample& a, const DeepSample& b) { return a.z_m < b.z_m; };
  if (!std::is_sorted(samples.begin() + begin, samples.end(), by_depth)) std::stable_sort(samples.begin() + begin, samples.end(), by_depth);
  first_sample.push_back(samples.size());
}

Image DeepImage::flatten() const {
  Image out(width, height, 4);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      double rgb[3] = {0.0, 0.0, 0.0}, transmitted = 1.0;
      for (const DeepSample& s : pixel(x, y)) {
        for (std::size_t c = 0; c < 3; ++c) rgb[c] += transmitted * s.rgb[c];
        transmitted *= 1.0 - s.alpha;
      }
      for (int c = 0; c < 3; ++c) out.at(x, y, c) = static_cast<float>(rgb[c]);
      out.at(x, y, 3) = static_cast<float>(1.0 - transmitted);
    }
  }
  return out;
}

DepthMap DeepImage::front_depth() const {
  DepthMap d(width, height, std::numeric_limits<float>::infinity());
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const auto p = pixel(x, y);
      if (!p.empty()) d.at(x, y) = p.front().z_m;
    }
  }
  return d;
}

double DeepImage::max_transparency() const {
  double worst = 0.0;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      double transmitted = 1.0;
      for (const DeepSample& s : pixel(x, y)) transmitted *= 1.0 - s.alpha;
      worst = std::max(worst, transmitted);
    }
  }
  return worst;
}

std::string DeepImage::to_string() const {
  std::size_t volumes = 0;
  for (const DeepSample& s : samples) volumes += s.is_volume() ? 1 : 0;
  std::ostringstream os;
  const double pixels = static_cast<double>(width) * static_cast<double>(height);
  os << "DeepImage(" << width << " x " << height << ", " << samples.size() << " samples, "
     << format_rounded(pixels > 0 ? static_cast<double>(samples.size()) / pixels : 0.0, 3) << " per pixel, " << volumes << " volumes)";
  return os.str();
}

namespace {

std::string where(const fs::path& path, int x, int y, std::size_t k) {
  return path.string() + ": pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") sample " + std::to_string(k);
}

}  // namespace

DeepImage read_deep_image(const fs::path& path, const DepthReadOptions& options, const PinholeFrame& frame) {
  return deep_image_from(read_deep_raster(path), path, options, frame);
}

DeepImage deep_image_from(const DeepRaster& raster, const fs::path& path, const DepthReadOptions& options, const PinholeFrame& frame) {
  std::vector<std::string> missing;
  auto channel = [&](const char* name, bool required) {
    const int c = raster.channel_index(name);
    if (c < 0 && required) missing.emplace_back(name);
    return c;
  };
  const int r = channel("R", true), g = channel("G", true), b = channel("B", true), z = channel("Z", true);
  // Without A every sample is opaque: what `oiiotool --deepen` makes of a picture without alpha.
  const int a = channel("A", false);
  const int z_back = channel("ZBack", false);
  if (!missing.empty()) {
    std::string names, have;
    for (std::size_t i = 0; i < missing.size(); ++i) names += (i ? ", " : "") + missing[i];
    for (std::size_t i = 0; i < raster.channels.size(); ++i) have += (i ? ", " : "") + raster.channels[i];
    throw ImageFileError(path.string() + ": a deep image without channel " + names + "; lensmith reads deep R, G, B and Z " +
                         "(A and ZBack optional); the file has " + have);
  }
  if (raster.width != frame.width_px() || raster.height != frame.height_px()) {
    throw ImageFileError(path.string() + ": deep image of " + std::to_string(raster.width) + " x " + std::to_string(raster.height) +
                         " pixels, but the camera is framed for " + std::to_string(frame.width_px()) + " x " +
                         std::to_string(frame.height_px()));
  }
  const std::size_t nc = raster.channels.size();
  constexpr float kFar = std::numeric_limits<float>::infinity();
  DeepImage image(raster.width, raster.height);
  image.samples.reserve(raster.sample_count());
  // Depths that name no point in front of the camera, resolved after the nearest valid one is known.
  std::vector<std::pair<std::size_t, bool>> invalid;  // (sample index in image.samples, back depth)
  std::string first_invalid;
  float nearest_m = kFar;
  std::vector<DeepSample> pixel;
  for (int y = 0; y < raster.height; ++y) {
    for (int x = 0; x < raster.width; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(raster.width) + static_cast<std::size_t>(x);
      pixel.clear();
      std::vector<std::pair<std::size_t, bool>> bad_here;
      for (std::uint64_t s = raster.first_sample[p]; s < raster.first_sample[p + 1]; ++s) {
        const float* v = raster.samples.data() + s * nc;
        const std::size_t k = static_cast<std::size_t>(s - raster.first_sample[p]);
        DeepSample d;
        d.alpha = a >= 0 ? v[a] : 1.0f;
        if (!(d.alpha >= 0.0f && d.alpha <= 1.0f)) {
          throw ImageFileError(where(path, x, y, k) + ": A = " + format_number(d.alpha) + ": deep alpha must lie in [0, 1]");
        }
        const int rgb[3] = {r, g, b};
        for (std::size_t c = 0; c < 3; ++c) {
          d.rgb[c] = v[rgb[c]];
          if (!(std::isfinite(d.rgb[c]) && d.rgb[c] >= 0.0f)) {
            throw ImageFileError(where(path, x, y, k) + ": " + raster.channels[static_cast<std::size_t>(rgb[c])] + " = " +
                                 format_number(d.rgb[c]) + ": deep colour is linear radiance, which must be finite and >= 0");
          }
        }
        const double front = planar_depth_m(v[z], options, frame, x, y);
        const double back = z_back >= 0 ? planar_depth_m(v[z_back], options, frame, x, y) : front;
        d.z_m = static_cast<float>(front);
        d.z_back_m = static_cast<float>(back);
        const bool front_ok = d.z_m > 0.0f, back_ok = d.z_back_m > 0.0f;
        if (front_ok && back_ok && d.z_back_m < d.z_m) {
          throw ImageFileError(where(path, x, y, k) + ": ZBack = " + format_number(v[z_back]) + " lies in front of Z = " +
                               format_number(v[z]) + ": a sample's back cannot be nearer than its front");
        }
        if (front_ok) nearest_m = std::min(nearest_m, d.z_m);
        if (!front_ok || !back_ok) {
          if (first_invalid.empty()) {
            first_invalid = where(path, x, y, k) + ": " + (front_ok ? "ZBack = " + format_number(v[z_back]) : "Z = " + format_number(v[z]));
          }
          if (!front_ok) bad_here.emplace_back(pixel.size(), false);
          if (!back_ok) bad_here.emplace_back(pixel.size(), true);
        }
        pixel.push_back(d);
      }
      if (!bad_here.empty() && options.invalid != InvalidDepth::Error) {
        // Resolved now for Far; Near needs the whole image's nearest depth, so it is marked here.
        for (const auto& [i, is_back] : bad_here) {
          float& value = is_back ? pixel[i].z_back_m : pixel[i].z_m;
          value = options.invalid == InvalidDepth::Far ? kFar : -1.0f;
        }
      }
      if (!bad_here.empty() && options.invalid == InvalidDepth::Error) break;
      image.push_pixel(pixel);
    }
    if (!first_invalid.empty() && options.invalid == InvalidDepth::Error) break;
  }
  if (!first_invalid.empty() && options.invalid == InvalidDepth::Error) {
    const std::string expected = options.kind == DepthKind::Inverse ? "inverse depth must be finite and >= 0 (0 = infinitely far)"
                                                                    : "depth must be > 0";
    throw ImageFileError(first_invalid + ": " + expected + " (--invalid-depth far or near treats such depths as infinitely far or as the nearest valid depth)");
  }
  if (options.invalid == InvalidDepth::Near) {
    const float near_m = std::isfinite(nearest_m) ? nearest_m : kFar;
    for (DeepSample& s : image.samples) {
      if (s.z_m < 0.0f) s.z_m = near_m;
      if (s.z_back_m < 0.0f) s.z_back_m = near_m;
      s.z_back_m = std::max(s.z_back_m, s.z_m);
    }
    // Moved depths may change the order within a pixel.
    for (std::size_t p = 0; p + 1 < image.first_sample.size(); ++p) {
      std::stable_sort(image.samples.begin() + static_cast<std::ptrdiff_t>(image.first_sample[p]),
                       image.samples.begin() + static_cast<std::ptrdiff_t>(image.first_sample[p + 1]),
                       [](const DeepSample& u, const DeepSample& v) { return u.z_m < v.z_m; });
    }
  } else if (options.invalid == InvalidDepth::Far) {
    for (DeepSample& s : image.samples) s.z_back_m = std::max(s.z_back_m, s.z_m);
  }
  return image;
}

void write_deep_image(const fs::path& path, const DeepImage& deep, const OutputMetadata& meta) {
  if (!output_keeps_alpha(path)) throw OptionsError(path.string() + ": a deep image is written as OpenEXR only (.exr)");
  bool volumes = false;
  for (const DeepSample& s : deep.samples) volumes = volumes || s.is_volume();
  DeepRaster raster;
  raster.width = deep.width;
  raster.height = deep.height;
  raster.channels = {"R", "G", "B", "A", "Z"};
  if (volumes) raster.channels.emplace_back("ZBack");
  raster.first_sample = deep.first_sample;
  raster.samples.reserve(deep.samples.size() * raster.channels.size());
  for (int y = 0; y < deep.height; ++y) {
    for (int x = 0; x < deep.width; ++x) {
      for (const DeepSample& s : deep.pixel(x, y)) {
        const float values[6] = {s.rgb[0], s.rgb[1], s.rgb[2], s.alpha, s.z_m, s.z_back_m};
        for (std::size_t c = 0; c < raster.channels.size(); ++c) {
          if (std::isnan(values[c])) {
            throw ComputationError(path.string() + ": the deep image to write has NaN at pixel (" + std::to_string(x) + ", " +
                                   std::to_string(y) + ") channel " + raster.channels[c]);
          }
          raster.samples.push_back(values[c]);
        }
      }
    }
  }
  write_deep_exr(path, raster, output_attributes(meta));
}

}  // namespace lensmith

#include "lensmith/render/image.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "lensmith/core/errors.h"

namespace lensmith {

Image::Image(int width_px, int height_px, int channel_count, float fill)
    : width(width_px), height(height_px), channels(channel_count) {
  if (width_px < 1 || height_px < 1 || channel_count < 1) {
    throw OptionsError("image size must be at least 1 x 1 with 1 channel (got " + std::to_string(width_px) + " x " +
                       std::to_string(height_px) + ", " + std::to_string(channel_count) + " channels)");
  }
  data.assign(pixel_count() * static_cast<std::size_t>(channels), fill);
}

Image Image::leading_channels(int count) const {
  if (count < 1 || count > channels) {
    throw OptionsError("an image of " + std::to_string(channels) + " channels has no first " + std::to_string(count));
  }
  Image out(width, height, count);
  const auto in_stride = static_cast<std::size_t>(channels), out_stride = static_cast<std::size_t>(count);
  for (std::size_t i = 0; i < pixel_count(); ++i) {
    for (std::size_t c = 0; c < out_stride; ++c) out.data[i * out_stride + c] = data[i * in_stride + c];
  }
  return out;
}

double Image::mean(int c) const {
  double sum = 0.0;
  for (std::size_t i = 0; i < pixel_count(); ++i) sum += data[i * channels + c];
  return pixel_count() > 0 ? sum / static_cast<double>(pixel_count()) : 0.0;
}

std::string Image::to_string() const {
  std::ostringstream os;
  os << "Image(" << width << " x " << height << ", " << channels << " channels)";
  return os.str();
}

DepthMap::DepthMap(int width_px, int height_px, float fill_m) : width(width_px), height(height_px) {
  if (width_px < 1 || height_px < 1) {
    throw OptionsError("depth map size must be at least 1 x 1 (got " + std::to_string(width_px) + " x " +
                       std::to_string(height_px) + ")");
  }
  z_m.assign(static_cast<std::size_t>(width) * height, fill_m);
}

std::string DepthMap::to_string() const {
  std::ostringstream os;
  os << "DepthMap(" << width << " x " << height;
  if (!z_m.empty()) {
    const auto [lo, hi] = std::minmax_element(z_m.begin(), z_m.end());
    os << ", " << *lo << " m to " << *hi << " m";
  }
  os << ")";
  return os.str();
}

std::vector<float> extend_edges(std::span<const float> samples, int width, int height, int channels, int left, int top, int right,
                                int bottom) {
  if (width < 1 || height < 1 || channels < 1 || left < 0 || top < 0 || right < 0 || bottom < 0 ||
      samples.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * static_cast<std::size_t>(channels)) {
    throw OptionsError("extend_edges: " + std::to_string(samples.size()) + " samples for " + std::to_string(width) + " x " +
                       std::to_string(height) + " pixels of " + std::to_string(channels) + " channels, growth " + std::to_string(left) +
                       ", " + std::to_string(top) + ", " + std::to_string(right) + ", " + std::to_string(bottom));
  }
  const int w = width + left + right, h = height + top + bottom;
  const auto c = static_cast<std::size_t>(channels);
  std::vector<float> out(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * c);
  for (int y = 0; y < h; ++y) {
    const int sy = std::clamp(y - top, 0, height - 1);
    for (int x = 0; x < w; ++x) {
      const int sx = std::clamp(x - left, 0, width - 1);
      std::copy_n(samples.begin() + static_cast<std::ptrdiff_t>((static_cast<std::size_t>(sy) * static_cast<std::size_t>(width) + static_cast<std::size_t>(sx)) * c),
                  c, out.begin() + static_cast<std::ptrdiff_t>((static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)) * c));
    }
  }
  return out;
}

std::vector<float> crop_pixels(std::span<const float> samples, int full_width, int channels, int left, int top, int width, int height) {
  const auto c = static_cast<std::size_t>(std::max(channels, 1));
  const std::size_t full_height = full_width > 0 ? samples.size() / (static_cast<std::size_t>(full_width) * c) : 0;
  if (channels < 1 || width < 1 || height < 1 || left < 0 || top < 0 || left + width > full_width ||
      static_cast<std::size_t>(top + height) > full_height) {
    throw OptionsError("crop_pixels: " + std::to_string(width) + " x " + std::to_string(height) + " at (" + std::to_string(left) + ", " +
                       std::to_string(top) + ") is not inside a picture " + std::to_string(full_width) + " pixels wide and " +
                       std::to_string(full_height) + " high");
  }
  std::vector<float> out(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * c);
  for (int y = 0; y < height; ++y) {
    std::copy_n(samples.begin() + static_cast<std::ptrdiff_t>((static_cast<std::size_t>(y + top) * static_cast<std::size_t>(full_width) + static_cast<std::size_t>(left)) * c),
                static_cast<std::size_t>(width) * c, out.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(y) * static_cast<std::size_t>(width) * c));
  }
  return out;
}

namespace {

void check_squeeze(std::span<const float> samples, int width, int height, int channels, int new_width) {
  if (width < 1 || height < 1 || channels < 1 ||
      samples.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * static_cast<std::size_t>(channels)) {
    throw OptionsError("squeeze_columns: " + std::to_string(samples.size()) + " samples do not fill " + std::to_string(width) + " x " +
                       std::to_string(height) + " pixels of " + std::to_string(channels) + " channels");
  }
  if (new_width < 1) throw OptionsError("squeeze_columns: " + std::to_string(new_width) + " columns: expected at least 1");
}

}  // namespace

std::vector<float> squeeze_columns(std::span<const float> samples, int width, int height, int channels, int new_width) {
  check_squeeze(samples, width, height, channels, new_width);
  const double share = static_cast<double>(width) / new_width;  // old pixels per new one
  const auto c = static_cast<std::size_t>(channels);
  std::vector<float> out(static_cast<std::size_t>(new_width) * static_cast<std::size_t>(height) * c);
  std::vector<double> sum(c);
  for (int y = 0; y < height; ++y) {
    const float* row = samples.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(width) * c;
    float* to = out.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(new_width) * c;
    for (int i = 0; i < new_width; ++i) {
      const double from = i * share, until = std::min(static_cast<double>(width), (i + 1) * share);
      std::fill(sum.begin(), sum.end(), 0.0);
      for (int x = static_cast<int>(from); x < width && x < until; ++x) {
        const double overlap = std::min(until, x + 1.0) - std::max(from, static_cast<double>(x));
        for (std::size_t k = 0; k < c; ++k) sum[k] += overlap * row[static_cast<std::size_t>(x) * c + k];
      }
      for (std::size_t k = 0; k < c; ++k) to[static_cast<std::size_t>(i) * c + k] = static_cast<float>(sum[k] / (until - from));
    }
  }
  return out;
}

std::vector<float> squeeze_columns_nearest(std::span<const float> samples, int width, int height, int channels, int new_width) {
  check_squeeze(samples, width, height, channels, new_width);
  const double share = static_cast<double>(width) / new_width;
  const auto c = static_cast<std::size_t>(channels);
  std::vector<float> out(static_cast<std::size_t>(new_width) * static_cast<std::size_t>(height) * c);
  for (int y = 0; y < height; ++y) {
    for (int i = 0; i < new_width; ++i) {
      const int x = std::min(width - 1, static_cast<int>((i + 0.5) * share));
      const std::size_t from = (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * c;
      const std::size_t to = (static_cast<std::size_t>(y) * static_cast<std::size_t>(new_width) + static_cast<std::size_t>(i)) * c;
      std::copy_n(samples.begin() + static_cast<std::ptrdiff_t>(from), c, out.begin() + static_cast<std::ptrdiff_t>(to));
    }
  }
  return out;
}

}  // namespace lensmith

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

}  // namespace lensmith

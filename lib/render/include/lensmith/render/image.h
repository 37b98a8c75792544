// In-memory images for the renderer: linear float pixels, interleaved channels, row-major with the
// top row first (as image files store them), and a planar depth map in metres.
#pragma once

#include <cstddef>
#include <ostream>
#include <span>
#include <string>
#include <vector>

namespace lensmith {

// A linear (scene-referred) float image. Pixel (x, y) covers [x, x+1] x [y, y+1] in continuous
// pixel coordinates, x to the right and y down; channel c of it is data[(y * width + x) * channels + c].
struct Image {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> data;

  Image() = default;
  Image(int width_px, int height_px, int channel_count, float fill = 0.0f);  // throws OptionsError for sizes < 1
  std::size_t pixel_count() const { return static_cast<std::size_t>(width) * static_cast<std::size_t>(height); }
  float& at(int x, int y, int c) { return data[(static_cast<std::size_t>(y) * width + x) * channels + c]; }
  float at(int x, int y, int c) const { return data[(static_cast<std::size_t>(y) * width + x) * channels + c]; }
  // Mean of channel c over all pixels (double accumulation).
  double mean(int c) const;
  // The first `count` channels (1..channels), e.g. RGB of an RGBA image. Throws OptionsError otherwise.
  Image leading_channels(int count) const;
  std::string to_string() const;  // "Image(640 x 360, 3 channels)"
  friend std::ostream& operator<<(std::ostream& os, const Image& i) { return os << i.to_string(); }
};

// Planar depth: the distance along the optical axis from the camera (the entrance pupil of a real
// lens) to the surface seen through each pixel, in metres. +infinity means infinitely far.
struct DepthMap {
  int width = 0;
  int height = 0;
  std::vector<float> z_m;

  DepthMap() = default;
  DepthMap(int width_px, int height_px, float fill_m);  // throws OptionsError for sizes < 1
  float& at(int x, int y) { return z_m[static_cast<std::size_t>(y) * width + x]; }
  float at(int x, int y) const { return z_m[static_cast<std::size_t>(y) * width + x]; }
  std::string to_string() const;  // "DepthMap(640 x 360, 0.5 m to inf)"
  friend std::ostream& operator<<(std::ostream& os, const DepthMap& d) { return os << d.to_string(); }
};

// Interleaved samples (`channels` per pixel, rows top first) of a width x height picture grown by
// `left`, `top`, `right` and `bottom` pixels (each >= 0), every new pixel a copy of the nearest
// edge pixel (clamp to edge, as compositors extend a picture). Throws OptionsError when the
// samples do not fill width x height x channels.
std::vector<float> extend_edges(std::span<const float> samples, int width, int height, int channels, int left, int top, int right,
                                int bottom);

// The width x height pixels from (left, top) of interleaved samples of a picture `full_width` pixels
// wide (the inverse of extend_edges). Throws OptionsError when the box is not inside the picture.
std::vector<float> crop_pixels(std::span<const float> samples, int full_width, int channels, int left, int top, int width, int height);

// Interleaved samples of a width x height picture resampled to `new_width` columns (>= 1; fewer squeeze,
// more stretch): each new column the mean over its width / new_width share of the row, fractional pixels
// by their overlap, as a sensor pixel that many times wider integrates the light (an anamorphic lens's
// squeezed picture; no negative lobes to ring around highlights, and the mean of every row kept). Throws
// OptionsError for sizes that do not match.
std::vector<float> squeeze_columns(std::span<const float> samples, int width, int height, int channels, int new_width);
// The same narrowed by taking each new column's value from the old pixel under its centre: for what
// must not be averaged (a depth).
std::vector<float> squeeze_columns_nearest(std::span<const float> samples, int width, int height, int channels, int new_width);

}  // namespace lensmith

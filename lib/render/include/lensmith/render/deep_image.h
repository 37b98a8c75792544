// Layered input for the bokeh renderer: per pixel the surfaces seen along its pinhole ray, front to
// back, each with its premultiplied colour, its alpha (the share of the pixel it covers) and its
// depth; a volume (fog, smoke) has a back depth behind its front. What an OpenEXR deep image holds
// (the OpenEXR documentation, "Interpreting OpenEXR Deep Pixels"), and what a single picture with
// one depth per pixel cannot know: the background behind an anti-aliased edge, or behind a whole
// foreground where the file was rendered with several layers per pixel.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include "lensmith/camera/pinhole_frame.h"
#include "lensmith/imageio/deep_raster.h"
#include "lensmith/render/image.h"
#include "lensmith/render/image_io.h"

namespace lensmith {

struct DeepSample {
  std::array<float, 3> rgb{};  // linear radiance premultiplied by alpha (>= 0)
  float alpha = 1.0f;          // 0..1
  float z_m = 0.0f;            // planar depth of its front, metres from the entrance pupil (> 0, +inf = infinitely far)
  float z_back_m = 0.0f;       // planar depth of its back: z_m for a surface, more for a volume
  bool is_volume() const { return z_back_m > z_m; }
};

struct DeepImage {
  int width = 0;
  int height = 0;
  // Pixel p (row-major, top row first) holds samples [first_sample[p], first_sample[p + 1]), front
  // to back (increasing z_m).
  std::vector<std::uint64_t> first_sample;
  std::vector<DeepSample> samples;

  DeepImage() = default;
  // `width` x `height` pixels without samples.
  DeepImage(int width, int height);

  std::span<const DeepSample> pixel(int x, int y) const;
  std::size_t sample_count() const { return samples.size(); }
  // Appends the samples of the next pixel (row-major order), sorting them front to back; a whole
  // image is built pixel by pixel, `width * height` calls.
  void push_pixel(std::span<const DeepSample> pixel_samples);
  void push_pixel(std::initializer_list<DeepSample> pixel_samples) { push_pixel(std::span<const DeepSample>(pixel_samples.begin(), pixel_samples.size())); }

  // The picture a pinhole camera sees: samples composited front to back ("over"), a volume as one
  // sample. 4 channels: premultiplied RGB and alpha.
  Image flatten() const;
  // The depth of each pixel's front sample (+inf where a pixel has none), planar metres.
  DepthMap front_depth() const;
  // The largest alpha a pixel's samples leave uncovered, 0..1 (0: every pixel is opaque).
  double max_transparency() const;

  std::string to_string() const;  // "DeepImage(640 x 360, 1234567 samples, 1.2 per pixel, 310 volumes)"
  friend std::ostream& operator<<(std::ostream& os, const DeepImage& d) { return os << d.to_string(); }
};

// A deep OpenEXR as a DeepImage: channels R, G, B and Z, A when present (else every sample is opaque,
// as `oiiotool --deepen` writes a picture without alpha), ZBack when present (else every sample is
// a surface), depth converted like read_depth's (`options`, pixel (x, y) of `frame`). Samples are
// sorted front to back. Throws ImageFileError naming the file, pixel and sample for a missing
// channel, another size than the frame, a Z or ZBack that is NaN or names no point in front of the
// camera (under InvalidDepth::Error; far and near override as for flat depth), a ZBack in front of
// its Z, an alpha outside [0, 1] or NaN, and colour that is NaN, infinite or negative.
DeepImage read_deep_image(const std::filesystem::path& path, const DepthReadOptions& options, const PinholeFrame& frame);
// Writes `deep` as a deep scanline OpenEXR (channels R, G, B, A, Z, and ZBack where a sample is a
// volume; ZIPS compression), atomically, with the attributes of `meta` (output_attributes). Throws
// OptionsError when `path` is not .exr, ComputationError for a NaN sample (naming the
// pixel), IoError when it cannot be written.
void write_deep_image(const std::filesystem::path& path, const DeepImage& deep, const OutputMetadata& meta);

// The same from samples already decoded from `path` (named in the messages).
DeepImage deep_image_from(const DeepRaster& raster, const std::filesystem::path& path, const DepthReadOptions& options,
                          const PinholeFrame& frame);

}  // namespace lensmith

// A deep picture as OpenEXR stores it (the OpenEXR documentation, "Interpreting OpenEXR Deep
// Pixels"): per pixel a list of samples, any number of them, each with a value in every channel
// (colour premultiplied by its alpha, A, Z and optionally ZBack). Renderers write them (RenderMan,
// Arnold, Houdini, Octane), Nuke composites them; lensmith bokeh reads them as layered input. The
// samples are as stored: neither sorted nor checked here (the renderer's reader does that, naming
// the pixel).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "lensmith/imageio/image_file.h"

namespace lensmith {

struct DeepRaster {
  int width = 0;   // pixels, >= 1
  int height = 0;  // pixels, >= 1
  std::vector<std::string> channels;  // names, in RasterInfo's order (layer by layer: R, G, B, A, ..., Z, ZBack)
  // Pixel p (row-major, top row first) holds samples [first_sample[p], first_sample[p + 1]).
  std::vector<std::uint64_t> first_sample;  // width * height + 1 entries
  std::vector<float> samples;               // samples[s * channels.size() + c], as float

  int channel_index(std::string_view name) const;  // -1 when absent
  std::size_t sample_count() const { return first_sample.empty() ? 0 : static_cast<std::size_t>(first_sample.back()); }
  std::string to_string() const;  // "deep 640 x 360, channels R, G, B, A, Z, 1234567 samples"
};

// Most samples read from one file (each a float per channel): a guard against a file whose sample
// counts claim more memory than any picture needs.
inline constexpr std::uint64_t kMaxDeepSamples = std::uint64_t{1} << 28;

// True when `path` is an OpenEXR file whose first part is deep (scanline or tiled). Throws IoError
// when the file cannot be read; false for every other format.
bool is_deep_image(const std::filesystem::path& path);

// The size and channels of a deep OpenEXR's first part, without its samples (first_sample and
// samples empty). Throws as read_deep_raster does, short of decoding.
DeepRaster read_deep_header(const std::filesystem::path& path);

// The first part of a deep OpenEXR (deep scanline, or the full-resolution level of deep tiles),
// every channel as float, over its display window: pixels outside a data window cropped inside it
// (as renderers crop an element) have no samples. Throws IoError when it cannot be decoded,
// ImageFileError when it is not deep, its data window reaches beyond its display window (overscan), a channel is subsampled or the file holds
// more than `max_samples` samples (a fuzzer sets fewer).
DeepRaster read_deep_raster(const std::filesystem::path& path, std::uint64_t max_samples = kMaxDeepSamples);

// Writes `raster` as a deep scanline OpenEXR (32-bit float channels, ZIPS compression, the only
// block compressions deep files allow besides RLE), atomically like write_exr, with `attributes`.
// Throws OptionsError when first_sample or samples do not match the size and channels, IoError when
// the file cannot be written.
void write_deep_exr(const std::filesystem::path& path, const DeepRaster& raster, const std::vector<ImageAttribute>& attributes);

}  // namespace lensmith

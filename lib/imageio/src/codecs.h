// The per-format readers and writers behind image_file.h. Each reader fills RasterInfo from its
// header and decodes into float samples; image_file.cpp picks one by the file's first bytes.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "lensmith/imageio/image_file.h"
#include "lensmith/imageio/raster.h"

namespace lensmith::codecs {

namespace fs = std::filesystem;

using Metadata = std::vector<std::pair<std::string, std::string>>;

// All channels of a decoded file, before the caller's channel choice.
struct Decoded {
  RasterInfo info;
  std::vector<float> samples;  // interleaved, info.channels.size() per pixel
};

// Keeps `channels` (indices into decoded.info.channels) of a fully decoded picture.
Raster select_channels(const Decoded& decoded, std::span<const int> channels);

// The shortest text that reads back to exactly this float ("0.1", not "0.100000001").
std::string shortest_float_text(float value);

// OpenEXR (exr_codec.cpp).
RasterInfo read_exr_info(const fs::path& path);
Raster read_exr(const fs::path& path, const RasterInfo& info, std::span<const int> channels);
Metadata read_exr_metadata(const fs::path& path);
void write_exr_file(const fs::path& path, const std::string& file, const PixelsView<float>& pixels,
                    const std::vector<std::string>& channel_names,
                    const std::vector<ImageAttribute>& attributes, const std::optional<std::pair<PixelBox, PixelBox>>& windows = {});

// While an ImageReadCache is alive on a thread (its constructor begins, its destructor ends; they
// nest), the OpenEXR files opened there are kept open and parsed once (exr_codec.cpp's open_exr).
void begin_exr_memo();
void end_exr_memo();

// TIFF (tiff_codec.cpp).
RasterInfo read_tiff_info(const fs::path& path);
Decoded read_tiff(const fs::path& path);
Metadata read_tiff_metadata(const fs::path& path);
void write_tiff_file(const fs::path& path, const std::string& file, const PixelsView<std::uint16_t>& pixels,
                     const std::vector<ImageAttribute>& attributes);

// PNG chunks through libpng (png_codec.cpp): the colour-space chunks and text; PNG output.
struct PngChunks {
  bool linear = false;  // gAMA of 1.0 and no sRGB chunk
  Metadata text;
};
PngChunks read_png_chunks(const fs::path& path);
void write_png_file(const fs::path& path, const std::string& file, const PixelsView<std::uint8_t>& pixels,
                    const std::vector<ImageAttribute>& attributes);

// JPEG through libjpeg-turbo (jpeg_codec.cpp): gray, RGB, and CMYK converted to RGB.
RasterInfo read_jpeg_info(const fs::path& path);
Decoded read_jpeg(const fs::path& path);

// Formats decoded by stb_image: PNG, HDR, TGA, BMP, PNM (stb_codecs.cpp); JPEG metadata and output.
bool stb_can_decode(const fs::path& path);  // stb recognises the header (the test for TGA, which has no magic bytes)
RasterInfo read_stb_info(const fs::path& path, ImageFormat format);
Decoded read_stb(const fs::path& path, ImageFormat format);
Metadata read_jpeg_metadata(const fs::path& path);
Metadata read_hdr_metadata(const fs::path& path);
void write_jpeg_file(const fs::path& path, const std::string& file, const PixelsView<std::uint8_t>& pixels, int quality,
                     const std::vector<ImageAttribute>& attributes);
void write_hdr_file(const fs::path& path, const std::string& file, const PixelsView<float>& rgb,
                    const std::vector<ImageAttribute>& attributes);

// PFM, the portable float map (pfm_codec.cpp).
RasterInfo read_pfm_info(const fs::path& path);
Decoded read_pfm(const fs::path& path);

}  // namespace lensmith::codecs

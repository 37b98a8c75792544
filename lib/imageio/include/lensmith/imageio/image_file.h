// Reading and writing picture files without a general imaging library: OpenEXR for EXR, libtiff for
// TIFF, libpng for PNG output and PNG text chunks, libjpeg-turbo for JPEG, stb_image for decoding PNG, Radiance HDR,
// TGA, BMP and PNM, stb_image_write for JPEG and HDR output, and a reader of its own for PFM.
// The format of an input is found from its first bytes; writers write through a temporary file in
// the same folder that is renamed onto the target (core's write_atomically).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "lensmith/imageio/raster.h"

namespace lensmith {

// The formats read_raster_info recognises, for messages.
inline constexpr const char* kReadableImageFormats =
    "OpenEXR (scanline or tiled, flat), TIFF, PNG, JPEG, Radiance HDR, PFM, BMP, TGA and binary PNM (P5/P6)";

// The format of a picture file from its first bytes. Throws IoError naming the file when it cannot
// be opened or is none of kReadableImageFormats (the message lists them).
ImageFormat detect_image_format(const std::filesystem::path& path);

// The header of a picture file (the first part of a multi-part OpenEXR, the first page of a TIFF).
// Throws IoError when the file cannot be opened or decoded, ImageFileError when it is a deep
// OpenEXR image ("a deep image; lensmith reads flat images only"), its data window differs from
// its display window (a crop or overscan would shift the picture against the pixels read) or its
// samples are laid out in a way lensmith does not read (subsampled OpenEXR channels, a TIFF of
// signed 16/32-bit or 64-bit samples).
RasterInfo read_raster_info(const std::filesystem::path& path);

// Decodes the channels of `info` (as read_raster_info gave it for `path`) listed in `channels`
// (indices into info.channels, in the order wanted; repeats allowed). Integers are normalised to
// [0, 1] by their full scale and otherwise left as stored (no colour conversion). Throws IoError
// when decoding fails, OptionsError for an index out of range.
Raster read_raster(const std::filesystem::path& path, const RasterInfo& info, std::span<const int> channels);

// While one lives on a thread, read_raster on that thread decodes each file once and serves later
// reads of it (other channels of the same file) from the decoded samples. A render's inputs are
// often one OpenEXR file read for its colour, alpha, passes and depth, and every read decompresses
// all of a file's channels: on bench/blender's 600 x 400 scenes four reads took about 0.08 s, one
// takes 0.02 s. read_raster_info and read_image_metadata_pairs are served from it too: a render
// asked for one file's header about twenty times, 0.15 ms each. A file is known by its path, size
// and modification time. An OpenEXR file is also opened and its header parsed once while one lives
// (is_deep_image, the header, the pixels and the metadata each opened it: 12 opens of bench/blender's
// fence picture, 3). Scoped, so that the decoded samples and open files do not outlive the reading
// of the inputs.
class ImageReadCache {
 public:
  ImageReadCache();
  ~ImageReadCache();
  ImageReadCache(const ImageReadCache&) = delete;
  ImageReadCache& operator=(const ImageReadCache&) = delete;

  struct Entry;
  struct Header;

 private:
  ImageReadCache* previous_;
  std::vector<Entry> entries_;
  std::vector<Header> headers_;
  friend Raster read_raster(const std::filesystem::path& path, const RasterInfo& info, std::span<const int> channels);
  friend RasterInfo read_raster_info(const std::filesystem::path& path);
  friend std::vector<std::pair<std::string, std::string>> read_image_metadata_pairs(const std::filesystem::path& path);
};

// Threads the OpenEXR codec may use to decompress and compress blocks of scanlines (0: none besides
// the caller; the default is the machine's hardware threads). Process-wide, as OpenEXR's pool is.
void set_image_codec_threads(int threads);
// The threads the codecs use (at least 1, counting the caller): as set, else the machine's. The
// passes over a picture as read (picking its channels, checking its values) run on as many.
int image_codec_threads();

// The metadata of a picture file as (name, value) text, under the names OpenImageIO used:
// OpenEXR attributes (comments as ImageDescription, capDate as DateTime, owner as Copyright, the
// compression as "compression"; strings as stored, floats and doubles in the shortest text that
// reads back exactly; the standard chromaticities as "rx, ry, gx, gy, bx, by, wx, wy"), PNG text chunks (Description as ImageDescription), TIFF's Software,
// ImageDescription, DateTime, Artist, Copyright and DocumentName tags and its compression, a
// JPEG's Exif ImageDescription, Software, DateTime, Artist and Copyright (its comment as the
// ImageDescription when Exif has none), and the NAME=value header lines of a Radiance HDR file
// (SOFTWARE as Software). PFM, BMP, TGA and PNM have none. Throws IoError.
std::vector<std::pair<std::string, std::string>> read_image_metadata_pairs(const std::filesystem::path& path);

// The eight numbers of the chromaticities text read_image_metadata_pairs gives ("rx, ry, gx, gy, bx,
// by, wx, wy"), or nothing when the text is not exactly eight finite numbers.
std::optional<std::array<double, 8>> parse_chromaticities(std::string_view text);

// One item of metadata to write: text, or a number that formats with typed attributes (OpenEXR)
// keep as a double and others write as its shortest exact text. OpenEXR writes an attribute named
// "chromaticities" whose text is eight numbers (as read_image_metadata_pairs gives them) as the
// standard chromaticities attribute.
struct ImageAttribute {
  std::string name;  // "Software", "ImageDescription", "lensmith:lens", ...
  std::variant<std::string, double> value;
  // OpenEXR: a number as a 32-bit float attribute, the type OpenEXR's standard attributes have
  // (focus, aperture, focalLength, ...); other formats write the number as text either way.
  bool exr_float = false;
};

// Interleaved samples of `channels` channels, row-major, top row first.
template <typename Sample>
struct PixelsView {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::span<const Sample> samples;  // width * height * channels values
};

// Writers. Each takes the final path, writes atomically, and throws IoError naming `path` when the
// file cannot be written, OptionsError when the view's sizes do not match its samples.
// OpenEXR, 32-bit float, ZIP compression (16 scanlines a block), one channel per name; every attribute (ImageDescription
// stored as the standard "comments", DateTime as "capDate").
// `windows`, when given, are the file's data window (the pixels' size) and display window, for an
// image with overscan; by default both are the image at (0, 0).
void write_exr(const std::filesystem::path& path, const PixelsView<float>& pixels, const std::vector<std::string>& channel_names,
               const std::vector<ImageAttribute>& attributes, const std::optional<std::pair<PixelBox, PixelBox>>& windows = {});
// 8-bit PNG (1 to 4 channels: Y, YA, RGB, RGBA) with an sRGB chunk (the samples are sRGB codes) and
// one tEXt chunk per attribute (ImageDescription as the standard keyword "Description").
void write_png(const std::filesystem::path& path, const PixelsView<std::uint8_t>& pixels,
               const std::vector<ImageAttribute>& attributes);
// Baseline 8-bit JPEG of 1 or 3 channels at `quality` (1 to 100; above 90 without chroma
// subsampling); Software and ImageDescription become Exif tags and the description also the file's
// comment (a COM segment), as OpenImageIO wrote them; others are dropped (no free attributes).
void write_jpeg(const std::filesystem::path& path, const PixelsView<std::uint8_t>& pixels, int quality,
                const std::vector<ImageAttribute>& attributes);
// 16-bit TIFF of 1 to 4 channels, deflate (ZIP) compression with horizontal differencing; the
// Software and ImageDescription attributes become those tags, others are dropped.
void write_tiff(const std::filesystem::path& path, const PixelsView<std::uint16_t>& pixels,
                const std::vector<ImageAttribute>& attributes);
// Radiance RGBE of 3 channels (run-length encoded scanlines); each attribute becomes a header line
// NAME=value (Software as Radiance's SOFTWARE; line breaks in values become spaces; a name with '='
// is an OptionsError).
void write_hdr(const std::filesystem::path& path, const PixelsView<float>& rgb, const std::vector<ImageAttribute>& attributes);

}  // namespace lensmith

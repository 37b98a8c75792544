// Picture files: the format from the first bytes (each format's published signature), dispatch to
// the codec that reads or writes it, and the temporary-file-and-rename of core for every writer.
#include "lensmith/imageio/image_file.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <functional>
#include <memory>
#include <optional>
#include <string_view>

#include "codecs.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/text_file.h"

namespace lensmith {

namespace fs = std::filesystem;

namespace codecs {

Raster select_channels(const Decoded& decoded, std::span<const int> channels) {
  const std::size_t stride = decoded.info.channels.size();
  Raster raster;
  raster.width = decoded.info.width;
  raster.height = decoded.info.height;
  raster.channels = static_cast<int>(channels.size());
  const std::size_t pixels = static_cast<std::size_t>(raster.width) * static_cast<std::size_t>(raster.height);
  raster.samples.resize(pixels * channels.size());
  const auto count = static_cast<std::ptrdiff_t>(pixels);
#pragma omp parallel for num_threads(image_codec_threads()) schedule(static)
  for (std::ptrdiff_t p = 0; p < count; ++p) {
    const auto u = static_cast<std::size_t>(p);
    for (std::size_t c = 0; c < channels.size(); ++c) {
      raster.samples[u * channels.size() + c] = decoded.samples[u * stride + static_cast<std::size_t>(channels[c])];
    }
  }
  return raster;
}

std::string shortest_float_text(float value) {
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return std::string(buffer.data(), result.ptr);
}

}  // namespace codecs

namespace {

// The first bytes of a file; fewer when the file is shorter.
std::string leading_bytes(const fs::path& path, std::size_t count) {
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!file) throw IoError(path.string() + ": cannot read the image: " + std::strerror(errno));
  std::string bytes(count, '\0');
  bytes.resize(std::fread(bytes.data(), 1, count, file.get()));
  return bytes;
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

template <typename Sample>
void check_view(const fs::path& path, const PixelsView<Sample>& pixels, int min_channels, int max_channels) {
  if (pixels.width < 1 || pixels.height < 1 || pixels.channels < min_channels || pixels.channels > max_channels ||
      pixels.samples.size() != static_cast<std::size_t>(pixels.width) * static_cast<std::size_t>(pixels.height) *
                                   static_cast<std::size_t>(pixels.channels)) {
    throw OptionsError(path.string() + ": cannot write " + std::to_string(pixels.width) + " x " + std::to_string(pixels.height) +
                       " pixels of " + std::to_string(pixels.channels) + " channels from " + std::to_string(pixels.samples.size()) +
                       " samples: this format takes " + std::to_string(min_channels) + " to " + std::to_string(max_channels) +
                       " channels and width x height x channels samples");
  }
}

// Writes through a hidden temporary file beside `path` (same extension, for anyone looking at it).
void write_through_temporary(const fs::path& path, const std::function<void(const std::string&)>& write) {
  write_atomically(path.string(), path.extension().string(), write);
}

}  // namespace

ImageFormat detect_image_format(const fs::path& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw IoError(path.string() + ": cannot read the image: it is a folder");
  const std::string head = leading_bytes(path, 16);
  const auto starts = [&](std::string_view magic) { return std::string_view(head).substr(0, magic.size()) == magic; };
  using namespace std::string_view_literals;
  // OpenEXR file layout, "Magic Number"; TIFF 6.0 section 2 (and BigTIFF's 43); PNG spec 5.2;
  // JPEG's SOI marker and the first marker of the next segment; Radiance's "#?" program line.
  if (starts("\x76\x2f\x31\x01"sv)) return ImageFormat::Exr;
  if (starts("II*\0"sv) || starts("MM\0*"sv) || starts("II+\0"sv) || starts("MM\0+"sv)) return ImageFormat::Tiff;
  if (starts("\x89PNG\r\n\x1a\n"sv)) return ImageFormat::Png;
  if (starts("\xff\xd8\xff"sv)) return ImageFormat::Jpeg;
  if (starts("#?"sv)) return ImageFormat::Hdr;
  if (head.size() >= 3 && head[0] == 'P' && is_space(head[2])) {
    if (head[1] == 'F' || head[1] == 'f') return ImageFormat::Pfm;
    if (head[1] == '5' || head[1] == '6') return ImageFormat::Pnm;
  }
  if (starts("BM"sv)) return ImageFormat::Bmp;
  // TGA has no signature: it is what stb_image's header test accepts once the others are excluded.
  if (codecs::stb_can_decode(path)) return ImageFormat::Tga;
  throw IoError(path.string() + ": not a picture lensmith can read: its first bytes match none of the formats it reads, " +
                kReadableImageFormats);
}

std::string PixelBox::to_string() const {
  // In 64 bits: a damaged file's window may span more than an int.
  const long long w = static_cast<long long>(max_x) - min_x + 1, h = static_cast<long long>(max_y) - min_y + 1;
  return std::to_string(w) + " x " + std::to_string(h) + " at (" + std::to_string(min_x) + ", " + std::to_string(min_y) + ")";
}

namespace {

RasterInfo read_format_info(const fs::path& path) {
  const ImageFormat format = detect_image_format(path);
  switch (format) {
    case ImageFormat::Exr: return codecs::read_exr_info(path);
    case ImageFormat::Tiff: return codecs::read_tiff_info(path);
    case ImageFormat::Pfm: return codecs::read_pfm_info(path);
    case ImageFormat::Png: {
      RasterInfo info = codecs::read_stb_info(path, format);
      info.integers_are_linear = codecs::read_png_chunks(path).linear;
      return info;
    }
    case ImageFormat::Jpeg: return codecs::read_jpeg_info(path);
    case ImageFormat::Hdr:
    case ImageFormat::Bmp:
    case ImageFormat::Tga:
    case ImageFormat::Pnm: return codecs::read_stb_info(path, format);
  }
  throw IoError(path.string() + ": unknown image format");
}

RasterInfo read_raster_info_uncached(const fs::path& path) {
  RasterInfo info = read_format_info(path);
  if (info.data_window.width() < 1) {
    // A format without windows: both are the picture.
    info.data_window = PixelBox{0, 0, info.width - 1, info.height - 1};
    info.display_window = info.data_window;
  }
  return info;
}

// The cache read_raster uses on this thread, if any (innermost ImageReadCache).
thread_local ImageReadCache* current_read_cache = nullptr;

// Every channel of the file, decoded.
codecs::Decoded decode_all(const fs::path& path, const RasterInfo& info) {
  codecs::Decoded decoded;
  if (info.format == ImageFormat::Exr) {
    std::vector<int> all(info.channels.size());
    for (std::size_t c = 0; c < all.size(); ++c) all[c] = static_cast<int>(c);
    decoded.info = info;
    decoded.samples = codecs::read_exr(path, info, all).samples;
    return decoded;
  }
  switch (info.format) {
    case ImageFormat::Tiff: decoded = codecs::read_tiff(path); break;
    case ImageFormat::Pfm: decoded = codecs::read_pfm(path); break;
    case ImageFormat::Jpeg: decoded = codecs::read_jpeg(path); break;
    default: decoded = codecs::read_stb(path, info.format); break;
  }
  if (decoded.info.width != info.width || decoded.info.height != info.height ||
      decoded.info.channels.size() != info.channels.size()) {
    throw IoError(path.string() + ": the file changed while it was read (" + info.to_string() + ", then " +
                  decoded.info.to_string() + ")");
  }
  return decoded;
}

// What identifies a file's contents for the cache: its path, size and modification time.
struct FileStamp {
  std::string path;
  std::uintmax_t bytes = 0;
  fs::file_time_type modified{};
  bool operator==(const FileStamp&) const = default;
};

std::optional<FileStamp> stamp_of(const fs::path& path) {
  std::error_code ec;
  FileStamp stamp;
  stamp.path = fs::absolute(path, ec).lexically_normal().string();
  if (ec) return std::nullopt;
  stamp.bytes = fs::file_size(path, ec);
  if (ec) return std::nullopt;
  stamp.modified = fs::last_write_time(path, ec);
  if (ec) return std::nullopt;
  return stamp;
}

}  // namespace

struct ImageReadCache::Entry {
  FileStamp stamp;
  codecs::Decoded decoded;
};

// A file's header as read_raster_info and read_image_metadata_pairs give it, each once read.
struct ImageReadCache::Header {
  FileStamp stamp;
  std::optional<RasterInfo> info;
  std::optional<std::vector<std::pair<std::string, std::string>>> metadata;
};

ImageReadCache::ImageReadCache() : previous_(current_read_cache) {
  current_read_cache = this;
  codecs::begin_exr_memo();
}

ImageReadCache::~ImageReadCache() {
  codecs::end_exr_memo();
  current_read_cache = previous_;
}

namespace {

// `field` of path's header entry in `headers` (the current cache's; null without one), read by
// `read` the first time. Without a cache, or where the file cannot be stamped, read each time (and
// `read` reports the error).
template <typename T, typename Read>
T cached_header_field(std::vector<ImageReadCache::Header>* headers, const fs::path& path, std::optional<T> ImageReadCache::Header::*field,
                      Read&& read) {
  const std::optional<FileStamp> stamp = headers ? stamp_of(path) : std::nullopt;
  if (!stamp) return read(path);
  auto header = std::find_if(headers->begin(), headers->end(), [&](const ImageReadCache::Header& h) { return h.stamp == *stamp; });
  if (header == headers->end()) header = headers->insert(headers->end(), {*stamp, std::nullopt, std::nullopt});
  std::optional<T>& value = (*header).*field;
  if (!value) value = read(path);
  return *value;
}

}  // namespace

RasterInfo read_raster_info(const fs::path& path) {
  ImageReadCache* cache = current_read_cache;
  return cached_header_field(cache ? &cache->headers_ : nullptr, path, &ImageReadCache::Header::info, read_raster_info_uncached);
}

Raster read_raster(const fs::path& path, const RasterInfo& info, std::span<const int> channels) {
  for (const int c : channels) {
    if (c < 0 || static_cast<std::size_t>(c) >= info.channels.size()) {
      throw OptionsError(path.string() + ": channel index " + std::to_string(c) + " outside the file's " +
                         std::to_string(info.channels.size()) + " channels");
    }
  }
  ImageReadCache* cache = current_read_cache;
  const std::optional<FileStamp> stamp = cache ? stamp_of(path) : std::nullopt;
  if (!stamp) {
    // Without a cache only the channels asked for are converted (OpenEXR decompresses them all anyway).
    if (info.format == ImageFormat::Exr) return codecs::read_exr(path, info, channels);
    return codecs::select_channels(decode_all(path, info), channels);
  }
  for (const ImageReadCache::Entry& entry : cache->entries_) {
    if (entry.stamp == *stamp && entry.decoded.info.width == info.width && entry.decoded.info.height == info.height &&
        entry.decoded.info.channels.size() == info.channels.size()) {
      return codecs::select_channels(entry.decoded, channels);
    }
  }
  cache->entries_.push_back({*stamp, decode_all(path, info)});
  return codecs::select_channels(cache->entries_.back().decoded, channels);
}

namespace {

std::vector<std::pair<std::string, std::string>> read_metadata_pairs_uncached(const fs::path& path) {
  switch (detect_image_format(path)) {
    case ImageFormat::Exr: return codecs::read_exr_metadata(path);
    case ImageFormat::Tiff: return codecs::read_tiff_metadata(path);
    case ImageFormat::Png: return codecs::read_png_chunks(path).text;
    case ImageFormat::Jpeg: return codecs::read_jpeg_metadata(path);
    case ImageFormat::Hdr: return codecs::read_hdr_metadata(path);
    case ImageFormat::Pfm:
    case ImageFormat::Bmp:
    case ImageFormat::Tga:
    case ImageFormat::Pnm: return {};
  }
  return {};
}

}  // namespace

std::vector<std::pair<std::string, std::string>> read_image_metadata_pairs(const fs::path& path) {
  ImageReadCache* cache = current_read_cache;
  return cached_header_field(cache ? &cache->headers_ : nullptr, path, &ImageReadCache::Header::metadata, read_metadata_pairs_uncached);
}

void write_exr(const fs::path& path, const PixelsView<float>& pixels, const std::vector<std::string>& channel_names,
               const std::vector<ImageAttribute>& attributes, const std::optional<std::pair<PixelBox, PixelBox>>& windows) {
  check_view(path, pixels, 1, 1 << 16);
  if (channel_names.size() != static_cast<std::size_t>(pixels.channels)) {
    throw OptionsError(path.string() + ": " + std::to_string(channel_names.size()) + " channel names for " +
                       std::to_string(pixels.channels) + " channels");
  }
  if (windows && (windows->first.width() != pixels.width || windows->first.height() != pixels.height)) {
    throw OptionsError(path.string() + ": data window " + windows->first.to_string() + " for an image of " + std::to_string(pixels.width) +
                       " x " + std::to_string(pixels.height) + " pixels");
  }
  write_through_temporary(path, [&](const std::string& file) { codecs::write_exr_file(path, file, pixels, channel_names, attributes, windows); });
}

void write_png(const fs::path& path, const PixelsView<std::uint8_t>& pixels, const std::vector<ImageAttribute>& attributes) {
  check_view(path, pixels, 1, 4);
  write_through_temporary(path, [&](const std::string& file) { codecs::write_png_file(path, file, pixels, attributes); });
}

void write_jpeg(const fs::path& path, const PixelsView<std::uint8_t>& pixels, int quality,
                const std::vector<ImageAttribute>& attributes) {
  check_view(path, pixels, 1, 3);
  if (pixels.channels == 2) throw OptionsError(path.string() + ": JPEG takes 1 (gray) or 3 (RGB) channels, not 2");
  if (quality < 1 || quality > 100) throw OptionsError(path.string() + ": JPEG quality " + std::to_string(quality) + ": must be 1 to 100");
  write_through_temporary(path, [&](const std::string& file) { codecs::write_jpeg_file(path, file, pixels, quality, attributes); });
}

void write_tiff(const fs::path& path, const PixelsView<std::uint16_t>& pixels, const std::vector<ImageAttribute>& attributes) {
  check_view(path, pixels, 1, 4);
  write_through_temporary(path, [&](const std::string& file) { codecs::write_tiff_file(path, file, pixels, attributes); });
}

void write_hdr(const fs::path& path, const PixelsView<float>& rgb, const std::vector<ImageAttribute>& attributes) {
  check_view(path, rgb, 3, 3);
  write_through_temporary(path, [&](const std::string& file) { codecs::write_hdr_file(path, file, rgb, attributes); });
}

}  // namespace lensmith

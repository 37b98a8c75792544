// TIFF through libtiff (TIFF 6.0 and Adobe's deflate and SampleFormat additions): contiguous gray
// or RGB(A) with 8/16/32-bit unsigned or 16/32-bit float samples, in strips or tiles, read
// directly; any other layout libtiff can turn into 8-bit RGBA (palette, YCbCr, separate planes,
// 1/2/4-bit) through its RGBA reader. Output: 16-bit, deflate with horizontal differencing.
#include <tiffio.h>

#include <Imath/half.h>

#include <algorithm>
#include <array>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <memory>

#include "codecs.h"
#include "lensmith/core/errors.h"

namespace lensmith::codecs {

namespace {

// libtiff reports errors through handlers; these collect a file's messages for the exception and
// keep warnings (unknown tags and the like) off the user's terminal.
int collect_message(TIFF*, void* user_data, const char* module, const char* format, va_list args) {
  std::array<char, 512> buffer{};
  std::vsnprintf(buffer.data(), buffer.size(), format, args);
  auto& messages = *static_cast<std::string*>(user_data);
  if (!messages.empty()) messages += "; ";
  if (module != nullptr && *module != '\0') messages += std::string(module) + ": ";
  messages += buffer.data();
  return 1;  // handled: libtiff's global handler (which prints) is not called
}

int ignore_message(TIFF*, void*, const char*, const char*, va_list) { return 1; }

// An open TIFF with its own error text; not movable, since libtiff keeps the text's address.
class TiffFile {
 public:
  TiffFile(const fs::path& path, const std::string& file, const char* mode) : path_(path) {
    TIFFOpenOptions* options = TIFFOpenOptionsAlloc();
    TIFFOpenOptionsSetErrorHandlerExtR(options, collect_message, &errors_);
    TIFFOpenOptionsSetWarningHandlerExtR(options, ignore_message, nullptr);
    tiff_ = TIFFOpenExt(file.c_str(), mode, options);
    TIFFOpenOptionsFree(options);
    if (tiff_ == nullptr) fail(*mode == 'r' ? "cannot read the TIFF image" : "cannot create the TIFF image");
  }
  ~TiffFile() {
    if (tiff_ != nullptr) TIFFClose(tiff_);
  }
  TiffFile(const TiffFile&) = delete;
  TiffFile& operator=(const TiffFile&) = delete;

  TIFF* get() const { return tiff_; }
  [[noreturn]] void fail(const std::string& what) const {
    throw IoError(path_.string() + ": " + what + (errors_.empty() ? "" : ": " + errors_));
  }
  // Flushes and closes, reporting a failure (a full disk shows up here).
  void close() {
    const bool flushed = TIFFFlush(tiff_) == 1;
    TIFFClose(tiff_);
    tiff_ = nullptr;
    if (!flushed || !errors_.empty()) fail("cannot write the TIFF image");
  }

 private:
  fs::path path_;
  std::string errors_;
  TIFF* tiff_ = nullptr;
};

// How a TIFF's pixels are stored and which path reads them.
struct TiffLayout {
  RasterInfo info;
  std::uint16_t bits = 8;
  bool direct = true;  // contiguous gray/RGB with supported samples; else libtiff's RGBA reader
};

constexpr std::uint16_t kMaxTiffSamples = 64;
constexpr std::uint32_t kMaxTiffTileSide = 1024;
constexpr std::uint64_t kMaxTiffTileBytes = std::uint64_t{kMaxTiffTileSide} * kMaxTiffTileSide * kMaxTiffSamples * 4;

TiffLayout read_layout(const TiffFile& file, const fs::path& path) {
  TIFF* t = file.get();
  std::uint32_t width = 0, height = 0;
  std::uint16_t samples = 1, bits = 1, format = SAMPLEFORMAT_UINT, planar = PLANARCONFIG_CONTIG, photometric = 0;
  TIFFGetField(t, TIFFTAG_IMAGEWIDTH, &width);
  TIFFGetField(t, TIFFTAG_IMAGELENGTH, &height);
  TIFFGetFieldDefaulted(t, TIFFTAG_SAMPLESPERPIXEL, &samples);
  TIFFGetFieldDefaulted(t, TIFFTAG_BITSPERSAMPLE, &bits);
  TIFFGetFieldDefaulted(t, TIFFTAG_SAMPLEFORMAT, &format);
  TIFFGetFieldDefaulted(t, TIFFTAG_PLANARCONFIG, &planar);
  if (TIFFGetField(t, TIFFTAG_PHOTOMETRIC, &photometric) != 1) {
    photometric = samples >= 3 ? PHOTOMETRIC_RGB : PHOTOMETRIC_MINISBLACK;
  }
  if (width < 1 || height < 1 || width > (1u << 24) || height > (1u << 24)) {
    throw ImageFileError(path.string() + ": TIFF of " + std::to_string(width) + " x " + std::to_string(height) +
                         " pixels: not a picture lensmith can read");
  }
  // Gray or RGB with alpha and a few extra samples is what lensmith photographs; a count in the
  // thousands (the field is 16-bit) is a damaged header that would size the decoded picture.
  if (samples < 1 || samples > kMaxTiffSamples) {
    throw ImageFileError(path.string() + ": a TIFF of " + std::to_string(samples) + " samples per pixel; lensmith reads 1 to " +
                         std::to_string(kMaxTiffSamples) + " (gray or RGB, alpha and extra samples)");
  }
  if (TIFFIsTiled(t) != 0) {
    // libtiff decodes a whole tile at once: a tile claiming 825104 x 1024 pixels on a 16 x 16
    // picture took 2.5 GB (found by tests/fuzz's exr_image target). TIFF 6.0 (section 15) asks
    // for sides that are multiples of 16; writers use 16 to 1024, or the picture's own size.
    std::uint32_t tile_width = 0, tile_height = 0;
    TIFFGetField(t, TIFFTAG_TILEWIDTH, &tile_width);
    TIFFGetField(t, TIFFTAG_TILELENGTH, &tile_height);
    const auto largest = [](std::uint32_t side) { return std::max<std::uint32_t>((side + 15) / 16 * 16, kMaxTiffTileSide); };
    if (tile_width < 1 || tile_height < 1 || tile_width > largest(width) || tile_height > largest(height)) {
      throw ImageFileError(path.string() + ": TIFF tiles of " + std::to_string(tile_width) + " x " + std::to_string(tile_height) +
                           " pixels for a picture of " + std::to_string(width) + " x " + std::to_string(height) +
                           ": a damaged file (tiles are at most " + std::to_string(kMaxTiffTileSide) +
                           " pixels a side or the picture's size)");
    }
    // And at most 1024 x 1024 pixels of 64 float samples: a long thin picture's sides alone let a
    // tile of its whole width x 1024 rows through.
    if (TIFFTileSize64(t) > kMaxTiffTileBytes) {
      throw ImageFileError(path.string() + ": TIFF tiles of " + std::to_string(tile_width) + " x " + std::to_string(tile_height) +
                           " pixels of " + std::to_string(samples) + " samples take " + std::to_string(TIFFTileSize64(t)) +
                           " bytes each; lensmith reads tiles of up to " + std::to_string(kMaxTiffTileBytes >> 20) + " MiB");
    }
  }
  TiffLayout layout;
  layout.bits = bits;
  layout.info.format = ImageFormat::Tiff;
  layout.info.width = static_cast<int>(width);
  layout.info.height = static_cast<int>(height);

  const bool gray = photometric == PHOTOMETRIC_MINISBLACK;
  const bool rgb = photometric == PHOTOMETRIC_RGB && samples >= 3;
  SampleType type = SampleType::Uint8;
  bool supported_samples = true;
  if (format == SAMPLEFORMAT_IEEEFP && (bits == 16 || bits == 32)) {
    type = bits == 16 ? SampleType::Half : SampleType::Float;
  } else if (format == SAMPLEFORMAT_UINT && (bits == 8 || bits == 16 || bits == 32)) {
    type = bits == 8 ? SampleType::Uint8 : bits == 16 ? SampleType::Uint16 : SampleType::Uint32;
  } else {
    supported_samples = false;
  }
  layout.direct = planar == PLANARCONFIG_CONTIG && (gray || rgb) && supported_samples;
  if (layout.direct) {
    const std::vector<std::string> base = rgb ? std::vector<std::string>{"R", "G", "B"} : std::vector<std::string>{"Y"};
    for (std::uint16_t c = 0; c < samples; ++c) {
      std::string name = c < base.size() ? base[c] : c == base.size() ? "A" : "channel" + std::to_string(c);
      layout.info.channels.push_back({name, type});
    }
    return layout;
  }
  std::array<char, 1024> reason{};
  // Integers wider than 8 bits or floats would lose their precision in the 8-bit RGBA reader.
  if (bits <= 8 && format != SAMPLEFORMAT_IEEEFP && TIFFRGBAImageOK(t, reason.data()) == 1) {
    for (const char* name : {"R", "G", "B", "A"}) layout.info.channels.push_back({name, SampleType::Uint8});
    return layout;
  }
  throw ImageFileError(path.string() + ": a TIFF of " + std::to_string(samples) + " samples of " + std::to_string(bits) + "-bit " +
                       (format == SAMPLEFORMAT_IEEEFP ? "float" : format == SAMPLEFORMAT_INT ? "signed integer" : "integer") +
                       " (photometric " + std::to_string(photometric) + ", planar configuration " + std::to_string(planar) +
                       "): lensmith reads contiguous gray or RGB(A) TIFFs of 8/16/32-bit unsigned integers or 16/32-bit "
                       "floats; save it as one of those");
}

// Converts `count` samples of the file's type to float (integers by their full scale).
void to_float(const unsigned char* raw, std::size_t count, SampleType type, float* out) {
  for (std::size_t i = 0; i < count; ++i) {
    switch (type) {
      case SampleType::Uint8: out[i] = static_cast<float>(raw[i]) / 255.0f; break;
      case SampleType::Uint16: {
        std::uint16_t v = 0;
        std::memcpy(&v, raw + 2 * i, 2);
        out[i] = static_cast<float>(v) / 65535.0f;
        break;
      }
      case SampleType::Uint32: {
        std::uint32_t v = 0;
        std::memcpy(&v, raw + 4 * i, 4);
        out[i] = static_cast<float>(static_cast<double>(v) / 4294967295.0);
        break;
      }
      case SampleType::Half: {
        std::uint16_t bits = 0;
        std::memcpy(&bits, raw + 2 * i, 2);
        Imath::half h;
        h.setBits(bits);
        out[i] = static_cast<float>(h);
        break;
      }
      case SampleType::Float: std::memcpy(out + i, raw + 4 * i, 4); break;
    }
  }
}

void read_direct(const TiffFile& file, const TiffLayout& layout, std::vector<float>& samples) {
  TIFF* t = file.get();
  const auto width = static_cast<std::size_t>(layout.info.width);
  const auto height = static_cast<std::size_t>(layout.info.height);
  const std::size_t channels = layout.info.channels.size();
  const SampleType type = layout.info.channels.front().type;
  if (TIFFIsTiled(t) != 0) {
    std::uint32_t tile_width = 0, tile_height = 0;
    TIFFGetField(t, TIFFTAG_TILEWIDTH, &tile_width);
    TIFFGetField(t, TIFFTAG_TILELENGTH, &tile_height);
    std::vector<unsigned char> tile(static_cast<std::size_t>(TIFFTileSize64(t)));
    const std::size_t tile_row_samples = static_cast<std::size_t>(tile_width) * channels;
    const std::size_t sample_bytes = layout.bits / 8u;
    for (std::uint32_t ty = 0; ty < height; ty += tile_height) {
      for (std::uint32_t tx = 0; tx < width; tx += tile_width) {
        if (TIFFReadTile(t, tile.data(), tx, ty, 0, 0) < 0) file.fail("cannot read the TIFF tile at (" + std::to_string(tx) + ", " + std::to_string(ty) + ")");
        const std::size_t rows = std::min<std::size_t>(tile_height, height - ty);
        const std::size_t columns = std::min<std::size_t>(tile_width, width - tx);
        for (std::size_t r = 0; r < rows; ++r) {
          to_float(tile.data() + r * tile_row_samples * sample_bytes, columns * channels, type,
                   samples.data() + ((ty + r) * width + tx) * channels);
        }
      }
    }
    return;
  }
  std::vector<unsigned char> row(static_cast<std::size_t>(TIFFScanlineSize64(t)));
  for (std::uint32_t y = 0; y < height; ++y) {
    if (TIFFReadScanline(t, row.data(), y, 0) < 0) file.fail("cannot read row " + std::to_string(y) + " of the TIFF image");
    to_float(row.data(), width * channels, type, samples.data() + y * width * channels);
  }
}

void read_through_rgba(const TiffFile& file, const TiffLayout& layout, std::vector<float>& samples) {
  const auto width = static_cast<std::uint32_t>(layout.info.width);
  const auto height = static_cast<std::uint32_t>(layout.info.height);
  std::vector<std::uint32_t> rgba(static_cast<std::size_t>(width) * height);
  if (TIFFReadRGBAImageOriented(file.get(), width, height, rgba.data(), ORIENTATION_TOPLEFT, 0) != 1) {
    file.fail("cannot read the TIFF image");
  }
  for (std::size_t i = 0; i < rgba.size(); ++i) {
    const std::uint32_t p = rgba[i];
    samples[4 * i] = static_cast<float>(TIFFGetR(p)) / 255.0f;
    samples[4 * i + 1] = static_cast<float>(TIFFGetG(p)) / 255.0f;
    samples[4 * i + 2] = static_cast<float>(TIFFGetB(p)) / 255.0f;
    samples[4 * i + 3] = static_cast<float>(TIFFGetA(p)) / 255.0f;
  }
}

std::string compression_name(std::uint16_t compression) {
  switch (compression) {
    case COMPRESSION_NONE: return "none";
    case COMPRESSION_LZW: return "lzw";
    case COMPRESSION_ADOBE_DEFLATE:
    case COMPRESSION_DEFLATE: return "zip";
    case COMPRESSION_PACKBITS: return "packbits";
    case COMPRESSION_JPEG: return "jpeg";
    case COMPRESSION_ZSTD: return "zstd";
    case COMPRESSION_LZMA: return "lzma";
    case COMPRESSION_WEBP: return "webp";
    default: return std::to_string(compression);
  }
}

}  // namespace

RasterInfo read_tiff_info(const fs::path& path) {
  const TiffFile file(path, path.string(), "r");
  return read_layout(file, path).info;
}

Decoded read_tiff(const fs::path& path) {
  const TiffFile file(path, path.string(), "r");
  const TiffLayout layout = read_layout(file, path);
  Decoded decoded{layout.info, {}};
  decoded.samples.resize(static_cast<std::size_t>(layout.info.width) * static_cast<std::size_t>(layout.info.height) *
                         layout.info.channels.size());
  if (layout.direct) {
    read_direct(file, layout, decoded.samples);
  } else {
    read_through_rgba(file, layout, decoded.samples);
  }
  return decoded;
}

Metadata read_tiff_metadata(const fs::path& path) {
  const TiffFile file(path, path.string(), "r");
  Metadata metadata;
  std::uint16_t compression = COMPRESSION_NONE;
  TIFFGetFieldDefaulted(file.get(), TIFFTAG_COMPRESSION, &compression);
  metadata.emplace_back("compression", compression_name(compression));
  const std::array<std::pair<ttag_t, const char*>, 6> tags{{{TIFFTAG_SOFTWARE, "Software"},
                                                            {TIFFTAG_IMAGEDESCRIPTION, "ImageDescription"},
                                                            {TIFFTAG_DATETIME, "DateTime"},
                                                            {TIFFTAG_ARTIST, "Artist"},
                                                            {TIFFTAG_COPYRIGHT, "Copyright"},
                                                            {TIFFTAG_DOCUMENTNAME, "DocumentName"}}};
  for (const auto& [tag, name] : tags) {
    const char* text = nullptr;
    if (TIFFGetField(file.get(), tag, &text) == 1 && text != nullptr) metadata.emplace_back(name, text);
  }
  return metadata;
}

void write_tiff_file(const fs::path& path, const std::string& file_name, const PixelsView<std::uint16_t>& pixels,
                     const std::vector<ImageAttribute>& attributes) {
  TiffFile file(path, file_name, "w");
  TIFF* t = file.get();
  const auto channels = static_cast<std::uint16_t>(pixels.channels);
  TIFFSetField(t, TIFFTAG_IMAGEWIDTH, static_cast<std::uint32_t>(pixels.width));
  TIFFSetField(t, TIFFTAG_IMAGELENGTH, static_cast<std::uint32_t>(pixels.height));
  TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, channels);
  TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, 16);
  TIFFSetField(t, TIFFTAG_SAMPLEFORMAT, SAMPLEFORMAT_UINT);
  TIFFSetField(t, TIFFTAG_PHOTOMETRIC, channels >= 3 ? PHOTOMETRIC_RGB : PHOTOMETRIC_MINISBLACK);
  TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  TIFFSetField(t, TIFFTAG_ORIENTATION, ORIENTATION_TOPLEFT);
  TIFFSetField(t, TIFFTAG_COMPRESSION, COMPRESSION_ADOBE_DEFLATE);
  TIFFSetField(t, TIFFTAG_PREDICTOR, PREDICTOR_HORIZONTAL);
  if (channels == 2 || channels == 4) {
    const std::uint16_t alpha[1] = {EXTRASAMPLE_UNASSALPHA};
    TIFFSetField(t, TIFFTAG_EXTRASAMPLES, 1, alpha);
  }
  TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, TIFFDefaultStripSize(t, 0));
  for (const ImageAttribute& attribute : attributes) {
    const auto* text = std::get_if<std::string>(&attribute.value);
    if (text == nullptr) continue;
    if (attribute.name == "Software") TIFFSetField(t, TIFFTAG_SOFTWARE, text->c_str());
    if (attribute.name == "ImageDescription") TIFFSetField(t, TIFFTAG_IMAGEDESCRIPTION, text->c_str());
  }
  // libtiff's differencing predictor works in place: each row goes through a copy.
  const std::size_t row_samples = static_cast<std::size_t>(pixels.width) * channels;
  std::vector<std::uint16_t> row(row_samples);
  for (int y = 0; y < pixels.height; ++y) {
    std::copy_n(pixels.samples.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(y) * row_samples), row_samples,
                row.begin());
    if (TIFFWriteScanline(t, row.data(), static_cast<std::uint32_t>(y), 0) != 1) file.fail("cannot write the TIFF pixels");
  }
  file.close();
}

}  // namespace lensmith::codecs

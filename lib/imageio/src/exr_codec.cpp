// OpenEXR through its C++ API (OpenEXR 3.1): the first part of a file, scanline or tiled, flat;
// deep parts are recognised from the part type and refused here, so a deep reader needs only a
// branch in read_exr that opens Imf::DeepScanLineInputPart / DeepTiledInputPart on the same file.
// Attribute names follow OpenImageIO's mapping (comments <-> ImageDescription, ...).
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfChromaticitiesAttribute.h>
#include <OpenEXR/ImfDeepFrameBuffer.h>
#include <OpenEXR/ImfDeepScanLineInputPart.h>
#include <OpenEXR/ImfDeepScanLineOutputFile.h>
#include <OpenEXR/ImfDeepTiledInputPart.h>
#include <OpenEXR/ImfCompressionAttribute.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfThreading.h>
#include <OpenEXR/ImfVecAttribute.h>
#include <OpenEXR/openexr.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <unistd.h>
#include <climits>
#include <cerrno>
#include <cstring>
#include <zlib.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <array>
#include <cstdint>
#include <atomic>
#include <cctype>
#include <memory>
#include <optional>
#include <fstream>
#include <set>
#include <string_view>
#include <thread>
#include <variant>

#include "codecs.h"
#include "lensmith/core/ascii_text.h"
#include "lensmith/imageio/deep_raster.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/text_file.h"

namespace lensmith::codecs {

namespace {

// OpenEXR's standard attribute names and the names OpenImageIO (and so lensmith's users) know them by.
constexpr std::array<std::pair<std::string_view, std::string_view>, 6> kAttributeNames{{
    {"comments", "ImageDescription"},
    {"capDate", "DateTime"},
    {"owner", "Copyright"},
    {"pixelAspectRatio", "PixelAspectRatio"},
    {"expTime", "ExposureTime"},
    {"aperture", "FNumber"},
}};

std::string common_name(const std::string& exr_name) {
  for (const auto& [exr, common] : kAttributeNames) {
    if (exr == exr_name) return std::string(common);
  }
  return exr_name;
}

std::string exr_name(const std::string& common) {
  for (const auto& [exr, name] : kAttributeNames) {
    if (name == common) return std::string(exr);
  }
  return common;
}

// The layout of a part; only the header attributes that describe it, not metadata.
bool is_structural(std::string_view name) {
  for (const char* s : {"channels", "dataWindow", "displayWindow", "lineOrder", "type", "tiles", "chunkCount", "version"}) {
    if (name == s) return true;
  }
  return false;
}

// An attribute as OpenEXR stores it: its OpenEXR name and typed value. "chromaticities" becomes the
// standard attribute's primaries (rx, ry, gx, gy, bx, by, wx, wy) only: a string of that name would
// hide them from readers. Numbers are floats where the attribute says (OpenEXR's standard ones).
struct ExrAttribute {
  std::string name;
  std::variant<std::array<float, 8>, std::string, float, double> value;
};

ExrAttribute exr_attribute(const ImageAttribute& attribute) {
  if (attribute.name == "chromaticities") {
    const auto* text = std::get_if<std::string>(&attribute.value);
    const std::optional<std::array<double, 8>> c = text ? parse_chromaticities(*text) : std::nullopt;
    if (!c) throw OptionsError("chromaticities attribute: expected eight numbers \"rx, ry, gx, gy, bx, by, wx, wy\"");
    std::array<float, 8> f{};
    for (std::size_t i = 0; i < f.size(); ++i) f[i] = static_cast<float>((*c)[i]);
    return {"chromaticities", f};
  }
  if (const auto* text = std::get_if<std::string>(&attribute.value)) return {exr_name(attribute.name), *text};
  const double number = std::get<double>(attribute.value);
  if (attribute.exr_float) return {exr_name(attribute.name), static_cast<float>(number)};
  return {exr_name(attribute.name), number};
}

void insert_attributes(Imf::Header& header, const std::vector<ImageAttribute>& attributes) {
  for (const ImageAttribute& attribute : attributes) {
    const ExrAttribute a = exr_attribute(attribute);
    if (const auto* c = std::get_if<std::array<float, 8>>(&a.value)) {
      const auto xy = [&](std::size_t i) { return Imath::V2f((*c)[i], (*c)[i + 1]); };
      header.insert(a.name, Imf::ChromaticitiesAttribute(Imf::Chromaticities(xy(0), xy(2), xy(4), xy(6))));
    } else if (const auto* text = std::get_if<std::string>(&a.value)) {
      header.insert(a.name, Imf::StringAttribute(*text));
    } else if (const auto* f = std::get_if<float>(&a.value)) {
      header.insert(a.name, Imf::FloatAttribute(*f));
    } else {
      header.insert(a.name, Imf::DoubleAttribute(std::get<double>(a.value)));
    }
  }
}

std::string compression_name(Imf::Compression c) {
  switch (c) {
    case Imf::NO_COMPRESSION: return "none";
    case Imf::RLE_COMPRESSION: return "rle";
    case Imf::ZIPS_COMPRESSION: return "zips";
    case Imf::ZIP_COMPRESSION: return "zip";
    case Imf::PIZ_COMPRESSION: return "piz";
    case Imf::PXR24_COMPRESSION: return "pxr24";
    case Imf::B44_COMPRESSION: return "b44";
    case Imf::B44A_COMPRESSION: return "b44a";
    case Imf::DWAA_COMPRESSION: return "dwaa";
    case Imf::DWAB_COMPRESSION: return "dwab";
    default: return "unknown";
  }
}

SampleType sample_type(Imf::PixelType type) {
  switch (type) {
    case Imf::UINT: return SampleType::Uint32;
    case Imf::HALF: return SampleType::Half;
    default: return SampleType::Float;
  }
}

// Rank of a channel's suffix within its layer, as OpenImageIO orders them (colour, then alpha,
// then depth); layers holding X with Y or Z are positions or normals and keep X, Y, Z together.
int suffix_rank(std::string_view suffix, bool xyz_layer) {
  static constexpr std::array<std::string_view, 20> kUsual{"r", "red", "g", "green", "b", "blue", "y", "real", "imag", "a",
                                                           "alpha", "ar", "ra", "ag", "ga", "ab", "ba", "z", "depth", "zback"};
  static constexpr std::array<std::string_view, 21> kXyz{"r", "red", "g", "green", "b", "blue", "x", "y", "z", "real", "imag",
                                                         "a", "alpha", "ar", "ra", "ag", "ga", "ab", "ba", "depth", "zback"};
  const std::string s = to_lower_ascii(suffix);
  if (xyz_layer) {
    for (std::size_t i = 0; i < kXyz.size(); ++i) {
      if (kXyz[i] == s) return static_cast<int>(i);
    }
  } else {
    for (std::size_t i = 0; i < kUsual.size(); ++i) {
      if (kUsual[i] == s) return static_cast<int>(i);
    }
  }
  return 10000;
}

struct ChannelName {
  std::string full;    // "depth.Z"
  std::string layer;   // "depth." ("" for none)
  std::string suffix;  // "Z"
  int rank = 0;
};

// The channel names of a part in the order described in RasterInfo::channels.
std::vector<std::string> canonical_order(const Imf::ChannelList& list) {
  std::vector<ChannelName> names;
  for (auto it = list.begin(); it != list.end(); ++it) {
    ChannelName n;
    n.full = it.name();
    const std::size_t dot = n.full.rfind('.');
    n.layer = dot == std::string::npos ? "" : n.full.substr(0, dot + 1);
    n.suffix = dot == std::string::npos ? n.full : n.full.substr(dot + 1);
    names.push_back(std::move(n));
  }
  for (std::size_t begin = 0; begin < names.size();) {
    std::size_t end = begin;
    bool has_x = false, has_yz = false;
    while (end < names.size() && names[end].layer == names[begin].layer) {
      const std::string s = to_lower_ascii(names[end].suffix);
      has_x |= s == "x";
      has_yz |= s == "y" || s == "z";
      ++end;
    }
    for (std::size_t i = begin; i < end; ++i) names[i].rank = suffix_rank(names[i].suffix, has_x && has_yz);
    begin = end;
  }
  // OpenEXR lists channels sorted by name, so each layer's channels are already together.
  std::stable_sort(names.begin(), names.end(), [](const ChannelName& a, const ChannelName& b) {
    if (a.layer != b.layer) return a.layer < b.layer;
    if (a.rank != b.rank) return a.rank < b.rank;
    return a.suffix < b.suffix;
  });
  std::vector<std::string> out;
  for (const ChannelName& n : names) out.push_back(n.full);
  return out;
}

// zlib level of the EXRs lensmith writes (flat and deep).
constexpr int kZipLevel = 1;
// A block of the flat EXRs lensmith writes is deflated only where a deflated sample of it (its first
// 1/kZipSampleParts of each filtered half) shrinks to less than kZipWorthRatio of its size; else it is
// stored as it is, as OpenEXR stores a block that does not shrink (its readers know one by its size).
// A rendered picture's float samples carry noise in their low bytes that no deflate removes: the
// bench/blender scenes' lensmith outputs deflate to 0.77 (street, with its flat sky) to 0.96 (fence)
// of their size, block by block from 0.13 to 0.97, and deflating them was half of writing them.
constexpr std::size_t kZipSampleParts = 8;
constexpr double kZipWorthRatio = 0.97;

// Threads for OpenEXR's block (de)compression: -1 until set_image_codec_threads, then its count.
std::atomic<int> codec_threads{-1};

// OpenEXR's global pool sized as asked (by default, the machine's hardware threads): zlib is the
// cost of reading and writing float images, and blocks of scanlines compress independently.
// The codec threads asked for (set_image_codec_threads), else the machine's hardware threads.
int codec_thread_count() {
  const int asked = codec_threads.load();
  return asked >= 0 ? asked : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

void size_codec_pool() {
  int wanted = codec_thread_count();
  if (wanted == 1) wanted = 0;  // the caller alone
  if (Imf::globalThreadCount() != wanted) Imf::setGlobalThreadCount(wanted);
}

// The bytes OpenEXR 3.1 reads for the value of an attribute of a fixed-size type whatever its size
// field says (TypedAttribute::readValueFrom reads the type), 0 for the types it reads by size.
std::size_t fixed_value_bytes(std::string_view type) {
  static constexpr std::array<std::pair<std::string_view, std::size_t>, 24> kFixed{{
      {"box2i", 16}, {"box2f", 16}, {"compression", 1}, {"lineOrder", 1}, {"envmap", 1}, {"deepImageState", 1},
      {"float", 4}, {"double", 8}, {"int", 4}, {"rational", 8}, {"timecode", 8}, {"keycode", 28},
      {"tiledesc", 9}, {"v2i", 8}, {"v2f", 8}, {"v2d", 16}, {"v3i", 12}, {"v3f", 12},
      {"v3d", 24}, {"m33f", 36}, {"m33d", 72}, {"m44f", 64}, {"m44d", 128}, {"chromaticities", 32},
  }};
  for (const auto& [name, bytes] : kFixed) {
    if (name == type) return bytes;
  }
  return 0;
}

// The headers' attribute sizes against the file's length, walked as OpenEXR 3.1's Header::readFrom
// walks them, before OpenEXR reads them: it allocates what a string, opaque or preview attribute
// claims before reading it, so a damaged header claiming 2 GB took 2 GB (found by tests/fuzz's
// exr_image target). Layout from the OpenEXR file layout document: magic and version (8 bytes),
// then per part a header of attributes (name, type, 32-bit little-endian size, value) ended by an
// empty name; a multi-part file ends its headers with one more empty name. Where the walk cannot
// follow, OpenEXR's own checks decide.
// The walk also refuses an attribute named twice in one header: OpenEXR 3.1's C++ reader keeps the
// last copy and OpenEXRCore the first, so a damaged file with two data windows was sized by one and
// decoded by the other, past the end of the pixels (found by CI's exr_image fuzz run on 0ac7166).
// No writer makes such a header (OpenEXR's own keeps its attributes in a map).
void check_header_attributes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::error_code ec;
  const std::uintmax_t length = fs::file_size(path, ec);
  if (!in || ec) return;
  char start[8];
  if (!in.read(start, 8)) return;
  const bool multipart = (static_cast<unsigned char>(start[5]) & 0x10) != 0;
  auto read_name = [&](std::string& name) {
    name.clear();
    for (char c; in.get(c);) {
      if (c == '\0') return true;
      if (name.size() >= 255) return false;
      name += c;
    }
    return false;
  };
  auto read_u32 = [&](std::uint32_t& v) {
    unsigned char b[4];
    if (!in.read(reinterpret_cast<char*>(b), 4)) return false;
    v = b[0] | (b[1] << 8) | (b[2] << 16) | (static_cast<std::uint32_t>(b[3]) << 24);
    return true;
  };
  auto remaining = [&]() {
    const auto at = static_cast<std::uintmax_t>(in.tellg());
    return at <= length ? length - at : 0;
  };
  auto too_big = [&](const std::string& name, std::uintmax_t claim) {
    throw IoError(path.string() + ": cannot read the OpenEXR image: header attribute '" + name + "' claims " + std::to_string(claim) +
                  " bytes, more than the " + std::to_string(remaining()) + " left in the file (a damaged file)");
  };
  for (int part = 0; part < 1 << 16; ++part) {
    std::string name, type;
    std::set<std::string> names;
    while (true) {
      if (!read_name(name)) return;
      if (name.empty()) break;
      if (!names.insert(name).second) {
        throw IoError(path.string() + ": cannot read the OpenEXR image: header attribute '" + name +
                      "' appears twice (a damaged file: OpenEXR's readers disagree on which copy counts)");
      }
      std::uint32_t size = 0;
      if (!read_name(type) || !read_u32(size)) return;
      // OpenEXR reads the size as a signed int: a negative one became an allocation of 2^64 - |size|
      // bytes for an attribute of unknown type (found by tests/fuzz's exr_image target).
      if (size > 0x7fffffffu) {
        throw IoError(path.string() + ": cannot read the OpenEXR image: header attribute '" + name + "' has a negative size (a damaged file)");
      }
      if (type == "tiledesc") {
        // OpenEXR sizes a deep tiled file's sample-count table as xSize * ySize * 4 in an int: a
        // tile of 2^15 x 2^15 pixels became an allocation of 2^64 - 2^31 bytes (found by
        // tests/fuzz's exr_image target), and so did one of exactly 2^29 pixels. Real tiles are 32 to
        // 256 pixels wide; 2^24 pixels (4096 x 4096) leaves room for any and far from the overflow.
        std::uint32_t x = 0, y = 0;
        if (!read_u32(x) || !read_u32(y)) return;
        if (x == 0 || y == 0 || std::uint64_t{x} * y > (std::uint64_t{1} << 24)) {
          throw IoError(path.string() + ": cannot read the OpenEXR image: tile size " + std::to_string(x) + " x " + std::to_string(y) +
                        " in attribute '" + name + "' (a damaged file)");
        }
        in.seekg(1, std::ios::cur);  // the level and rounding mode
      } else if (const std::size_t fixed = fixed_value_bytes(type); fixed > 0) {
        in.seekg(static_cast<std::streamoff>(fixed), std::ios::cur);
      } else if (type == "chlist") {
        // Channels until an empty name, each a name and 16 bytes.
        std::string channel;
        while (read_name(channel) && !channel.empty()) in.seekg(16, std::ios::cur);
      } else if (type == "preview") {
        std::uint32_t w = 0, h = 0;
        if (!read_u32(w) || !read_u32(h)) return;
        const std::uintmax_t bytes = std::uintmax_t{4} * w * h;
        if (bytes > remaining()) too_big(name, bytes);
        in.seekg(static_cast<std::streamoff>(bytes), std::ios::cur);
      } else {
        if (size > remaining()) too_big(name, size);
        in.seekg(static_cast<std::streamoff>(size), std::ios::cur);
      }
      if (!in) return;
    }
    if (!multipart || names.empty()) return;
  }
}

// The files open_exr opened on this thread while an ImageReadCache is alive here (exr_memo_depth > 0),
// each by what identifies its contents (device, inode, size, modification time): a command asks
// whether its picture is deep, then for its header, pixels and metadata, and each opened the file,
// walked its header (check_header_attributes) and parsed it again: the bench/blender fence's
// pinhole.exr was opened 12 times.
struct OpenedExr {
  dev_t device = 0;
  ino_t inode = 0;
  off_t bytes = 0;
  timespec modified{};
  std::shared_ptr<Imf::MultiPartInputFile> file;
};
thread_local int exr_memo_depth = 0;
thread_local std::vector<OpenedExr> exr_memo;

std::shared_ptr<Imf::MultiPartInputFile> open_exr(const fs::path& path) {
  struct stat status {};
  const bool memo = exr_memo_depth > 0 && ::stat(path.c_str(), &status) == 0;
  const auto same = [&](const OpenedExr& o) {
    return o.device == status.st_dev && o.inode == status.st_ino && o.bytes == status.st_size && o.modified.tv_sec == status.st_mtim.tv_sec &&
           o.modified.tv_nsec == status.st_mtim.tv_nsec;
  };
  if (memo) {
    if (const auto it = std::find_if(exr_memo.begin(), exr_memo.end(), same); it != exr_memo.end()) return it->file;
  }
  check_header_attributes(path);
  std::shared_ptr<Imf::MultiPartInputFile> file;
  try {
    file = std::make_shared<Imf::MultiPartInputFile>(path.c_str());
  } catch (const std::exception& e) {
    throw IoError(path.string() + ": cannot read the OpenEXR image: " + e.what());
  }
  if (memo) exr_memo.push_back({status.st_dev, status.st_ino, status.st_size, status.st_mtim, file});
  return file;
}

bool is_deep(const Imf::Header& header) { return header.hasType() && Imf::isDeepData(header.type()); }

// The data window, which must be the display window: a crop or overscan would shift the picture
// against the pinhole frame, centred on the pixels read.
void check_windows(const fs::path& path, const Imf::Header& header) {
  const Imath::Box2i data = header.dataWindow();
  const Imath::Box2i display = header.displayWindow();
  if (data == display) return;
  const int width = data.max.x - data.min.x + 1, height = data.max.y - data.min.y + 1;
  const int full_width = display.max.x - display.min.x + 1;
  const int full_height = display.max.y - display.min.y + 1;
  throw ImageFileError(path.string() + ": data window " + std::to_string(width) + " x " + std::to_string(height) +
                       " at (" + std::to_string(data.min.x) + ", " + std::to_string(data.min.y) +
                       ") differs from the display window " + std::to_string(full_width) + " x " +
                       std::to_string(full_height) + " at (" + std::to_string(display.min.x) + ", " +
                       std::to_string(display.min.y) + "): render or save the image without a crop or overscan");
}

// Pictures of more than kMaxImagePixels: a header's claim that no picture needs (and that would
// take all memory to decode) is refused before anything is allocated.
constexpr long long kMaxImagePixels = 1LL << 28;  // 16384 x 16384
void check_size(const fs::path& path, int width, int height) {
  if (static_cast<long long>(width) * height > kMaxImagePixels) {
    throw ImageFileError(path.string() + ": " + std::to_string(width) + " x " + std::to_string(height) +
                         " pixels, more than lensmith reads (" + std::to_string(kMaxImagePixels) + " pixels)");
  }
}

// The largest flat tile read: 1024 x 1024 pixels of 64 float channels.
constexpr std::uint64_t kMaxExrTileBytes = std::uint64_t{1} << 28;

RasterInfo info_from_header(const fs::path& path, const Imf::Header& header) {
  if (is_deep(header)) {
    throw ImageFileError(path.string() + ": a deep image; lensmith bokeh reads it as layered input (--image), "
                         "elsewhere lensmith reads flat images only (flatten it first, e.g. oiiotool --flatten)");
  }
  const Imath::Box2i data = header.dataWindow();
  RasterInfo info;
  info.format = ImageFormat::Exr;
  info.width = data.max.x - data.min.x + 1;
  info.height = data.max.y - data.min.y + 1;
  // OpenEXR pixel values are linear light (the format's technical introduction, "Scene-Referred Images").
  info.integers_are_linear = true;
  if (info.width < 1 || info.height < 1 || header.channels().begin() == header.channels().end()) {
    throw ImageFileError(path.string() + ": image of " + std::to_string(info.width) + " x " + std::to_string(info.height) +
                         " pixels and no channels: not a 2-D picture");
  }
  info.data_window = {data.min.x, data.min.y, data.max.x, data.max.y};
  const Imath::Box2i display = header.displayWindow();
  info.display_window = {display.min.x, display.min.y, display.max.x, display.max.y};
  if (!info.data_window.contains(info.display_window)) {
    // A crop (or a window beside the frame): the missing part of the frame has no pixels to photograph.
    throw ImageFileError(path.string() + ": data window " + info.data_window.to_string() + " does not cover the display window " +
                         info.display_window.to_string() + ": a cropped image; save it uncropped (overscan, a data window larger "
                         "than the display window, is read)");
  }
  check_size(path, info.width, info.height);
  for (const std::string& name : canonical_order(header.channels())) {
    const Imf::Channel& channel = header.channels()[name];
    if (channel.xSampling != 1 || channel.ySampling != 1) {
      throw ImageFileError(path.string() + ": channel " + name + " is subsampled (" + std::to_string(channel.xSampling) + " x " +
                           std::to_string(channel.ySampling) + "); lensmith reads channels with a sample in every pixel: "
                           "save the image without chroma subsampling");
    }
    info.channels.push_back({name, sample_type(channel.type)});
  }
  if (header.hasTileDescription()) {
    // OpenEXR decodes a whole tile into buffers of its full size, however little of it lies in the
    // data window: a 2.4 kB file of 100 float channels in 2048 x 2048 tiles took 19 s and 3 GB to
    // read (tests/fuzz's exr_image target, ASan build). Real tiles are 32 to 256 pixels wide.
    std::uint64_t pixel_bytes = 0;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) pixel_bytes += it.channel().type == Imf::HALF ? 2 : 4;
    const Imf::TileDescription& tile = header.tileDescription();
    const std::uint64_t tile_bytes = std::uint64_t{tile.xSize} * tile.ySize * pixel_bytes;
    if (tile_bytes > kMaxExrTileBytes) {
      throw ImageFileError(path.string() + ": tiles of " + std::to_string(tile.xSize) + " x " + std::to_string(tile.ySize) + " pixels of " +
                           std::to_string(info.channels.size()) + " channels take " + std::to_string(tile_bytes) +
                           " bytes each; lensmith reads tiles of up to " + std::to_string(kMaxExrTileBytes >> 20) +
                           " MiB (a damaged file, or re-tile it, e.g. oiiotool --tile 64 64)");
    }
  }
  return info;
}

// zip_filter (below) undone: the n filtered bytes (which it overwrites) back to the raw bytes in `out`, as
// OpenEXR's reader does (internal_zip.c: a running sum of the differences less 128, then the two
// byte streams interleaved). The running sum sixteen bytes at a time (a prefix sum within a vector
// in four shifted adds, plus the byte before): OpenEXR 3.1's loop, a byte at a time, was a third of
// its decoding of a ZIP block beside the inflate itself (bench/blender's 600 x 400 pictures).
void zip_unfilter(std::uint8_t* filtered, std::size_t n, std::uint8_t* out) {
  if (n == 0) return;
  std::size_t i = 1;
#if defined(__SSE2__)
  const __m128i bias = _mm_set1_epi8(static_cast<char>(-128));
  __m128i carry = _mm_set1_epi8(static_cast<char>(filtered[0]));  // the byte before, in every lane
  for (; i + 16 <= n; i += 16) {
    __m128i v = _mm_add_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(filtered + i)), bias);
    v = _mm_add_epi8(v, _mm_slli_si128(v, 1));
    v = _mm_add_epi8(v, _mm_slli_si128(v, 2));
    v = _mm_add_epi8(v, _mm_slli_si128(v, 4));
    v = _mm_add_epi8(v, _mm_slli_si128(v, 8));
    v = _mm_add_epi8(v, carry);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(filtered + i), v);
    // The last byte, broadcast: to the top four bytes, then to all.
    const __m128i high = _mm_unpackhi_epi8(v, v);
    carry = _mm_shuffle_epi32(_mm_unpackhi_epi16(high, high), 0xFF);
  }
#endif
  for (; i < n; ++i) filtered[i] = static_cast<std::uint8_t>(filtered[i - 1] + filtered[i] - 128);
  // The two streams, even bytes first: out[2k] = first[k], out[2k + 1] = second[k].
  const std::uint8_t* first = filtered;
  const std::uint8_t* second = filtered + (n + 1) / 2;
  std::size_t k = 0;
  const std::size_t pairs = n / 2;
#if defined(__SSE2__)
  for (; k + 16 <= pairs; k += 16) {
    const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(first + k));
    const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(second + k));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 2 * k), _mm_unpacklo_epi8(a, b));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 2 * k + 16), _mm_unpackhi_epi8(a, b));
  }
#endif
  for (; k < pairs; ++k) {
    out[2 * k] = first[k];
    out[2 * k + 1] = second[k];
  }
  if (n % 2 == 1) out[n - 1] = first[pairs];
}

// OpenEXRCore's decompression of a ZIP or ZIPS block (the pipeline's decompress_fn, which its
// documentation leaves to the caller): packed_buffer's zlib stream inflated (zlib's uncompress,
// which the command line makes libdeflate's: cli/libdeflate_zlib.cpp) and unfiltered into
// unpacked_buffer, which exr_decoding_run has sized to the chunk's unpacked size. A block stored as
// it is (packed as large as unpacked) is copied, as OpenEXRCore copies it; a stream that does not
// inflate to exactly the unpacked size is a corrupt chunk, as OpenEXRCore says.
exr_result_t decompress_zip_block(exr_decode_pipeline_t* decode) {
  const std::size_t packed = decode->chunk.packed_size, unpacked = decode->chunk.unpacked_size;
  if (packed == 0) return EXR_ERR_SUCCESS;
  if (decode->packed_buffer == nullptr || decode->unpacked_buffer == nullptr) return EXR_ERR_CORRUPT_CHUNK;
  if (packed == unpacked) {
    if (decode->unpacked_buffer != decode->packed_buffer) std::memcpy(decode->unpacked_buffer, decode->packed_buffer, unpacked);
    return EXR_ERR_SUCCESS;
  }
  thread_local std::vector<std::uint8_t> filtered;
  if (filtered.size() < unpacked) filtered.resize(unpacked);
  uLongf inflated = static_cast<uLongf>(unpacked);
  if (unpacked > std::numeric_limits<uLong>::max() || packed > std::numeric_limits<uLong>::max() ||
      uncompress(filtered.data(), &inflated, static_cast<const Bytef*>(decode->packed_buffer), static_cast<uLong>(packed)) != Z_OK ||
      inflated != unpacked) {
    return EXR_ERR_CORRUPT_CHUNK;
  }
  zip_unfilter(filtered.data(), unpacked, static_cast<std::uint8_t*>(decode->unpacked_buffer));
  return EXR_ERR_SUCCESS;
}

}  // namespace

RasterInfo read_exr_info(const fs::path& path) {
  const auto file = open_exr(path);
  return info_from_header(path, file->header(0));
}

// The pixels of a flat scanline image with half or float channels at full resolution, through
// OpenEXRCore's chunk API, its chunks decoded on the codec threads: OpenEXR 3.1's C++ reader (which
// Debian 12 ships) spent 18-21 ms on a 600 x 400 RGBZ float file in copying line buffers, on 1 thread
// as on 2; decoded chunk by chunk, 5-11 ms. `slot[c]`: where channel c of the file goes in each
// pixel of `samples` (`stride` floats a pixel, the data window's rows), or -1 to skip it, c in the
// order of info.channels. Returns false, reading nothing, for what it does not take (tiled, several
// parts, subsampled or integer channels): the C++ reader reads those. Throws IoError naming the file
// for a damaged one.
bool read_exr_chunks(const fs::path& path, const Imf::MultiPartInputFile& file, const RasterInfo& info, const std::vector<int>& slot,
                     float* samples, std::size_t stride) {
  const Imf::Header& header = file.header(0);
  if (file.parts() != 1 || header.hasTileDescription()) return false;
  std::vector<std::string> names;  // info.channels' names, in its order
  for (std::size_t c = 0; c < info.channels.size(); ++c) {
    const Imf::Channel* ch = header.channels().findChannel(info.channels[c].name);
    if (ch == nullptr || ch->xSampling != 1 || ch->ySampling != 1) return false;
    if (slot[c] >= 0 && ch->type != Imf::HALF && ch->type != Imf::FLOAT) return false;
    names.push_back(info.channels[c].name);
  }
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  init.error_handler_fn = [](exr_const_context_t, exr_result_t, const char*) {};  // said by the IoError below
  exr_context_t context = nullptr;
  auto failed = [&](exr_result_t code) {
    return IoError(path.string() + ": cannot read the OpenEXR pixels: " + exr_get_default_error_message(code));
  };
  if (const exr_result_t code = exr_start_read(&context, path.c_str(), &init); code != EXR_ERR_SUCCESS) {
    exr_finish(&context);
    throw failed(code);
  }
  const std::unique_ptr<exr_context_t, void (*)(exr_context_t*)> closer(&context, [](exr_context_t* ctx) { exr_finish(ctx); });
  exr_attr_box2i_t window{};
  int32_t lines = 0, chunks = 0;
  if (exr_result_t code = exr_get_data_window(context, 0, &window); code != EXR_ERR_SUCCESS) throw failed(code);
  if (exr_result_t code = exr_get_scanlines_per_chunk(context, 0, &lines); code != EXR_ERR_SUCCESS) throw failed(code);
  if (exr_result_t code = exr_get_chunk_count(context, 0, &chunks); code != EXR_ERR_SUCCESS) throw failed(code);
  // The pixels were sized from the C++ reader's header; OpenEXRCore parses the header again, and
  // where the two read it differently (check_header_attributes refuses the one way known) the chunks
  // would be decoded past the pixels' end.
  const Imath::Box2i sized = header.dataWindow();
  const exr_attr_chlist_t* core_channels = nullptr;
  exr_compression_t compression = EXR_COMPRESSION_NONE;
  if (exr_result_t code = exr_get_channels(context, 0, &core_channels); code != EXR_ERR_SUCCESS) throw failed(code);
  if (exr_result_t code = exr_get_compression(context, 0, &compression); code != EXR_ERR_SUCCESS) throw failed(code);
  int header_channels = 0;
  for (auto it = header.channels().begin(); it != header.channels().end(); ++it) ++header_channels;
  bool same_channels = core_channels->num_channels == header_channels;
  for (int c = 0; same_channels && c < core_channels->num_channels; ++c) {
    const exr_attr_chlist_entry_t& entry = core_channels->entries[c];
    const Imf::Channel* ch = header.channels().findChannel(entry.name.str);
    same_channels = ch != nullptr && static_cast<int>(ch->type) == static_cast<int>(entry.pixel_type) && entry.x_sampling == 1 &&
                    entry.y_sampling == 1;
  }
  if (window.min.x != sized.min.x || window.min.y != sized.min.y || window.max.x != sized.max.x || window.max.y != sized.max.y ||
      static_cast<int>(compression) != static_cast<int>(header.compression()) || !same_channels || lines < 1) {
    throw IoError(path.string() + ": cannot read the OpenEXR pixels: OpenEXR's two readers read the header differently (a damaged file)");
  }
  const std::size_t width = static_cast<std::size_t>(window.max.x) - static_cast<std::size_t>(window.min.x) + 1;
  const std::size_t row_floats = width * stride;
  std::atomic<int> next{0};
  std::atomic<exr_result_t> error{EXR_ERR_SUCCESS};
  auto work = [&] {
    for (int k = next++; k < chunks && error.load() == EXR_ERR_SUCCESS; k = next++) {
      exr_chunk_info_t chunk{};
      exr_decode_pipeline_t decoder = EXR_DECODE_PIPELINE_INITIALIZER;
      exr_result_t code = exr_read_scanline_chunk_info(context, 0, window.min.y + k * lines, &chunk);
      // A chunk is decoded only where it lies in the window the pixels were sized for.
      if (code == EXR_ERR_SUCCESS && (chunk.start_y < window.min.y || chunk.height < 1 || std::int64_t{chunk.start_y} + chunk.height - 1 > window.max.y ||
                                      static_cast<std::size_t>(chunk.width) != width)) {
        code = EXR_ERR_BAD_CHUNK_LEADER;
      }
      if (code == EXR_ERR_SUCCESS) code = exr_decoding_initialize(context, 0, &chunk, &decoder);
      if (code == EXR_ERR_SUCCESS) {
        for (int16_t d = 0; d < decoder.channel_count; ++d) {
          exr_coding_channel_info_t& ch = decoder.channels[d];
          const auto found = std::find(names.begin(), names.end(), ch.channel_name);
          const int at = found == names.end() ? -1 : slot[static_cast<std::size_t>(found - names.begin())];
          if (at < 0) {
            ch.decode_to_ptr = nullptr;  // not asked for: skipped
            continue;
          }
          ch.decode_to_ptr = reinterpret_cast<uint8_t*>(
              samples + static_cast<std::size_t>(chunk.start_y - window.min.y) * row_floats + static_cast<std::size_t>(at));
          ch.user_pixel_stride = static_cast<int32_t>(stride * sizeof(float));
          ch.user_line_stride = static_cast<int32_t>(row_floats * sizeof(float));
          ch.user_data_type = EXR_PIXEL_FLOAT;
          ch.user_bytes_per_element = static_cast<int16_t>(sizeof(float));
        }
        code = exr_decoding_choose_default_routines(context, 0, &decoder);
        if (code == EXR_ERR_SUCCESS && decoder.decompress_fn != nullptr &&
            (compression == EXR_COMPRESSION_ZIP || compression == EXR_COMPRESSION_ZIPS)) {
          decoder.decompress_fn = &decompress_zip_block;
        }
        if (code == EXR_ERR_SUCCESS) code = exr_decoding_run(context, 0, &decoder);
      }
      exr_decoding_destroy(context, &decoder);
      if (code != EXR_ERR_SUCCESS) {
        exr_result_t none = EXR_ERR_SUCCESS;
        error.compare_exchange_strong(none, code);
      }
    }
  };
  // On OpenMP's threads, each taking the next chunk, so that a thread that starts late takes fewer:
  // the first parallel region of a process waits up to a few ms for its threads to start, which a
  // pool of its own paid here and the renderer's first region paid again (docs/performance.md).
  const int threads = std::clamp(codec_thread_count(), 1, std::max(1, chunks));
#pragma omp parallel num_threads(threads)
  work();
  if (error.load() != EXR_ERR_SUCCESS) throw failed(error.load());
  return true;
}

Raster read_exr(const fs::path& path, const RasterInfo& info, std::span<const int> channels) {
  const auto file = open_exr(path);
  const Imf::Header& header = file->header(0);
  if (is_deep(header)) throw ImageFileError(path.string() + ": a deep image; lensmith reads flat images only");
  Raster raster;
  raster.width = info.width;
  raster.height = info.height;
  raster.channels = static_cast<int>(channels.size());
  const std::size_t stride = channels.size();
  raster.samples.assign(static_cast<std::size_t>(info.width) * static_cast<std::size_t>(info.height) * stride, 0.0f);
  // A frame buffer takes each channel once: a channel asked for twice is read once and copied.
  std::vector<int> first_position(info.channels.size(), -1);
  Imf::FrameBuffer frame;
  for (std::size_t i = 0; i < channels.size(); ++i) {
    const auto c = static_cast<std::size_t>(channels[i]);
    if (first_position[c] >= 0) continue;
    first_position[c] = static_cast<int>(i);
    frame.insert(info.channels[c].name,
                 Imf::Slice::Make(Imf::FLOAT, raster.samples.data() + i, header.dataWindow(), stride * sizeof(float),
                                  static_cast<std::size_t>(info.width) * stride * sizeof(float)));
  }
  const bool read = read_exr_chunks(path, *file, info, first_position, raster.samples.data(), stride);
  if (!read) {
    // OpenEXR's own pool only for its C++ reader: started for every file, its idle threads were
    // joined at the process's end, 1-3 ms after the output was written (`lensmith bokeh`).
    size_codec_pool();
    try {
      Imf::InputPart part(*file, 0);
      part.setFrameBuffer(frame);
      part.readPixels(header.dataWindow().min.y, header.dataWindow().max.y);
    } catch (const std::exception& e) {
      throw IoError(path.string() + ": cannot read the OpenEXR pixels: " + e.what());
    }
  }
  const std::size_t pixels = static_cast<std::size_t>(info.width) * static_cast<std::size_t>(info.height);
  for (std::size_t i = 0; i < channels.size(); ++i) {
    const auto c = static_cast<std::size_t>(channels[i]);
    const auto from = static_cast<std::size_t>(first_position[c]);
    // Integer channels are normalised by their full scale, as for the other formats.
    const bool normalise = info.channels[c].type == SampleType::Uint32;
    if (from == i && !normalise) continue;
    for (std::size_t p = 0; p < pixels; ++p) {
      float& v = raster.samples[p * stride + i];
      v = raster.samples[p * stride + from];
      if (normalise && from == i) v = static_cast<float>(static_cast<double>(v) / 4294967295.0);
    }
  }
  return raster;
}

Metadata read_exr_metadata(const fs::path& path) {
  const auto file = open_exr(path);
  const Imf::Header& header = file->header(0);
  Metadata metadata;
  for (auto it = header.begin(); it != header.end(); ++it) {
    const std::string name = it.name();
    if (is_structural(name)) continue;
    const Imf::Attribute& a = it.attribute();
    std::string value;
    if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&a)) {
      value = s->value();
    } else if (const auto* d = dynamic_cast<const Imf::DoubleAttribute*>(&a)) {
      value = format_number(d->value());
    } else if (const auto* f = dynamic_cast<const Imf::FloatAttribute*>(&a)) {
      value = shortest_float_text(f->value());
    } else if (const auto* i = dynamic_cast<const Imf::IntAttribute*>(&a)) {
      value = std::to_string(i->value());
    } else if (const auto* c = dynamic_cast<const Imf::CompressionAttribute*>(&a)) {
      value = compression_name(c->value());
    } else if (const auto* v = dynamic_cast<const Imf::V2fAttribute*>(&a)) {
      value = shortest_float_text(v->value().x) + ", " + shortest_float_text(v->value().y);
    } else if (const auto* w = dynamic_cast<const Imf::V2iAttribute*>(&a)) {
      value = std::to_string(w->value().x) + ", " + std::to_string(w->value().y);
    } else if (const auto* primaries = dynamic_cast<const Imf::ChromaticitiesAttribute*>(&a)) {
      const Imf::Chromaticities& k = primaries->value();
      for (const float x : {k.red.x, k.red.y, k.green.x, k.green.y, k.blue.x, k.blue.y, k.white.x, k.white.y}) {
        value += (value.empty() ? "" : ", ") + shortest_float_text(x);
      }
    } else {
      continue;  // matrices, time codes, ...: no one-line text form
    }
    metadata.emplace_back(common_name(name), value);
  }
  return metadata;
}

namespace {

// The last message of the OpenEXR C library's error handler on this thread (its default handler
// prints to stderr; a lensmith error says what failed instead).
thread_local std::string core_error;

void note_core_error(exr_const_context_t, exr_result_t, const char* message) { core_error = message ? message : ""; }

// A C-library write context, finished (its chunk table written, the file closed) when it goes.
struct CoreWriteContext {
  exr_context_t context = nullptr;
  CoreWriteContext() = default;
  CoreWriteContext(const CoreWriteContext&) = delete;
  CoreWriteContext& operator=(const CoreWriteContext&) = delete;
  ~CoreWriteContext() {
    if (context != nullptr) exr_finish(&context);
  }
};

// OpenEXR's ZIP block filter (ImfZip.cpp, internal_zip.c): the bytes split into the even and the odd
// ones, then each byte replaced by its difference to the one before plus 128. Float samples' high
// bytes then run in long similar stretches that deflate compresses.
void zip_filter(const std::uint8_t* raw, std::size_t n, std::uint8_t* out) {
  std::uint8_t* first = out;
  std::uint8_t* second = out + (n + 1) / 2;
  for (std::size_t i = 0; i + 1 < n; i += 2) {
    *first++ = raw[i];
    *second++ = raw[i + 1];
  }
  if (n % 2 == 1) *first = raw[n - 1];
  int previous = n > 0 ? out[0] : 0;
  for (std::size_t i = 1; i < n; ++i) {
    const int d = int{out[i]} - previous + (128 + 256);
    previous = out[i];
    out[i] = static_cast<std::uint8_t>(d);
  }
}

// The sample by which deflate_pays judges a block of n raw bytes: the start of each half of its
// filtered bytes (zip_filter's two byte streams), `part` bytes of the first and up to `part` of the
// second, filtered from the raw bytes they come from (the first 2 part, and the last even byte, which
// the second stream's first difference is taken against) without filtering the whole block: most
// blocks of a rendered picture are then stored as they are (kZipWorthRatio). The bytes are those
// zip_filter would give.
void zip_filter_sample(const std::uint8_t* raw, std::size_t n, std::size_t part, std::vector<std::uint8_t>& sample) {
  const std::size_t half = (n + 1) / 2, second = std::min(part, n - half);
  sample.resize(part + second);
  const auto difference = [](int value, int previous) { return static_cast<std::uint8_t>(value - previous + (128 + 256)); };
  for (std::size_t j = 0; j < part; ++j) sample[j] = j == 0 ? raw[0] : difference(raw[2 * j], raw[2 * j - 2]);
  const std::size_t last_even = 2 * (half - 1);
  for (std::size_t j = 0; j < second; ++j) {
    sample[part + j] = difference(raw[2 * j + 1], j == 0 ? raw[last_even] : raw[2 * j - 1]);
  }
}

// Whether deflating a block of n raw bytes (filtered by zip_filter) pays (kZipWorthRatio), judged from
// a sample (zip_filter_sample). `sample` and `scratch` are working space.
bool deflate_pays(const std::uint8_t* raw, std::size_t n, std::vector<std::uint8_t>& sample, std::vector<std::uint8_t>& scratch) {
  const std::size_t half = (n + 1) / 2, part = half / kZipSampleParts;
  if (part == 0) return true;  // too small to judge: deflated, kept raw if it does not shrink
  zip_filter_sample(raw, n, part, sample);
  uLongf size = compressBound(static_cast<uLong>(sample.size()));
  scratch.resize(size);
  if (compress2(scratch.data(), &size, sample.data(), static_cast<uLong>(sample.size()), kZipLevel) != Z_OK) return true;
  return static_cast<double>(size) < kZipWorthRatio * static_cast<double>(sample.size());
}

// The bytes of a file OpenEXRCore writes (its write_fn), gathered and written to the file by one
// pwritev at the end: the library writes each block's leader and data apart, and the kernel
// takes one write of the whole file faster than its 50 pieces (a 2.9 MB file on this guest's ext4:
// 0.87-1.09 ms in 50 writes, 0.46-0.60 ms in one, best of 15). `blocks` (the packed blocks, alive
// until the flush) are referred to; anything else the library passes (the header, the leaders, the
// chunk table) is its own buffer and copied.
class GatheredExrFile {
 public:
  explicit GatheredExrFile(const std::vector<std::vector<std::uint8_t>>& blocks) : blocks_(blocks) {}

  static int64_t write(exr_const_context_t /*context*/, void* self, const void* buffer, uint64_t size, uint64_t offset,
                       exr_stream_error_func_ptr_t /*error*/) {
    return static_cast<GatheredExrFile*>(self)->add(static_cast<const std::uint8_t*>(buffer), size, offset);
  }

  // Creates `file` and writes the gathered bytes: in one pwritev (IOV_MAX pieces a call) where they
  // follow one another from offset 0 without a gap or an overlap, else each piece at its offset in
  // the order written. Throws IoError naming `path`.
  void flush(const std::string& file, const fs::path& path) const {
    const auto fail = [&](const std::string& what) {
      throw IoError(path.string() + ": cannot write the OpenEXR image (" + what + "): " + std::strerror(errno));
    };
    // The descriptor, closed on the way out where the end below does not close it.
    struct Descriptor {
      int fd;
      ~Descriptor() {
        if (fd >= 0) ::close(fd);
      }
    } out{::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666)};
    const int fd = out.fd;
    if (fd < 0) fail("creating it");
    std::vector<Piece> order = pieces_;
    std::stable_sort(order.begin(), order.end(), [](const Piece& a, const Piece& b) { return a.offset < b.offset; });
    bool contiguous = true;
    std::uint64_t end = 0;
    for (const Piece& p : order) {
      contiguous = contiguous && p.offset == end;
      end = p.offset + p.size;
    }
    std::size_t first = 0;  // the first piece (of `order`) not yet written whole
    if (contiguous) {
      std::vector<iovec> iov;
      std::uint64_t at = 0;
      while (first < order.size()) {
        iov.clear();
        std::uint64_t bytes = 0;
        for (std::size_t k = first; k < order.size() && iov.size() < static_cast<std::size_t>(IOV_MAX); ++k) {
          iov.push_back({const_cast<std::uint8_t*>(order[k].data), order[k].size});
          bytes += order[k].size;
        }
        const ssize_t done = ::pwritev(fd, iov.data(), static_cast<int>(iov.size()), static_cast<off_t>(at));
        if (done < 0) fail("writing it");
        // Whole pieces written; a piece cut short is written again below, with the rest.
        std::uint64_t left = static_cast<std::uint64_t>(done);
        while (first < order.size() && left >= order[first].size) {
          left -= order[first].size;
          at += order[first].size;
          ++first;
        }
        if (static_cast<std::uint64_t>(done) < bytes) break;
      }
    }
    for (std::size_t k = contiguous ? first : 0; k < order.size(); ++k) {
      const Piece& p = contiguous ? order[k] : pieces_[k];
      for (std::size_t done = 0; done < p.size;) {
        const ssize_t n = ::pwrite(fd, p.data + done, p.size - done, static_cast<off_t>(p.offset + done));
        if (n <= 0) fail("writing it");
        done += static_cast<std::size_t>(n);
      }
    }
    out.fd = -1;
    if (::close(fd) != 0) fail("closing it");
  }

 private:
  struct Piece {
    std::uint64_t offset;
    const std::uint8_t* data;
    std::size_t size;
  };

  int64_t add(const std::uint8_t* bytes, uint64_t size, uint64_t offset) {
    const bool block = std::any_of(blocks_.begin(), blocks_.end(), [&](const std::vector<std::uint8_t>& b) { return b.data() == bytes; });
    if (!block) {
      copies_.emplace_back(bytes, bytes + size);  // (each copy's bytes stay where they are as the list grows)
      bytes = copies_.back().data();
    }
    pieces_.push_back({offset, bytes, static_cast<std::size_t>(size)});
    return static_cast<int64_t>(size);
  }

  const std::vector<std::vector<std::uint8_t>>& blocks_;
  std::vector<std::vector<std::uint8_t>> copies_;
  std::vector<Piece> pieces_;
};

}  // namespace

// Written with OpenEXR's C library (3.1's "core"): the blocks of 16 scanlines are packed, filtered and
// deflated here, all at once on the codec threads (OpenMP: after a render, its threads), then written
// in order. OpenEXR's C++ writer compresses a block at a time on its own pool behind its writer: a
// 600 x 400 RGB float picture took 14-15 ms on 2 threads, of which zlib's (libdeflate's) work is
// about 8 ms a thread (docs/performance.md). The file is the same ZIP-compressed OpenEXR.
void write_exr_file(const fs::path& path, const std::string& file, const PixelsView<float>& pixels,
                    const std::vector<std::string>& channel_names, const std::vector<ImageAttribute>& attributes,
                    const std::optional<std::pair<PixelBox, PixelBox>>& windows) {
  std::set<std::string> seen;
  for (const std::string& name : channel_names) {
    if (name.empty() || !seen.insert(name).second) {
      throw OptionsError(path.string() + ": channel name '" + name + "' is empty or repeated: each channel needs its own name");
    }
  }
  const auto fail = [&](exr_result_t code, const std::string& what) {
    const std::string detail = core_error.empty() ? exr_get_default_error_message(code) : core_error;
    throw IoError(path.string() + ": cannot write the OpenEXR image (" + what + "): " + detail);
  };
  core_error.clear();
  std::vector<std::vector<std::uint8_t>> packed;  // the blocks as stored, made below
  GatheredExrFile gathered(packed);
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  init.error_handler_fn = note_core_error;
  init.zip_level = kZipLevel;
  init.user_data = &gathered;
  init.write_fn = &GatheredExrFile::write;
  CoreWriteContext out;
  if (const exr_result_t rc = exr_start_write(&out.context, file.c_str(), EXR_WRITE_FILE_DIRECTLY, &init); rc != EXR_ERR_SUCCESS) {
    out.context = nullptr;
    fail(rc, "opening it");
  }
  exr_context_t ctx = out.context;
  // Names past 31 bytes need the file's long-names flag (OpenEXR 1.7 on), set only where they occur
  // as OpenEXR's C++ writer does (lensmith:estimated_relative_error is 33).
  constexpr std::size_t kShortName = 31;
  const bool long_names =
      std::any_of(attributes.begin(), attributes.end(), [&](const ImageAttribute& a) { return exr_name(a.name).size() > kShortName; }) ||
      std::any_of(channel_names.begin(), channel_names.end(), [&](const std::string& n) { return n.size() > kShortName; });
  if (long_names) {
    if (const exr_result_t rc = exr_set_longname_support(ctx, 1); rc != EXR_ERR_SUCCESS) fail(rc, "long names");
  }
  int part = 0;
  if (const exr_result_t rc = exr_add_part(ctx, "", EXR_STORAGE_SCANLINE, &part); rc != EXR_ERR_SUCCESS) fail(rc, "its part");
  const auto box = [](const PixelBox& b) {
    exr_attr_box2i_t e{};
    e.min.x = b.min_x;
    e.min.y = b.min_y;
    e.max.x = b.max_x;
    e.max.y = b.max_y;
    return e;
  };
  const PixelBox whole{0, 0, pixels.width - 1, pixels.height - 1};
  const exr_attr_box2i_t data = box(windows ? windows->first : whole), display = box(windows ? windows->second : whole);
  const exr_attr_v2f_t centre{};
  if (const exr_result_t rc =
          exr_initialize_required_attr(ctx, part, &display, &data, 1.0f, &centre, 1.0f, EXR_LINEORDER_INCREASING_Y, EXR_COMPRESSION_ZIP);
      rc != EXR_ERR_SUCCESS) {
    fail(rc, "its windows");
  }
  for (const std::string& name : channel_names) {
    if (const exr_result_t rc = exr_add_channel(ctx, part, name.c_str(), EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
        rc != EXR_ERR_SUCCESS) {
      fail(rc, "channel " + name);
    }
  }
  for (const ImageAttribute& attribute : attributes) {
    const ExrAttribute a = exr_attribute(attribute);
    const char* name = a.name.c_str();
    exr_result_t rc = EXR_ERR_SUCCESS;
    if (const auto* c = std::get_if<std::array<float, 8>>(&a.value)) {
      const exr_attr_chromaticities_t k{(*c)[0], (*c)[1], (*c)[2], (*c)[3], (*c)[4], (*c)[5], (*c)[6], (*c)[7]};
      rc = exr_attr_set_chromaticities(ctx, part, name, &k);
    } else if (const auto* text = std::get_if<std::string>(&a.value)) {
      rc = exr_attr_set_string(ctx, part, name, text->c_str());
    } else {
      const auto* f = std::get_if<float>(&a.value);
      const double number = f ? *f : std::get<double>(a.value);
      if (a.name == "pixelAspectRatio") {
        rc = exr_set_pixel_aspect_ratio(ctx, part, static_cast<float>(number));  // a required attribute: its own setter
      } else {
        rc = f ? exr_attr_set_float(ctx, part, name, *f) : exr_attr_set_double(ctx, part, name, number);
      }
    }
    if (rc != EXR_ERR_SUCCESS) fail(rc, "attribute " + a.name);
  }
  if (const exr_result_t rc = exr_write_header(ctx); rc != EXR_ERR_SUCCESS) fail(rc, "its header");

  // A block's lines, each line its channels in the file's (sorted) order, each channel the row's
  // samples (little-endian floats, as x86 and ARM hold them).
  const exr_attr_chlist_t* list = nullptr;
  if (const exr_result_t rc = exr_get_channels(ctx, part, &list); rc != EXR_ERR_SUCCESS) fail(rc, "its channels");
  std::vector<std::size_t> source(static_cast<std::size_t>(list->num_channels));
  for (std::size_t c = 0; c < source.size(); ++c) {
    const std::string_view name(list->entries[c].name.str, static_cast<std::size_t>(list->entries[c].name.length));
    source[c] = static_cast<std::size_t>(std::find(channel_names.begin(), channel_names.end(), name) - channel_names.begin());
  }
  int32_t lines_per_block = 0;
  if (const exr_result_t rc = exr_get_scanlines_per_chunk(ctx, part, &lines_per_block); rc != EXR_ERR_SUCCESS) fail(rc, "its blocks");
  const auto width = static_cast<std::size_t>(pixels.width), stride = static_cast<std::size_t>(pixels.channels);
  const int blocks = (pixels.height + lines_per_block - 1) / lines_per_block;
  packed.resize(static_cast<std::size_t>(blocks));
  bool deflated = true;
#pragma omp parallel num_threads(std::max(1, codec_thread_count()))
  {
    std::vector<std::uint8_t> filtered, sample, deflated_block;
#pragma omp for schedule(dynamic, 1)
    for (int b = 0; b < blocks; ++b) {
      const int y0 = b * lines_per_block, y1 = std::min(pixels.height, y0 + lines_per_block);
      const std::size_t bytes = static_cast<std::size_t>(y1 - y0) * width * source.size() * sizeof(float);
      // The block as stored raw, packed in place; deflated where that pays.
      std::vector<std::uint8_t>& block = packed[static_cast<std::size_t>(b)];
      block.resize(bytes);
      auto* line = reinterpret_cast<float*>(block.data());
      for (int y = y0; y < y1; ++y) {
        const float* row = pixels.samples.data() + static_cast<std::size_t>(y) * width * stride;
        for (const std::size_t c : source) {
          for (std::size_t x = 0; x < width; ++x) line[x] = row[x * stride + c];
          line += width;
        }
      }
      if (!deflate_pays(block.data(), bytes, sample, deflated_block)) continue;
      filtered.resize(bytes);
      zip_filter(block.data(), bytes, filtered.data());
      uLongf size = compressBound(static_cast<uLong>(bytes));
      deflated_block.resize(size);
      const int rc = compress2(deflated_block.data(), &size, filtered.data(), static_cast<uLong>(bytes), kZipLevel);
      if (rc != Z_OK) {
#pragma omp atomic write
        deflated = false;
      } else if (size < bytes) {
        // (A block that does not shrink stays raw, as OpenEXR keeps it: its readers know it by its size.)
        block.assign(deflated_block.begin(), deflated_block.begin() + static_cast<std::ptrdiff_t>(size));
      }
    }
  }
  if (!deflated) throw IoError(path.string() + ": cannot write the OpenEXR image: zlib failed to compress a block");
  for (int b = 0; b < blocks; ++b) {
    const std::vector<std::uint8_t>& block = packed[static_cast<std::size_t>(b)];
    if (const exr_result_t rc = exr_write_scanline_chunk(ctx, part, data.min.y + b * lines_per_block, block.data(), block.size());
        rc != EXR_ERR_SUCCESS) {
      fail(rc, "block " + std::to_string(b));
    }
  }
  const exr_result_t rc = exr_finish(&out.context);
  out.context = nullptr;
  if (rc != EXR_ERR_SUCCESS) fail(rc, "closing it");
  gathered.flush(file, path);
}

void begin_exr_memo() { ++exr_memo_depth; }

void end_exr_memo() {
  if (--exr_memo_depth == 0) exr_memo.clear();
}

}  // namespace lensmith::codecs

namespace lensmith {

std::optional<std::array<double, 8>> parse_chromaticities(std::string_view text) {
  std::array<double, 8> v{};
  std::size_t count = 0, start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    std::string_view item = text.substr(start, comma - start);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    const std::optional<double> number = parse_finite_number(item);
    if (!number || count == v.size()) return std::nullopt;
    v[count++] = *number;
    start = comma + 1;
  }
  if (count != v.size()) return std::nullopt;
  return v;
}

void set_image_codec_threads(int threads) { codecs::codec_threads.store(std::max(0, threads)); }
int image_codec_threads() { return std::max(1, codecs::codec_thread_count()); }

int DeepRaster::channel_index(std::string_view name) const {
  for (std::size_t i = 0; i < channels.size(); ++i) {
    if (channels[i] == name) return static_cast<int>(i);
  }
  return -1;
}

std::string DeepRaster::to_string() const {
  std::string names;
  for (std::size_t i = 0; i < channels.size(); ++i) names += (i ? ", " : "") + channels[i];
  return "deep " + std::to_string(width) + " x " + std::to_string(height) + ", channels " + names + ", " +
         std::to_string(sample_count()) + " samples";
}

bool is_deep_image(const std::filesystem::path& path) {
  if (detect_image_format(path) != ImageFormat::Exr) return false;
  const auto file = codecs::open_exr(path);
  return codecs::is_deep(file->header(0));
}

namespace {

DeepRaster deep_header(const std::filesystem::path& path, const Imf::Header& header) {
  if (!codecs::is_deep(header)) throw ImageFileError(path.string() + ": not a deep image (its samples are flat)");
  // Deep renders of an element are often cropped to where it has samples (a data window inside the
  // display window): the pixels outside are empty. A data window beyond the display (overscan) would
  // shift the picture against the pinhole frame and is refused as for flat images.
  const Imath::Box2i data = header.dataWindow(), display = header.displayWindow();
  const bool empty = data.max.x < data.min.x || data.max.y < data.min.y;
  if (!empty && (data.min.x < display.min.x || data.min.y < display.min.y || data.max.x > display.max.x || data.max.y > display.max.y)) {
    codecs::check_windows(path, header);  // says which windows differ
  }
  const Imath::Box2i window = display;
  DeepRaster raster;
  raster.width = window.max.x - window.min.x + 1;
  raster.height = window.max.y - window.min.y + 1;
  raster.channels = codecs::canonical_order(header.channels());
  codecs::check_size(path, raster.width, raster.height);
  if (raster.width < 1 || raster.height < 1 || raster.channels.empty()) {
    throw ImageFileError(path.string() + ": deep image of " + std::to_string(raster.width) + " x " + std::to_string(raster.height) +
                         " pixels and no channels: not a 2-D picture");
  }
  for (const std::string& name : raster.channels) {
    const Imf::Channel& channel = header.channels()[name];
    if (channel.xSampling != 1 || channel.ySampling != 1) {
      throw ImageFileError(path.string() + ": channel " + name + " is subsampled; lensmith reads channels with a sample in every pixel");
    }
  }
  return raster;
}

}  // namespace

DeepRaster read_deep_header(const std::filesystem::path& path) {
  const auto file = codecs::open_exr(path);
  return deep_header(path, file->header(0));
}

DeepRaster read_deep_raster(const std::filesystem::path& path, std::uint64_t max_samples) {
  const auto file = codecs::open_exr(path);
  const Imf::Header& header = file->header(0);
  DeepRaster raster = deep_header(path, header);
  codecs::size_codec_pool();
  const Imath::Box2i window = header.displayWindow(), data = header.dataWindow();
  const auto w = static_cast<std::size_t>(raster.width), h = static_cast<std::size_t>(raster.height);
  const std::size_t nc = raster.channels.size();
  // The buffers cover the display window (pixels outside a cropped data window stay empty); OpenEXR
  // addresses them in absolute pixel coordinates, so base pointers are offset back to (0, 0).
  const std::ptrdiff_t origin = static_cast<std::ptrdiff_t>(window.min.y) * static_cast<std::ptrdiff_t>(w) + window.min.x;
  std::vector<unsigned int> counts(w * h, 0);
  std::vector<float*> pointers(w * h * nc, nullptr);
  Imf::DeepFrameBuffer frame;
  frame.insertSampleCountSlice(Imf::Slice(Imf::UINT, reinterpret_cast<char*>(counts.data() - origin), sizeof(unsigned int),
                                          w * sizeof(unsigned int)));
  for (std::size_t c = 0; c < nc; ++c) {
    // Pointer per pixel in pointers[(p * nc) + c]; a sample's channels are adjacent in `samples`.
    frame.insert(raster.channels[c], Imf::DeepSlice(Imf::FLOAT, reinterpret_cast<char*>(pointers.data() + c - origin * static_cast<std::ptrdiff_t>(nc)),
                                                    nc * sizeof(float*), w * nc * sizeof(float*), nc * sizeof(float)));
  }
  auto allocate = [&]() {
    raster.first_sample.assign(w * h + 1, 0);
    for (std::size_t p = 0; p < w * h; ++p) raster.first_sample[p + 1] = raster.first_sample[p] + counts[p];
    if (raster.sample_count() > max_samples) {
      throw ImageFileError(path.string() + ": " + std::to_string(raster.sample_count()) + " deep samples, more than lensmith reads (" +
                           std::to_string(max_samples) + ")");
    }
    raster.samples.assign(raster.sample_count() * nc, 0.0f);
    for (std::size_t p = 0; p < w * h; ++p) {
      for (std::size_t c = 0; c < nc; ++c) {
        pointers[p * nc + c] = counts[p] ? raster.samples.data() + raster.first_sample[p] * nc + c : nullptr;
      }
    }
  };
  try {
    if (data.max.x < data.min.x || data.max.y < data.min.y) {
      allocate();  // an empty data window: no samples anywhere
    } else if (header.type() == Imf::DEEPTILE) {
      Imf::DeepTiledInputPart part(*file, 0);
      part.setFrameBuffer(frame);
      part.readPixelSampleCounts(0, part.numXTiles(0) - 1, 0, part.numYTiles(0) - 1);
      allocate();
      part.readTiles(0, part.numXTiles(0) - 1, 0, part.numYTiles(0) - 1);
    } else {
      Imf::DeepScanLineInputPart part(*file, 0);
      part.setFrameBuffer(frame);
      part.readPixelSampleCounts(data.min.y, data.max.y);
      allocate();
      part.readPixels(data.min.y, data.max.y);
    }
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw IoError(path.string() + ": cannot read the deep OpenEXR pixels: " + e.what());
  }
  return raster;
}

void write_deep_exr(const std::filesystem::path& path, const DeepRaster& raster, const std::vector<ImageAttribute>& attributes) {
  const auto w = static_cast<std::size_t>(raster.width), h = static_cast<std::size_t>(raster.height);
  const std::size_t nc = raster.channels.size();
  if (raster.width < 1 || raster.height < 1 || nc == 0 || raster.first_sample.size() != w * h + 1 || raster.first_sample.front() != 0 ||
      raster.samples.size() != raster.sample_count() * nc) {
    throw OptionsError(path.string() + ": cannot write " + raster.to_string() + ": first_sample needs width x height + 1 entries from 0 "
                       "and samples one value per channel per sample");
  }
  std::set<std::string> seen;
  for (const std::string& name : raster.channels) {
    if (name.empty() || !seen.insert(name).second) {
      throw OptionsError(path.string() + ": channel name '" + name + "' is empty or repeated: each channel needs its own name");
    }
  }
  std::vector<unsigned int> counts(w * h);
  std::vector<const float*> pointers(w * h * nc, nullptr);
  for (std::size_t p = 0; p < w * h; ++p) {
    counts[p] = static_cast<unsigned int>(raster.first_sample[p + 1] - raster.first_sample[p]);
    for (std::size_t c = 0; c < nc; ++c) pointers[p * nc + c] = raster.samples.data() + raster.first_sample[p] * nc + c;
  }
  codecs::size_codec_pool();
  write_atomically(path.string(), path.extension().string(), [&](const std::string& file) {
    try {
      Imf::Header header(raster.width, raster.height);
      header.setType(Imf::DEEPSCANLINE);
      header.compression() = Imf::ZIPS_COMPRESSION;
      header.zipCompressionLevel() = codecs::kZipLevel;
      codecs::insert_attributes(header, attributes);
      Imf::DeepFrameBuffer frame;
      frame.insertSampleCountSlice(Imf::Slice(Imf::UINT, reinterpret_cast<char*>(counts.data()), sizeof(unsigned int),
                                              w * sizeof(unsigned int)));
      for (std::size_t c = 0; c < nc; ++c) {
        header.channels().insert(raster.channels[c], Imf::Channel(Imf::FLOAT));
        frame.insert(raster.channels[c], Imf::DeepSlice(Imf::FLOAT, reinterpret_cast<char*>(pointers.data() + c), nc * sizeof(float*),
                                                        w * nc * sizeof(float*), nc * sizeof(float)));
      }
      Imf::DeepScanLineOutputFile out(file.c_str(), header);
      out.setFrameBuffer(frame);
      out.writePixels(raster.height);
    } catch (const Error&) {
      throw;
    } catch (const std::exception& e) {
      throw IoError(path.string() + ": cannot write the deep OpenEXR image: " + e.what());
    }
  });
}

}  // namespace lensmith

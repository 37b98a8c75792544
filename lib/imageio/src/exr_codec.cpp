// OpenEXR through its C++ API (OpenEXR 3.1): the first part of a file, scanline or tiled, flat;
// deep parts are recognised from the part type and refused here, so a deep reader needs only a
// branch in read_exr that opens Imf::DeepScanLineInputPart / DeepTiledInputPart on the same file.
// Attribute names follow OpenImageIO's mapping (comments <-> ImageDescription, ...).
#include <OpenEXR/ImfChannelList.h>
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

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <memory>
#include <set>
#include <string_view>
#include <thread>

#include "codecs.h"
#include "lensmith/core/number_parsing.h"

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

std::string lower(std::string_view text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

// Rank of a channel's suffix within its layer, as OpenImageIO orders them (colour, then alpha,
// then depth); layers holding X with Y or Z are positions or normals and keep X, Y, Z together.
int suffix_rank(std::string_view suffix, bool xyz_layer) {
  static constexpr std::array<std::string_view, 20> kUsual{"r", "red", "g", "green", "b", "blue", "y", "real", "imag", "a",
                                                           "alpha", "ar", "ra", "ag", "ga", "ab", "ba", "z", "depth", "zback"};
  static constexpr std::array<std::string_view, 21> kXyz{"r", "red", "g", "green", "b", "blue", "x", "y", "z", "real", "imag",
                                                         "a", "alpha", "ar", "ra", "ag", "ga", "ab", "ba", "depth", "zback"};
  const std::string s = lower(suffix);
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
      const std::string s = lower(names[end].suffix);
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

// Threads for OpenEXR's block (de)compression: -1 until set_image_codec_threads, then its count.
std::atomic<int> codec_threads{-1};

// OpenEXR's global pool sized as asked (by default, the machine's hardware threads): zlib is the
// cost of reading and writing float images, and blocks of scanlines compress independently.
void size_codec_pool() {
  int wanted = codec_threads.load();
  if (wanted < 0) wanted = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  if (wanted == 1) wanted = 0;  // the caller alone
  if (Imf::globalThreadCount() != wanted) Imf::setGlobalThreadCount(wanted);
}

std::unique_ptr<Imf::MultiPartInputFile> open_exr(const fs::path& path) {
  try {
    return std::make_unique<Imf::MultiPartInputFile>(path.c_str());
  } catch (const std::exception& e) {
    throw IoError(path.string() + ": cannot read the OpenEXR image: " + e.what());
  }
}

bool is_deep(const Imf::Header& header) { return header.hasType() && Imf::isDeepData(header.type()); }

RasterInfo info_from_header(const fs::path& path, const Imf::Header& header) {
  if (is_deep(header)) throw ImageFileError(path.string() + ": a deep image; lensmith reads flat images only");
  const Imath::Box2i data = header.dataWindow();
  const Imath::Box2i display = header.displayWindow();
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
  // A crop or overscan would shift the picture against the pinhole frame, centred on the pixels read.
  if (data != display) {
    const int full_width = display.max.x - display.min.x + 1;
    const int full_height = display.max.y - display.min.y + 1;
    throw ImageFileError(path.string() + ": data window " + std::to_string(info.width) + " x " + std::to_string(info.height) +
                         " at (" + std::to_string(data.min.x) + ", " + std::to_string(data.min.y) +
                         ") differs from the display window " + std::to_string(full_width) + " x " +
                         std::to_string(full_height) + " at (" + std::to_string(display.min.x) + ", " +
                         std::to_string(display.min.y) + "): render or save the image without a crop or overscan");
  }
  for (const std::string& name : canonical_order(header.channels())) {
    const Imf::Channel& channel = header.channels()[name];
    if (channel.xSampling != 1 || channel.ySampling != 1) {
      throw ImageFileError(path.string() + ": channel " + name + " is subsampled (" + std::to_string(channel.xSampling) + " x " +
                           std::to_string(channel.ySampling) + "); lensmith reads channels with a sample in every pixel: "
                           "save the image without chroma subsampling");
    }
    info.channels.push_back({name, sample_type(channel.type)});
  }
  return info;
}

}  // namespace

RasterInfo read_exr_info(const fs::path& path) {
  const auto file = open_exr(path);
  return info_from_header(path, file->header(0));
}

Raster read_exr(const fs::path& path, const RasterInfo& info, std::span<const int> channels) {
  const auto file = open_exr(path);
  const Imf::Header& header = file->header(0);
  if (is_deep(header)) throw ImageFileError(path.string() + ": a deep image; lensmith reads flat images only");
  size_codec_pool();
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
  try {
    Imf::InputPart part(*file, 0);
    part.setFrameBuffer(frame);
    part.readPixels(header.dataWindow().min.y, header.dataWindow().max.y);
  } catch (const std::exception& e) {
    throw IoError(path.string() + ": cannot read the OpenEXR pixels: " + e.what());
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
    } else {
      continue;  // matrices, chromaticities, time codes, ...: no one-line text form
    }
    metadata.emplace_back(common_name(name), value);
  }
  return metadata;
}

void write_exr_file(const fs::path& path, const std::string& file, const PixelsView<float>& pixels,
                    const std::vector<std::string>& channel_names, const std::vector<ImageAttribute>& attributes) {
  std::set<std::string> seen;
  for (const std::string& name : channel_names) {
    if (name.empty() || !seen.insert(name).second) {
      throw OptionsError(path.string() + ": channel name '" + name + "' is empty or repeated: each channel needs its own name");
    }
  }
  size_codec_pool();
  try {
    Imf::Header header(pixels.width, pixels.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const ImageAttribute& attribute : attributes) {
      if (const auto* text = std::get_if<std::string>(&attribute.value)) {
        header.insert(exr_name(attribute.name), Imf::StringAttribute(*text));
      } else {
        header.insert(exr_name(attribute.name), Imf::DoubleAttribute(std::get<double>(attribute.value)));
      }
    }
    Imf::FrameBuffer frame;
    const auto stride = static_cast<std::size_t>(pixels.channels);
    for (std::size_t c = 0; c < channel_names.size(); ++c) {
      header.channels().insert(channel_names[c], Imf::Channel(Imf::FLOAT));
      frame.insert(channel_names[c], Imf::Slice::Make(Imf::FLOAT, pixels.samples.data() + c, header.dataWindow(),
                                                      stride * sizeof(float),
                                                      static_cast<std::size_t>(pixels.width) * stride * sizeof(float)));
    }
    Imf::OutputFile out(file.c_str(), header);
    out.setFrameBuffer(frame);
    out.writePixels(pixels.height);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw IoError(path.string() + ": cannot write the OpenEXR image: " + e.what());
  }
}

}  // namespace lensmith::codecs

namespace lensmith {

void set_image_codec_threads(int threads) { codecs::codec_threads.store(std::max(0, threads)); }

}  // namespace lensmith

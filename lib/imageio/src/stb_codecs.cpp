// Decoding PNG, Radiance HDR, TGA, BMP and binary PNM with stb_image, and writing JPEG and
// HDR with stb_image_write; the metadata those libraries skip is read and written here: a JPEG's
// COM segment and the Software/ImageDescription tags of its Exif APP1 segment (JPEG File
// Interchange Format 1.02; Exif 2.3, 4.5 and 4.6), and the NAME=value lines of a Radiance header
// (Ward, "The RADIANCE Picture File Format").
// The single definition of stb_image and stb_image_write in lensmith. GIF, PSD and PIC decoding is
// left out, so stb's header test below recognises only the formats lensmith reads; JPEG decoding
// too: libjpeg-turbo reads JPEG (jpeg_codec.cpp says why).
#define STBI_NO_JPEG
#define STBI_NO_GIF
#define STBI_NO_PSD
#define STBI_NO_PIC
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#include <stb_image.h>
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <fstream>
#include <memory>

#include "codecs.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/text_file.h"

namespace lensmith::codecs {

namespace {

constexpr const char* kImageDescription = "ImageDescription";
constexpr const char* kSoftware = "Software";

// The names stb_image's channel counts stand for (gray, gray + alpha, RGB, RGBA).
std::vector<std::string> channel_names(int count) {
  switch (count) {
    case 1: return {"Y"};
    case 2: return {"Y", "A"};
    case 3: return {"R", "G", "B"};
    default: return {"R", "G", "B", "A"};
  }
}

std::string attribute_text(const ImageAttribute& attribute) {
  const auto* text = std::get_if<std::string>(&attribute.value);
  return text != nullptr ? *text : format_number(std::get<double>(attribute.value));
}

std::string text_attribute(const std::vector<ImageAttribute>& attributes, const std::string& name) {
  for (const ImageAttribute& attribute : attributes) {
    if (attribute.name == name) return attribute_text(attribute);
  }
  return "";
}

void append_u16_be(std::string& out, std::size_t value) {
  out += static_cast<char>((value >> 8) & 0xFF);
  out += static_cast<char>(value & 0xFF);
}

void append_u16_le(std::string& out, std::size_t value) {
  out += static_cast<char>(value & 0xFF);
  out += static_cast<char>((value >> 8) & 0xFF);
}

void append_u32_le(std::string& out, std::size_t value) {
  for (int shift = 0; shift < 32; shift += 8) out += static_cast<char>((value >> shift) & 0xFF);
}

// A JPEG segment: marker, 2-byte big-endian length (counting itself), payload of at most 65533 bytes.
std::string jpeg_segment(unsigned char marker, std::string payload) {
  payload.resize(std::min<std::size_t>(payload.size(), 65533));
  std::string segment{'\xFF', static_cast<char>(marker)};
  append_u16_be(segment, payload.size() + 2);
  return segment + payload;
}

// "Exif\0\0" and a little-endian TIFF structure whose IFD0 holds the given ASCII tags (sorted by tag).
std::string exif_payload(const std::vector<std::pair<std::uint16_t, std::string>>& tags) {
  std::string tiff = "II*";
  tiff += '\0';
  append_u32_le(tiff, 8);  // IFD0 follows the 8-byte header
  append_u16_le(tiff, tags.size());
  std::size_t data_offset = 8 + 2 + 12 * tags.size() + 4;
  std::string data;
  for (const auto& [tag, text] : tags) {
    const std::size_t count = text.size() + 1;  // with the terminating NUL
    append_u16_le(tiff, tag);
    append_u16_le(tiff, 2);  // ASCII
    append_u32_le(tiff, count);
    if (count <= 4) {
      std::string inline_value = text;
      inline_value.resize(4, '\0');
      tiff += inline_value;
    } else {
      append_u32_le(tiff, data_offset + data.size());
      data += text;
      data += '\0';
      if (data.size() % 2 != 0) data += '\0';  // offsets are even (TIFF 6.0, section 2)
    }
  }
  append_u32_le(tiff, 0);  // no IFD1
  return std::string("Exif\0\0", 6) + tiff + data;
}

// The ASCII tags of an Exif payload's IFD0 we report, by name.
void read_exif_tags(std::string_view exif, Metadata& metadata) {
  if (exif.size() < 14 || exif.substr(0, 6) != std::string_view("Exif\0\0", 6)) return;
  const std::string_view tiff = exif.substr(6);
  const bool little = tiff.substr(0, 2) == "II";
  if (!little && tiff.substr(0, 2) != "MM") return;
  const auto u16 = [&](std::size_t at) -> std::uint32_t {
    if (at + 2 > tiff.size()) return 0;
    const auto a = static_cast<unsigned char>(tiff[at]), b = static_cast<unsigned char>(tiff[at + 1]);
    return little ? a | (b << 8u) : (a << 8u) | b;
  };
  const auto u32 = [&](std::size_t at) -> std::uint32_t {
    return little ? u16(at) | (u16(at + 2) << 16u) : (u16(at) << 16u) | u16(at + 2);
  };
  const std::size_t ifd = u32(4);
  const std::uint32_t entries = u16(ifd);
  constexpr std::pair<std::uint32_t, const char*> kTags[] = {
      {0x010E, "ImageDescription"}, {0x0131, "Software"}, {0x0132, "DateTime"}, {0x013B, "Artist"}, {0x8298, "Copyright"}};
  for (std::uint32_t i = 0; i < entries; ++i) {
    const std::size_t entry = ifd + 2 + 12 * static_cast<std::size_t>(i);
    if (entry + 12 > tiff.size()) return;
    if (u16(entry + 2) != 2) continue;  // not ASCII
    const std::size_t count = u32(entry + 4);
    const std::size_t at = count <= 4 ? entry + 8 : u32(entry + 8);
    if (at + count > tiff.size()) continue;
    std::string text(tiff.substr(at, count));
    text.erase(std::find(text.begin(), text.end(), '\0'), text.end());
    for (const auto& [tag, name] : kTags) {
      if (tag == u16(entry)) metadata.emplace_back(name, text);
    }
  }
}

void write_bytes(const fs::path& path, const std::string& file, const std::string& bytes, const char* format) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) throw IoError(path.string() + ": cannot create the " + format + " image");
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw IoError(path.string() + ": cannot write the " + format + " image (disk full?)");
}

// stb_image_write hands its output to a callback in pieces; this collects them.
void append_to_string(void* context, void* data, int size) {
  static_cast<std::string*>(context)->append(static_cast<const char*>(data), static_cast<std::size_t>(size));
}

// Radiance header lines hold one NAME=value each: a line break in a value would end it early.
std::string one_line(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  std::replace(text.begin(), text.end(), '\r', ' ');
  return text;
}

// Radiance's own name for the program that wrote a picture.
constexpr const char* kRadianceSoftware = "SOFTWARE";

// stb_image reads a PNM header's numbers into an int without checking for overflow (a "P5" followed
// by ten digits is undefined behaviour, found by the fuzzer): walked here first as stb walks it
// (stbi__pnm_info: magic, then three numbers, each after whitespace and '#' comments to the end of
// the line), a header number of more than nine digits, or a header that does not end within 64 KiB,
// is refused. Other files pass.
bool pnm_header_is_sane(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[2] = {};
  if (!in.read(magic, 2) || magic[0] != 'P' || magic[1] < '1' || magic[1] > '7') return true;
  std::string head(64 * 1024, '\0');
  head[0] = magic[0];
  head[1] = magic[1];
  in.read(head.data() + 2, static_cast<std::streamsize>(head.size() - 2));
  const auto n = 2 + static_cast<std::size_t>(in.gcount());
  const bool whole_file = n < head.size();
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r'; };
  std::size_t i = 2;
  for (int number = 0; number < 3; ++number) {
    while (i < n && (space(head[i]) || head[i] == '#')) {
      if (head[i] == '#') {
        while (i < n && head[i] != '\n' && head[i] != '\r') ++i;
      } else {
        ++i;
      }
    }
    std::size_t digits = 0;
    while (i < n && head[i] >= '0' && head[i] <= '9') {
      ++i;
      ++digits;
    }
    if (digits > 9) return false;
    if (i >= n) return whole_file;  // the header runs past what was read: refused unless the file ends there
  }
  return true;
}

}  // namespace

bool stb_can_decode(const fs::path& path) {
  int width = 0, height = 0, channels = 0;
  return pnm_header_is_sane(path) && stbi_info(path.c_str(), &width, &height, &channels) == 1;
}

RasterInfo read_stb_info(const fs::path& path, ImageFormat format) {
  int width = 0, height = 0, channels = 0;
  if (format == ImageFormat::Pnm && !pnm_header_is_sane(path)) throw ImageFileError(path.string() + ": a PNM header number of more than nine digits: not a picture lensmith reads");
  if (stbi_info(path.c_str(), &width, &height, &channels) != 1) {
    throw IoError(path.string() + ": cannot read the " + to_string(format) + " image: " + stbi_failure_reason());
  }
  RasterInfo info;
  info.format = format;
  info.width = width;
  info.height = height;
  const SampleType type = format == ImageFormat::Hdr             ? SampleType::Float
                          : stbi_is_16_bit(path.c_str()) == 1 ? SampleType::Uint16
                                                              : SampleType::Uint8;
  for (const std::string& name : channel_names(channels)) info.channels.push_back({name, type});
  return info;
}

Decoded read_stb(const fs::path& path, ImageFormat format) {
  Decoded decoded{read_stb_info(path, format), {}};
  int width = 0, height = 0, channels = 0;
  const auto fail = [&]() {
    throw IoError(path.string() + ": cannot read the " + to_string(format) + " image: " + stbi_failure_reason());
  };
  const auto store = [&](auto* data, float full_scale) {
    const std::unique_ptr<void, void (*)(void*)> owned(data, stbi_image_free);
    const std::size_t count = static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * static_cast<std::size_t>(channels);
    decoded.samples.resize(count);
    for (std::size_t i = 0; i < count; ++i) decoded.samples[i] = static_cast<float>(data[i]) / full_scale;
  };
  switch (decoded.info.channels.front().type) {
    case SampleType::Float: {
      float* data = stbi_loadf(path.c_str(), &width, &height, &channels, 0);
      if (data == nullptr) fail();
      store(data, 1.0f);
      break;
    }
    case SampleType::Uint16: {
      stbi_us* data = stbi_load_16(path.c_str(), &width, &height, &channels, 0);
      if (data == nullptr) fail();
      store(data, 65535.0f);
      break;
    }
    default: {
      stbi_uc* data = stbi_load(path.c_str(), &width, &height, &channels, 0);
      if (data == nullptr) fail();
      store(data, 255.0f);
      break;
    }
  }
  decoded.info.width = width;
  decoded.info.height = height;
  return decoded;
}

Metadata read_jpeg_metadata(const fs::path& path) {
  const std::string bytes = read_file_bytes(path.string());
  Metadata metadata;
  std::string comment;
  bool exif_description = false;
  // Segments from after SOI up to the start of the scan (SOS), where the metadata lives.
  for (std::size_t at = 2; at + 4 <= bytes.size() && bytes[at] == '\xFF';) {
    const auto marker = static_cast<unsigned char>(bytes[at + 1]);
    if (marker == 0xDA || marker == 0xD9) break;
    const std::size_t length = (static_cast<std::size_t>(static_cast<unsigned char>(bytes[at + 2])) << 8) |
                               static_cast<unsigned char>(bytes[at + 3]);
    if (length < 2 || at + 2 + length > bytes.size()) break;
    const std::string_view payload(bytes.data() + at + 4, length - 2);
    if (marker == 0xFE && comment.empty()) comment = std::string(payload);
    if (marker == 0xE1) {
      const std::size_t before = metadata.size();
      read_exif_tags(payload, metadata);
      for (std::size_t i = before; i < metadata.size(); ++i) exif_description |= metadata[i].first == kImageDescription;
    }
    at += 2 + length;
  }
  // The comment is the description (as OpenImageIO reads it) unless Exif gives one.
  if (!comment.empty() && !exif_description) metadata.insert(metadata.begin(), {kImageDescription, comment});
  return metadata;
}

Metadata read_hdr_metadata(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path.string() + ": cannot read the Radiance HDR image");
  Metadata metadata;
  std::string line;
  std::getline(in, line);  // "#?RADIANCE"
  // Header lines up to the blank line before the resolution; comments start with '#'.
  while (std::getline(in, line) && !line.empty()) {
    const std::size_t equals = line.find('=');
    if (line[0] == '#' || equals == std::string::npos || line.compare(0, equals, "FORMAT") == 0) continue;
    std::string name = line.substr(0, equals);
    metadata.emplace_back(name == kRadianceSoftware ? kSoftware : name, line.substr(equals + 1));
  }
  return metadata;
}

void write_jpeg_file(const fs::path& path, const std::string& file, const PixelsView<std::uint8_t>& pixels, int quality,
                     const std::vector<ImageAttribute>& attributes) {
  std::string jpeg;
  if (stbi_write_jpg_to_func(append_to_string, &jpeg, pixels.width, pixels.height, pixels.channels, pixels.samples.data(),
                             quality) == 0) {
    throw IoError(path.string() + ": cannot encode the JPEG image");
  }
  // Metadata goes after SOI and the JFIF APP0 segment, which must come first (JFIF 1.02).
  std::size_t insert_at = 2;
  if (jpeg.size() > 6 && static_cast<unsigned char>(jpeg[3]) == 0xE0) {
    insert_at += 2 + ((static_cast<std::size_t>(static_cast<unsigned char>(jpeg[4])) << 8) | static_cast<unsigned char>(jpeg[5]));
  }
  const std::string description = text_attribute(attributes, kImageDescription);
  const std::string software = text_attribute(attributes, kSoftware);
  std::string segments;
  if (!description.empty()) segments += jpeg_segment(0xFE, description);
  std::vector<std::pair<std::uint16_t, std::string>> tags;
  if (!description.empty()) tags.emplace_back(0x010E, description);
  if (!software.empty()) tags.emplace_back(0x0131, software);
  if (!tags.empty()) segments += jpeg_segment(0xE1, exif_payload(tags));
  jpeg.insert(insert_at, segments);
  write_bytes(path, file, jpeg, "JPEG");
}

void write_hdr_file(const fs::path& path, const std::string& file, const PixelsView<float>& rgb,
                    const std::vector<ImageAttribute>& attributes) {
  std::string hdr;
  if (stbi_write_hdr_to_func(append_to_string, &hdr, rgb.width, rgb.height, 3, rgb.samples.data()) == 0) {
    throw IoError(path.string() + ": cannot encode the Radiance HDR image");
  }
  // Attribute lines go after the first ("#?RADIANCE") line; readers pass over variables they do not know.
  std::string lines;
  for (const ImageAttribute& attribute : attributes) {
    const std::string name = attribute.name == kSoftware ? kRadianceSoftware : one_line(attribute.name);
    if (name.empty() || name.find('=') != std::string::npos) {
      throw OptionsError(path.string() + ": attribute name '" + name + "' cannot be a Radiance header variable (empty or with '=')");
    }
    lines += name + "=" + one_line(attribute_text(attribute)) + "\n";
  }
  hdr.insert(hdr.find('\n') + 1, lines);
  write_bytes(path, file, hdr, "Radiance HDR");
}

}  // namespace lensmith::codecs

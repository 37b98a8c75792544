// PFM, the portable float map (Debevec's HDRShop format, as netpbm documents it): a text header
// "PF" (RGB) or "Pf" (gray), width and height, and a scale whose sign gives the byte order
// (negative = little-endian), each followed by white space; then 32-bit IEEE floats, rows from the
// bottom of the picture to the top. Like OpenImageIO and most readers, the scale's magnitude is not
// applied to the samples.
#include <bit>
#include <cstring>
#include <string_view>

#include "codecs.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/text_file.h"

namespace lensmith::codecs {

namespace {

struct PfmHeader {
  RasterInfo info;
  bool little_endian = true;
  std::size_t data_offset = 0;  // first byte of the samples
};

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

PfmHeader parse_header(const fs::path& path, std::string_view bytes) {
  std::size_t at = 0;
  // The next white-space separated token; the one white-space byte after it is consumed too.
  const auto token = [&]() {
    while (at < bytes.size() && is_space(bytes[at])) ++at;
    const std::size_t begin = at;
    while (at < bytes.size() && !is_space(bytes[at])) ++at;
    const std::string_view t = bytes.substr(begin, at - begin);
    if (at < bytes.size()) ++at;
    return t;
  };
  const auto fail = [&](const std::string& what) -> PfmHeader {
    throw IoError(path.string() + ": cannot read the PFM image: " + what);
  };
  PfmHeader header;
  header.info.format = ImageFormat::Pfm;
  const std::string_view magic = token();
  if (magic != "PF" && magic != "Pf") return fail("it starts with '" + std::string(magic) + "', expected PF or Pf");
  const std::string_view width_text = token(), height_text = token(), scale_text = token();
  const auto width = parse_finite_number(width_text), height = parse_finite_number(height_text);
  const auto scale = parse_finite_number(scale_text);
  if (!width || !height || *width < 1 || *height < 1 || *width > (1 << 24) || *height > (1 << 24) || *width != static_cast<int>(*width) ||
      *height != static_cast<int>(*height)) {
    return fail("size '" + std::string(width_text) + " " + std::string(height_text) + "': expected two positive whole numbers");
  }
  if (!scale || *scale == 0.0) {
    return fail("scale '" + std::string(scale_text) + "': expected a non-zero number (negative = little-endian)");
  }
  header.info.width = static_cast<int>(*width);
  header.info.height = static_cast<int>(*height);
  header.little_endian = *scale < 0.0;
  header.data_offset = at;
  const std::vector<std::string> names = magic == "PF" ? std::vector<std::string>{"R", "G", "B"} : std::vector<std::string>{"Y"};
  for (const std::string& name : names) header.info.channels.push_back({name, SampleType::Float});
  const std::size_t needed = static_cast<std::size_t>(header.info.width) * static_cast<std::size_t>(header.info.height) *
                             names.size() * sizeof(float);
  if (bytes.size() - header.data_offset < needed) {
    return fail("it holds " + std::to_string(bytes.size() - header.data_offset) + " bytes of samples, " + std::to_string(needed) +
                " expected for " + header.info.to_string() + " (a truncated file?)");
  }
  return header;
}

}  // namespace

RasterInfo read_pfm_info(const fs::path& path) {
  return parse_header(path, read_file_bytes(path.string())).info;
}

Decoded read_pfm(const fs::path& path) {
  const std::string bytes = read_file_bytes(path.string());
  const PfmHeader header = parse_header(path, bytes);
  Decoded decoded{header.info, {}};
  const auto width = static_cast<std::size_t>(header.info.width);
  const auto height = static_cast<std::size_t>(header.info.height);
  const std::size_t row_samples = width * header.info.channels.size();
  decoded.samples.resize(row_samples * height);
  const bool swap = header.little_endian != (std::endian::native == std::endian::little);
  for (std::size_t file_row = 0; file_row < height; ++file_row) {
    const std::size_t y = height - 1 - file_row;  // the file's first row is the bottom one
    for (std::size_t i = 0; i < row_samples; ++i) {
      std::uint32_t word = 0;
      std::memcpy(&word, bytes.data() + header.data_offset + (file_row * row_samples + i) * 4, 4);
      if (swap) word = (word >> 24) | ((word >> 8) & 0xFF00u) | ((word << 8) & 0xFF0000u) | (word << 24);
      decoded.samples[y * row_samples + i] = std::bit_cast<float>(word);
    }
  }
  return decoded;
}

}  // namespace lensmith::codecs

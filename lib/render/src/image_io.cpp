// Image and depth input/output for the bokeh renderer through OpenImageIO; the sRGB curve of
// IEC 61966-2-1:1999 (5.2 encoding, 5.3 decoding) and the temporary-file-and-rename write of core.
#include "lensmith/render/image_io.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <sstream>
#include <system_error>

#include "lensmith/core/number_parsing.h"
#include "lensmith/core/text_file.h"
#include "lensmith/core/units.h"

namespace lensmith {

namespace {

namespace fs = std::filesystem;

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& item : items) {
    if (!out.empty()) out += ", ";
    out += item;
  }
  return out;
}

std::string pixel_text(int x, int y) { return "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ")"; }

// The first subimage of a picture, opened for reading; IoError with OpenImageIO's message otherwise.
std::unique_ptr<OIIO::ImageInput> open_input(const fs::path& path) {
  auto input = OIIO::ImageInput::open(path.string());
  if (!input) throw IoError(path.string() + ": cannot read the image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = input->spec();
  if (spec.deep) throw ImageFileError(path.string() + ": a deep image; lensmith reads flat images only");
  if (spec.width < 1 || spec.height < 1 || spec.depth != 1 || spec.nchannels < 1) {
    throw ImageFileError(path.string() + ": image of " + std::to_string(spec.width) + " x " + std::to_string(spec.height) +
                         " x " + std::to_string(spec.depth) + " pixels and " + std::to_string(spec.nchannels) +
                         " channels: not a 2-D picture");
  }
  // A crop or overscan would shift the picture against the pinhole frame, centred on the pixels read.
  if (spec.full_width > 0 && spec.full_height > 0 &&
      (spec.x != spec.full_x || spec.y != spec.full_y || spec.width != spec.full_width || spec.height != spec.full_height)) {
    throw ImageFileError(path.string() + ": data window " + std::to_string(spec.width) + " x " + std::to_string(spec.height) +
                         " at (" + std::to_string(spec.x) + ", " + std::to_string(spec.y) + ") differs from the display window " +
                         std::to_string(spec.full_width) + " x " + std::to_string(spec.full_height) + " at (" +
                         std::to_string(spec.full_x) + ", " + std::to_string(spec.full_y) +
                         "): render or save the image without a crop or overscan");
  }
  return input;
}

// Channels [first, first + count) of every pixel as float (integers normalised to [0, 1]).
std::vector<float> read_channels(OIIO::ImageInput& input, const fs::path& path, int first, int count) {
  const OIIO::ImageSpec& spec = input.spec();
  std::vector<float> values(static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height) *
                            static_cast<std::size_t>(count));
  if (!input.read_image(0, 0, first, first + count, OIIO::TypeDesc::FLOAT, values.data())) {
    throw IoError(path.string() + ": cannot read the pixels: " + input.geterror());
  }
  return values;
}

int channel_index(const OIIO::ImageSpec& spec, const std::string& name) {
  for (int c = 0; c < spec.nchannels; ++c) {
    if (spec.channel_name(c) == name) return c;
  }
  return -1;
}

std::vector<std::string> channel_names(const OIIO::ImageSpec& spec) {
  std::vector<std::string> names;
  for (int c = 0; c < spec.nchannels; ++c) names.emplace_back(spec.channel_name(c));
  return names;
}

double smoothstep(double u) { return u * u * (3.0 - 2.0 * u); }

// The highlight factor of RadianceReadOptions for the largest encoded channel of a pixel.
double highlight_factor(double max_encoded, const RadianceReadOptions& options) {
  if (options.highlight_gain == 1.0 || max_encoded < options.highlight_threshold) return 1.0;
  const double span = 1.0 - options.highlight_threshold;
  const double u = span > 0.0 ? std::clamp((max_encoded - options.highlight_threshold) / span, 0.0, 1.0) : 1.0;
  return 1.0 + (options.highlight_gain - 1.0) * smoothstep(u);
}

double metres_from(double value, DepthUnit unit) {
  switch (unit) {
    case DepthUnit::M: return value;
    case DepthUnit::Cm: return m_from_mm(mm_from_cm(value));
    case DepthUnit::Mm: return m_from_mm(value);
  }
  return value;
}

// The output formats by lower-case extension.
enum class OutputFormat { Exr, Hdr, Png, Jpeg, Tiff };
constexpr const char* kSupportedOutputs = ".exr, .hdr, .png, .jpg, .jpeg, .tif, .tiff";

OutputFormat output_format(const fs::path& path) {
  const std::string ext = lower(path.extension().string());
  if (ext == ".exr") return OutputFormat::Exr;
  if (ext == ".hdr") return OutputFormat::Hdr;
  if (ext == ".png") return OutputFormat::Png;
  if (ext == ".jpg" || ext == ".jpeg") return OutputFormat::Jpeg;
  if (ext == ".tif" || ext == ".tiff") return OutputFormat::Tiff;
  throw OptionsError(path.string() + ": unknown image extension '" + path.extension().string() +
                     "': supported are " + kSupportedOutputs);
}

// Opens, writes and closes one image through OpenImageIO; `pixels` holds spec.format values.
void write_with_oiio(const fs::path& path, const std::string& temporary, const OIIO::ImageSpec& spec, const void* pixels) {
  auto output = OIIO::ImageOutput::create(temporary);
  if (!output) throw IoError(path.string() + ": no image writer for this format: " + OIIO::geterror());
  if (!output->open(temporary, spec)) throw IoError(path.string() + ": cannot create the image: " + output->geterror());
  if (!output->write_image(spec.format, pixels)) {
    const std::string message = output->geterror();
    output->close();
    throw IoError(path.string() + ": cannot write the pixels: " + message);
  }
  if (!output->close()) throw IoError(path.string() + ": cannot finish the image: " + output->geterror());
}

// Writes through a temporary file in the same folder whose name ends in the real extension, so
// OpenImageIO picks the format from it (as lensmith::plot's PNG output does).
void write_image_atomically(const fs::path& path, const OIIO::ImageSpec& spec, const void* pixels) {
  write_atomically(path.string(), lower(path.extension().string()),
                   [&](const std::string& temporary) { write_with_oiio(path, temporary, spec, pixels); });
}

void check_no_nan(const fs::path& path, const Image& image) {
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      for (int c = 0; c < image.channels; ++c) {
        if (std::isnan(image.at(x, y, c))) {
          throw ComputationError(path.string() + ": the image to write has NaN at " + pixel_text(x, y) + " channel " +
                                 std::to_string(c) + ": the computation that made it failed");
        }
      }
    }
  }
}

std::string shortest_float(float value) {
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return std::string(buffer.data(), result.ptr);
}

}  // namespace

// ---- sRGB ----------------------------------------------------------------------------------------

float srgb_encode(float linear) {
  const double l = linear;
  const double e = l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
  return static_cast<float>(e);
}

float srgb_decode(float encoded) {
  const double e = encoded;
  const double l = e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4);
  return static_cast<float>(l);
}

// ---- radiance ------------------------------------------------------------------------------------

void RadianceReadOptions::validate() const {
  if (!(highlight_threshold > 0.0 && highlight_threshold <= 1.0)) {
    throw OptionsError("RadianceReadOptions::highlight_threshold = " + format_number(highlight_threshold) +
                       ": must be in (0, 1] (an encoded value)");
  }
  if (!(highlight_gain >= 1.0 && std::isfinite(highlight_gain))) {
    throw OptionsError("RadianceReadOptions::highlight_gain = " + format_number(highlight_gain) +
                       ": must be finite and >= 1 (1 = off)");
  }
}

std::string RadianceReadOptions::to_string() const {
  return "RadianceReadOptions(highlight_threshold " + format_number(highlight_threshold) + ", highlight_gain " +
         format_number(highlight_gain) + ")";
}

Image read_radiance_image(const fs::path& path, const RadianceReadOptions& options) {
  options.validate();
  auto input = open_input(path);
  const OIIO::ImageSpec& spec = input->spec();

  std::array<int, 3> source{0, 0, 0};
  const std::array<int, 3> named{channel_index(spec, "R"), channel_index(spec, "G"), channel_index(spec, "B")};
  if (named[0] >= 0 && named[1] >= 0 && named[2] >= 0) {
    source = named;
  } else if (spec.nchannels >= 3) {
    source = {0, 1, 2};
  }  // else gray (+ alpha): channel 0 three times
  const int last = *std::max_element(source.begin(), source.end());
  const std::vector<float> values = read_channels(*input, path, 0, last + 1);
  const std::size_t stride = static_cast<std::size_t>(last) + 1;

  const bool file_says_linear = lower(spec.get_string_attribute("oiio:ColorSpace")) == "linear";
  std::array<bool, 3> is_float{};
  std::array<bool, 3> decode{};
  for (std::size_t c = 0; c < 3; ++c) {
    is_float[c] = spec.channelformat(source[c]).is_floating_point();
    decode[c] = !is_float[c] && !file_says_linear;
  }
  const bool any_integer = !is_float[0] || !is_float[1] || !is_float[2];

  Image image(spec.width, spec.height, 3);
  for (int y = 0; y < spec.height; ++y) {
    for (int x = 0; x < spec.width; ++x) {
      const std::size_t pixel = static_cast<std::size_t>(y) * static_cast<std::size_t>(spec.width) + static_cast<std::size_t>(x);
      const std::size_t base = pixel * stride;
      double max_encoded = 0.0;
      for (std::size_t c = 0; c < 3; ++c) {
        const float v = values[base + static_cast<std::size_t>(source[c])];
        if (is_float[c]) {
          if (!(std::isfinite(v) && v >= 0.0f)) {
            throw ImageFileError(path.string() + ": " + pixel_text(x, y) + " channel " +
                                 std::string(spec.channel_name(source[c])) + " = " + format_number(v) +
                                 ": a float image is read as linear radiance, which must be finite and >= 0; "
                                 "repair or clamp the file");
          }
          image.at(x, y, static_cast<int>(c)) = v;
        } else {
          max_encoded = std::max(max_encoded, static_cast<double>(v));
          image.at(x, y, static_cast<int>(c)) = decode[c] ? srgb_decode(v) : v;
        }
      }
      if (any_integer) {
        const double factor = highlight_factor(max_encoded, options);
        if (factor != 1.0) {
          for (std::size_t c = 0; c < 3; ++c) {
            if (!is_float[c]) {
              float& v = image.at(x, y, static_cast<int>(c));
              v = static_cast<float>(v * factor);
            }
          }
        }
      }
    }
  }
  return image;
}

// ---- depth ---------------------------------------------------------------------------------------

DepthSource DepthSource::parse(const std::string& spec) {
  if (spec.empty()) throw OptionsError("depth source is empty: expected FILE or FILE:CHANNEL");
  std::error_code ec;
  if (fs::exists(fs::path(spec), ec)) return DepthSource{fs::path(spec), ""};
  const std::size_t colon = spec.rfind(':');
  if (colon == std::string::npos) return DepthSource{fs::path(spec), ""};
  DepthSource source{fs::path(spec.substr(0, colon)), spec.substr(colon + 1)};
  if (source.file.empty()) {
    throw OptionsError("depth source '" + spec + "': the file name before ':' is empty (expected FILE:CHANNEL)");
  }
  if (source.channel.empty()) {
    throw OptionsError("depth source '" + spec + "': the channel name after ':' is empty (expected FILE:CHANNEL)");
  }
  return source;
}

std::string DepthSource::to_string() const { return channel.empty() ? file.string() : file.string() + ":" + channel; }

DepthKind parse_depth_kind(const std::string& text) {
  if (text == "z") return DepthKind::Z;
  if (text == "distance") return DepthKind::Distance;
  if (text == "inverse") return DepthKind::Inverse;
  throw OptionsError("depth kind '" + text + "': expected z, distance or inverse");
}

DepthUnit parse_depth_unit(const std::string& text) {
  if (text == "m") return DepthUnit::M;
  if (text == "cm") return DepthUnit::Cm;
  if (text == "mm") return DepthUnit::Mm;
  throw OptionsError("depth unit '" + text + "': expected m, cm or mm");
}

InvalidDepth parse_invalid_depth(const std::string& text) {
  if (text == "error") return InvalidDepth::Error;
  if (text == "far") return InvalidDepth::Far;
  if (text == "near") return InvalidDepth::Near;
  throw OptionsError("invalid depth handling '" + text + "': expected error, far or near");
}

std::string to_string(DepthKind kind) {
  switch (kind) {
    case DepthKind::Z: return "z";
    case DepthKind::Distance: return "distance";
    case DepthKind::Inverse: return "inverse";
  }
  return "?";
}

std::string to_string(DepthUnit unit) {
  switch (unit) {
    case DepthUnit::M: return "m";
    case DepthUnit::Cm: return "cm";
    case DepthUnit::Mm: return "mm";
  }
  return "?";
}

std::string to_string(InvalidDepth invalid) {
  switch (invalid) {
    case InvalidDepth::Error: return "error";
    case InvalidDepth::Far: return "far";
    case InvalidDepth::Near: return "near";
  }
  return "?";
}

std::string DepthReadOptions::to_string() const {
  return "DepthReadOptions(kind " + lensmith::to_string(kind) + ", unit " + lensmith::to_string(unit) + ", invalid " +
         lensmith::to_string(invalid) + ")";
}

DepthMap read_depth(const DepthSource& source, const DepthReadOptions& options, const PinholeFrame& frame) {
  const fs::path& path = source.file;
  auto input = open_input(path);
  const OIIO::ImageSpec& spec = input->spec();

  int channel = -1;
  if (!source.channel.empty()) {
    channel = channel_index(spec, source.channel);
    if (channel < 0) {
      throw ImageFileError(path.string() + ": no channel '" + source.channel + "'; the file has " + join(channel_names(spec)));
    }
  } else {
    channel = channel_index(spec, "Z");
    if (channel < 0) channel = channel_index(spec, "depth.Z");
    if (channel < 0) channel = 0;
  }
  const std::string where = path.string() + " channel " + std::string(spec.channel_name(channel));
  const OIIO::TypeDesc format = spec.channelformat(channel);
  if (!format.is_floating_point()) {
    throw ImageFileError(where + " is stored as " + std::string(format.c_str()) +
                         " integers, which image readers scale to [0, 1] and which carry no metric depth: "
                         "store depth as float (EXR, float TIFF or PFM)");
  }
  if (spec.width != frame.width_px() || spec.height != frame.height_px()) {
    throw ImageFileError(path.string() + ": depth map of " + std::to_string(spec.width) + " x " + std::to_string(spec.height) +
                         " pixels, but the picture is " + std::to_string(frame.width_px()) + " x " +
                         std::to_string(frame.height_px()) + ": the depth map must have the picture's size");
  }
  const std::vector<float> values = read_channels(*input, path, channel, 1);

  constexpr float kFar = std::numeric_limits<float>::infinity();
  DepthMap depth(spec.width, spec.height, kFar);
  std::vector<bool> invalid(values.size(), false);
  std::size_t invalid_count = 0;
  std::size_t first_invalid = 0;
  float nearest_m = kFar;
  for (int y = 0; y < spec.height; ++y) {
    for (int x = 0; x < spec.width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(spec.width) + static_cast<std::size_t>(x);
      const double v = values[i];
      double z_m = std::numeric_limits<double>::quiet_NaN();
      switch (options.kind) {
        case DepthKind::Z:
          z_m = metres_from(v, options.unit);
          break;
        case DepthKind::Distance: {
          const Tangents t = frame.tangents_at({x + 0.5, y + 0.5});
          z_m = metres_from(v, options.unit) / std::sqrt(1.0 + t.x * t.x + t.y * t.y);
          break;
        }
        case DepthKind::Inverse:
          // 0 is infinitely far; +inf would be a point at the pinhole, as invalid as z = 0.
          if (v == 0.0) {
            z_m = kInfinity;
          } else if (v > 0.0 && std::isfinite(v)) {
            z_m = metres_from(1.0 / v, options.unit);
          }
          break;
      }
      const float z = static_cast<float>(z_m);
      // z = 0 (also a depth too small for a float) is a point at the pinhole, not in front of it.
      if (z > 0.0f) {
        depth.z_m[i] = z;
        nearest_m = std::min(nearest_m, z);
      } else {
        if (invalid_count == 0) first_invalid = i;
        ++invalid_count;
        invalid[i] = true;
      }
    }
  }
  if (invalid_count == 0) return depth;

  const int bad_x = static_cast<int>(first_invalid % static_cast<std::size_t>(spec.width));
  const int bad_y = static_cast<int>(first_invalid / static_cast<std::size_t>(spec.width));
  const std::string bad = where + ": " + pixel_text(bad_x, bad_y) + " = " + format_number(values[first_invalid]) +
                          (invalid_count > 1 ? " (and " + std::to_string(invalid_count - 1) + " more invalid pixels)" : "");
  const std::string expected = options.kind == DepthKind::Inverse
                                   ? "inverse depth must be finite and >= 0 (0 = infinitely far)"
                                   : "depth (" + lensmith::to_string(options.kind) + ") must be > 0 (+inf = infinitely far)";
  if (options.invalid == InvalidDepth::Error) {
    throw ImageFileError(bad + ": " + expected +
                         "; set invalid depth to 'far' to treat such pixels as infinitely far, or to 'near' to give "
                         "them the nearest valid depth");
  }
  float replacement = kFar;
  if (options.invalid == InvalidDepth::Near) {
    if (nearest_m == kFar) {
      throw ImageFileError(bad + ": " + expected + "; invalid depth 'near' needs a finite valid depth, and the map has none");
    }
    replacement = nearest_m;
  }
  for (std::size_t i = 0; i < invalid.size(); ++i) {
    if (invalid[i]) depth.z_m[i] = replacement;
  }
  return depth;
}

// ---- output --------------------------------------------------------------------------------------

std::string OutputMetadata::to_string() const {
  std::vector<std::string> parts;
  if (!lens.empty()) parts.push_back("lens " + lens);
  if (f_number > 0.0) parts.push_back("f/" + format_number(f_number));
  if (focus_m > 0.0) parts.push_back("focus " + format_number(focus_m) + " m");
  if (!model.empty()) parts.push_back("model " + model);
  for (const auto& [key, value] : extra) parts.push_back(key + " " + value);
  return join(parts);
}

void write_output_image(const fs::path& path, const Image& linear_rgb, const OutputMetadata& meta) {
  const OutputFormat format = output_format(path);
  if (linear_rgb.channels != 3 || linear_rgb.width < 1 || linear_rgb.height < 1) {
    throw OptionsError(path.string() + ": cannot write " + linear_rgb.to_string() + ": expected RGB, 3 channels");
  }
  check_no_nan(path, linear_rgb);

  OIIO::TypeDesc pixel_type = OIIO::TypeDesc::FLOAT;
  if (format == OutputFormat::Png || format == OutputFormat::Jpeg) pixel_type = OIIO::TypeDesc::UINT8;
  if (format == OutputFormat::Tiff) pixel_type = OIIO::TypeDesc::UINT16;
  OIIO::ImageSpec spec(linear_rgb.width, linear_rgb.height, 3, pixel_type);
  const std::string software = meta.lensmith_version.empty() ? "lensmith" : "lensmith " + meta.lensmith_version;
  spec.attribute("Software", software);
  spec.attribute("ImageDescription", "lensmith render: " + meta.to_string());
  if (!meta.lens.empty()) spec.attribute("lensmith:lens", meta.lens);
  if (!meta.model.empty()) spec.attribute("lensmith:model", meta.model);
  if (!meta.lensmith_version.empty()) spec.attribute("lensmith:version", meta.lensmith_version);
  if (meta.f_number > 0.0) spec.attribute("lensmith:f_number", OIIO::TypeDesc::DOUBLE, &meta.f_number);
  if (meta.focus_m > 0.0) spec.attribute("lensmith:focus_m", OIIO::TypeDesc::DOUBLE, &meta.focus_m);
  for (const auto& [key, value] : meta.extra) spec.attribute("lensmith:" + key, value);

  switch (format) {
    case OutputFormat::Exr:
      spec.attribute("compression", "zip");
      break;
    case OutputFormat::Jpeg:
      spec.attribute("Compression", "jpeg:95");
      break;
    case OutputFormat::Tiff:
      spec.attribute("compression", "zip");
      break;
    case OutputFormat::Hdr:
    case OutputFormat::Png:
      break;
  }

  if (pixel_type == OIIO::TypeDesc::FLOAT) {
    write_image_atomically(path, spec, linear_rgb.data.data());
    return;
  }
  spec.attribute("oiio:ColorSpace", "sRGB");
  const auto quantise = [&](float linear, double full_scale) {
    // NaN was refused above; +inf clamps to full scale like any highlight.
    const double encoded = std::clamp(static_cast<double>(srgb_encode(linear)), 0.0, 1.0);
    return std::lround(encoded * full_scale);
  };
  if (pixel_type == OIIO::TypeDesc::UINT8) {
    std::vector<std::uint8_t> pixels(linear_rgb.data.size());
    for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<std::uint8_t>(quantise(linear_rgb.data[i], 255.0));
    write_image_atomically(path, spec, pixels.data());
  } else {
    std::vector<std::uint16_t> pixels(linear_rgb.data.size());
    for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<std::uint16_t>(quantise(linear_rgb.data[i], 65535.0));
    write_image_atomically(path, spec, pixels.data());
  }
}

void write_float_exr(const fs::path& path, const Image& image, const std::vector<std::string>& channel_names) {
  if (lower(path.extension().string()) != ".exr") {
    throw OptionsError(path.string() + ": write_float_exr writes OpenEXR files only (extension .exr)");
  }
  if (image.channels < 1 || static_cast<std::size_t>(image.channels) != channel_names.size()) {
    throw OptionsError(path.string() + ": " + std::to_string(channel_names.size()) + " channel names for " + image.to_string());
  }
  OIIO::ImageSpec spec(image.width, image.height, image.channels, OIIO::TypeDesc::FLOAT);
  spec.channelnames = channel_names;
  spec.alpha_channel = -1;
  spec.z_channel = -1;
  spec.attribute("compression", "zip");
  spec.attribute("Software", "lensmith");
  write_image_atomically(path, spec, image.data.data());
}

std::vector<std::pair<std::string, std::string>> read_image_metadata(const fs::path& path) {
  auto input = OIIO::ImageInput::open(path.string());
  if (!input) throw IoError(path.string() + ": cannot read the image: " + OIIO::geterror());
  std::vector<std::pair<std::string, std::string>> metadata;
  for (const OIIO::ParamValue& p : input->spec().extra_attribs) {
    std::string value;
    if (p.type() == OIIO::TypeString) {
      value = p.get_string();
    } else if (p.type() == OIIO::TypeDesc::DOUBLE) {
      value = format_number(p.get<double>());
    } else if (p.type() == OIIO::TypeFloat) {
      value = shortest_float(p.get<float>());
    } else {
      value = OIIO::ImageSpec::metadata_val(p);
    }
    metadata.emplace_back(p.name().string(), value);
  }
  return metadata;
}

void ensure_not_an_input(const fs::path& output, const std::vector<fs::path>& inputs) {
  for (const fs::path& input : inputs) {
    std::error_code ec;
    bool same = false;
    if (fs::exists(output, ec) && fs::exists(input, ec)) {
      same = fs::equivalent(output, input, ec) && !ec;
    } else {
      std::error_code ec_output, ec_input;
      const fs::path a = fs::weakly_canonical(fs::absolute(output), ec_output);
      const fs::path b = fs::weakly_canonical(fs::absolute(input), ec_input);
      same = !ec_output && !ec_input && a == b;
    }
    if (same) {
      throw OptionsError("output " + output.string() + " is the input " + input.string() +
                         ": writing it would destroy the input; choose another output file");
    }
  }
}

}  // namespace lensmith

// Image and depth input/output for the bokeh renderer on top of lensmith::imageio's file codecs; the
// sRGB curve of IEC 61966-2-1:1999 (5.2 encoding, 5.3 decoding).
#include "lensmith/core/ascii_text.h"
#include "lensmith/render/image_io.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <limits>
#include <system_error>

#include "lensmith/core/first_index.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/units.h"
#include "lensmith/imageio/image_file.h"

namespace lensmith {

namespace {

namespace fs = std::filesystem;

// The channels that hold the picture: R, G, B (and A) by those names, else of the first layer that
// has all three, such as a Blender multilayer EXR's "ViewLayer.Combined.R" (OpenImageIO lists
// layers in the file's order); -1 where absent.
struct PictureChannels {
  int r = -1, g = -1, b = -1, a = -1;
  bool found() const { return r >= 0 && g >= 0 && b >= 0; }
};
PictureChannels picture_channels(const RasterInfo& info) {
  PictureChannels p{info.channel_index("R"), info.channel_index("G"), info.channel_index("B"), info.channel_index("A")};
  if (p.found()) return p;
  for (const RasterChannel& c : info.channels) {
    const std::string& name = c.name;
    if (name.size() < 3 || name.compare(name.size() - 2, 2, ".R") != 0) continue;
    const std::string layer = name.substr(0, name.size() - 1);  // "ViewLayer.Combined."
    const PictureChannels q{info.channel_index(name), info.channel_index(layer + "G"), info.channel_index(layer + "B"),
                            info.channel_index(layer + "A")};
    if (q.found()) return q;
  }
  return p;
}

// The depth channel of a file named without a channel: Z, depth.Z, or the Z of a layer named
// depth in any case (Blender's "ViewLayer.Depth.Z"); -1 when there is none.
int depth_channel(const RasterInfo& info) {
  for (const char* name : {"Z", "depth.Z"}) {
    if (const int c = info.channel_index(name); c >= 0) return c;
  }
  for (std::size_t c = 0; c < info.channels.size(); ++c) {
    const std::string name = to_lower_ascii(info.channels[c].name);
    if (name.size() > 8 && name.compare(name.size() - 8, 8, ".depth.z") == 0) return static_cast<int>(c);
  }
  return -1;
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
// Quality of JPEG output (libjpeg's 1-100 scale): high enough that a flat colour moves by a code value or two.
constexpr int kJpegQuality = 95;

OutputFormat output_format(const fs::path& path) {
  const std::string ext = to_lower_ascii(path.extension().string());
  if (ext == ".exr") return OutputFormat::Exr;
  if (ext == ".hdr") return OutputFormat::Hdr;
  if (ext == ".png") return OutputFormat::Png;
  if (ext == ".jpg" || ext == ".jpeg") return OutputFormat::Jpeg;
  if (ext == ".tif" || ext == ".tiff") return OutputFormat::Tiff;
  throw OptionsError(path.string() + ": unknown image extension '" + path.extension().string() +
                     "': supported are " + kSupportedOutputs);
}

void check_no_nan(const fs::path& path, const Image& image) {
  const std::size_t k = first_index_where(image.data.size(), image_codec_threads(), [&](std::size_t i) { return std::isnan(image.data[i]); });
  if (k == image.data.size()) return;
  const auto channels = static_cast<std::size_t>(image.channels), pixel = k / channels;
  throw ComputationError(path.string() + ": the image to write has NaN at " +
                         pixel_text(static_cast<int>(pixel % static_cast<std::size_t>(image.width)), static_cast<int>(pixel / static_cast<std::size_t>(image.width))) +
                         " channel " + std::to_string(k % channels) + ": the computation that made it failed");
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

std::optional<std::vector<float>> read_alpha(const fs::path& path) {
  const RasterInfo info = read_raster_info(path);
  const int index = picture_channels(info).a;
  if (index < 0) return std::nullopt;
  const int channels[1] = {index};
  Raster alpha = read_raster(path, info, channels);
  for (std::size_t i = 0; i < alpha.samples.size(); ++i) {
    float& a = alpha.samples[i];
    if (!(a >= 0.0f && a <= 1.0f + 1e-3f)) {
      throw ImageFileError(path.string() + ": alpha at pixel (" + std::to_string(i % static_cast<std::size_t>(alpha.width)) + ", " +
                           std::to_string(i / static_cast<std::size_t>(alpha.width)) + ") is " + format_number(a) +
                           ": expected 0 to 1");
    }
    a = std::min(a, 1.0f);
  }
  return std::move(alpha.samples);
}

OtherChannels read_other_channels(const fs::path& path) {
  const RasterInfo info = read_raster_info(path);
  OtherChannels out;
  if (info.format != ImageFormat::Exr) return out;
  const PictureChannels picture = picture_channels(info);
  const int depth = depth_channel(info);
  std::vector<int> indices;
  for (std::size_t c = 0; c < info.channels.size(); ++c) {
    const int i = static_cast<int>(c);
    if (i == picture.r || i == picture.g || i == picture.b || i == picture.a || i == depth) continue;
    out.names.push_back(info.channels[c].name);
    indices.push_back(i);
  }
  if (indices.empty()) return out;
  out.samples = read_raster(path, info, indices).samples;
  return out;
}

Image read_radiance_image(const fs::path& path, const RadianceReadOptions& options) {
  options.validate();
  const RasterInfo info = read_raster_info(path);

  std::array<int, 3> source{0, 0, 0};
  const PictureChannels picture = picture_channels(info);
  if (picture.found()) {
    source = {picture.r, picture.g, picture.b};
  } else if (info.channels.size() >= 3) {
    source = {0, 1, 2};
  }  // else gray (+ alpha): channel 0 three times
  Raster values = read_raster(path, info, source);

  std::array<bool, 3> is_float{};
  std::array<bool, 3> decode{};
  for (std::size_t c = 0; c < 3; ++c) {
    is_float[c] = is_floating_point(info.channels[static_cast<std::size_t>(source[c])].type);
    decode[c] = !is_float[c] && !info.integers_are_linear;
  }
  const bool any_integer = !is_float[0] || !is_float[1] || !is_float[2];
  auto not_radiance = [&](int x, int y, std::size_t c, float v) {
    return ImageFileError(path.string() + ": " + pixel_text(x, y) + " channel " + info.channels[static_cast<std::size_t>(source[c])].name +
                          " = " + format_number(v) +
                          ": a float image is read as linear radiance, which must be finite and >= 0; repair or clamp the file");
  };
  if (!any_integer && values.channels == 3 && values.width == info.width && values.height == info.height) {
    // Float channels are the picture as read: checked, then taken over (a copy of the frame, and
    // its fresh memory, cost the street scene's process about 2 ms).
    const std::size_t count = values.samples.size();
    const std::size_t k = first_index_where(count, image_codec_threads(), [&](std::size_t i) {
      const float v = values.samples[i];
      return !(std::isfinite(v) && v >= 0.0f);
    });
    if (k < count) {
      const std::size_t pixel = k / 3;
      throw not_radiance(static_cast<int>(pixel % static_cast<std::size_t>(info.width)),
                         static_cast<int>(pixel / static_cast<std::size_t>(info.width)), k % 3, values.samples[k]);
    }
    Image image;
    image.width = info.width;
    image.height = info.height;
    image.channels = 3;
    image.data = std::move(values.samples);
    return image;
  }

  Image image(info.width, info.height, 3);
  for (int y = 0; y < info.height; ++y) {
    for (int x = 0; x < info.width; ++x) {
      double max_encoded = 0.0;
      for (std::size_t c = 0; c < 3; ++c) {
        const float v = values.at(x, y, static_cast<int>(c));
        if (is_float[c]) {
          if (!(std::isfinite(v) && v >= 0.0f)) throw not_radiance(x, y, c, v);
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

double planar_depth_m(double v, const DepthReadOptions& options, const PinholeFrame& frame, int x, int y) {
  switch (options.kind) {
    case DepthKind::Z: return metres_from(v, options.unit);
    case DepthKind::Distance: {
      const Tangents t = frame.tangents_at({x + 0.5, y + 0.5});
      return metres_from(v, options.unit) / std::sqrt(1.0 + t.x * t.x + t.y * t.y);
    }
    case DepthKind::Inverse:
      // 0 is infinitely far; +inf would be a point at the pinhole, as invalid as z = 0.
      if (v == 0.0) return kInfinity;
      if (v > 0.0 && std::isfinite(v)) return metres_from(1.0 / v, options.unit);
      break;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

DepthMap depth_map_from_values(std::span<const float> values, const DepthReadOptions& options, const PinholeFrame& frame,
                               const std::string& where) {
  if (values.size() != static_cast<std::size_t>(frame.width_px()) * static_cast<std::size_t>(frame.height_px())) {
    throw ImageFileError(where + ": " + std::to_string(values.size()) + " depth values for a picture of " + std::to_string(frame.width_px()) +
                         " x " + std::to_string(frame.height_px()) + " pixels: the depth map must have the picture's size");
  }
  constexpr float kFar = std::numeric_limits<float>::infinity();
  // Each pixel's planar depth, on the codec threads (a row each); an invalid one is left NaN until
  // the rule for it is known. z = 0 (also a depth too small for a float) is a point at the pinhole,
  // not in front of it.
  DepthMap depth(frame.width_px(), frame.height_px(), kFar);
  std::size_t invalid_count = 0;
  std::size_t first_invalid = values.size();
  float nearest_m = kFar;
#pragma omp parallel for num_threads(image_codec_threads()) schedule(static) reduction(+ : invalid_count) reduction(min : first_invalid, nearest_m)
  for (int y = 0; y < depth.height; ++y) {
    for (int x = 0; x < depth.width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(depth.width) + static_cast<std::size_t>(x);
      const float z = static_cast<float>(planar_depth_m(values[i], options, frame, x, y));
      if (z > 0.0f) {
        depth.z_m[i] = z;
        nearest_m = std::min(nearest_m, z);
      } else {
        depth.z_m[i] = std::numeric_limits<float>::quiet_NaN();
        first_invalid = std::min(first_invalid, i);
        ++invalid_count;
      }
    }
  }
  if (invalid_count == 0) return depth;

  const int bad_x = static_cast<int>(first_invalid % static_cast<std::size_t>(depth.width));
  const int bad_y = static_cast<int>(first_invalid / static_cast<std::size_t>(depth.width));
  const std::string bad = where + ": " + pixel_text(bad_x, bad_y) + " = " + format_number(values[first_invalid]) +
                          (invalid_count > 1 ? " (and " + std::to_string(invalid_count - 1) + " more invalid pixels)" : "");
  const std::string expected = options.kind == DepthKind::Inverse
                                   ? "inverse depth must be finite and >= 0 (0 = infinitely far)"
                                   : "depth (" + lensmith::to_string(options.kind) + ") must be > 0 (+inf = infinitely far)";
  if (options.invalid == InvalidDepth::Error) {
    throw ImageFileError(bad + ": " + expected +
                         "; --invalid-depth far treats such pixels as infinitely far, --invalid-depth near gives them "
                         "the nearest valid depth");
  }
  float replacement = kFar;
  if (options.invalid == InvalidDepth::Near) {
    if (nearest_m == kFar) {
      throw ImageFileError(bad + ": " + expected + "; --invalid-depth near needs a finite valid depth, and the map has none: use --invalid-depth far");
    }
    replacement = nearest_m;
  }
  for (float& z : depth.z_m) {
    if (std::isnan(z)) z = replacement;
  }
  return depth;
}

DepthMap read_depth(const DepthSource& source, const DepthReadOptions& options, const PinholeFrame& frame) {
  const fs::path& path = source.file;
  const RasterInfo info = read_raster_info(path);

  int channel = -1;
  bool grey_check = false;
  if (!source.channel.empty()) {
    channel = info.channel_index(source.channel);
    if (channel < 0) {
      throw ImageFileError(path.string() + ": no channel '" + source.channel + "'; the file has " + join(info.channel_names()));
    }
  } else {
    channel = depth_channel(info);
    // A one-channel file is its depth, and so is a grey picture of it in another format (R = G = B,
    // checked below); in a colour picture channel 0 would be its red, and an EXR names its depth.
    if (channel < 0 && (info.channels.size() == 1 || info.format != ImageFormat::Exr)) {
      channel = 0;
      grey_check = info.channels.size() >= 3;
    }
    if (channel < 0) {
      throw ImageFileError(path.string() + ": no depth channel (Z, depth.Z or a layer's Depth.Z); name one as FILE:CHANNEL; the file has " +
                           join(info.channel_names()));
    }
  }
  const RasterChannel& stored = info.channels[static_cast<std::size_t>(channel)];
  const std::string where = path.string() + " channel " + stored.name;
  if (!is_floating_point(stored.type)) {
    throw ImageFileError(where + " is stored as " + to_string(stored.type) +
                         " integers, which image readers scale to [0, 1] and which carry no metric depth: "
                         "store depth as float (EXR, float TIFF or PFM)");
  }
  if (info.width != frame.width_px() || info.height != frame.height_px()) {
    throw ImageFileError(path.string() + ": depth map of " + std::to_string(info.width) + " x " + std::to_string(info.height) +
                         " pixels, but the picture is " + std::to_string(frame.width_px()) + " x " +
                         std::to_string(frame.height_px()) + ": the depth map must have the picture's size");
  }
  const int channels[1] = {channel};
  const std::vector<float> values = read_raster(path, info, channels).samples;
  if (grey_check) {
    const int rgb[3] = {0, 1, 2};
    const Raster all = read_raster(path, info, rgb);
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (all.samples[3 * i] != all.samples[3 * i + 1] || all.samples[3 * i] != all.samples[3 * i + 2]) {
        throw ImageFileError(path.string() + ": no depth channel, and its channels " + join(info.channel_names()) + " differ at pixel (" +
                             std::to_string(i % static_cast<std::size_t>(info.width)) + ", " + std::to_string(i / static_cast<std::size_t>(info.width)) +
                             "): a colour picture, not a depth map; give the depth as its own file or channel");
      }
    }
  }

  return depth_map_from_values(values, options, frame, where);
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

bool output_keeps_alpha(const fs::path& path) { return output_format(path) == OutputFormat::Exr; }

std::vector<ImageAttribute> output_attributes(const OutputMetadata& meta) {
  std::vector<ImageAttribute> attributes{
      {"Software", meta.lensmith_version.empty() ? "lensmith" : "lensmith " + meta.lensmith_version},
      {"ImageDescription", "lensmith render: " + meta.to_string()}};
  if (!meta.lens.empty()) attributes.push_back({"lensmith:lens", meta.lens});
  if (!meta.model.empty()) attributes.push_back({"lensmith:model", meta.model});
  if (!meta.lensmith_version.empty()) attributes.push_back({"lensmith:version", meta.lensmith_version});
  if (meta.f_number > 0.0) attributes.push_back({"lensmith:f_number", meta.f_number});
  if (meta.focus_m > 0.0) attributes.push_back({"lensmith:focus_m", meta.focus_m});
  for (const auto& [key, value] : meta.extra) attributes.push_back({"lensmith:" + key, value});
  for (const auto& [name, value] : meta.camera) attributes.push_back({name, value, true});
  if (!meta.chromaticities.empty()) attributes.push_back({"chromaticities", meta.chromaticities});
  return attributes;
}

void write_output_image(const fs::path& path, const Image& linear_rgb, const OutputMetadata& meta,
                        const std::vector<std::string>& channel_names) {
  const OutputFormat format = output_format(path);
  std::vector<std::string> names = channel_names;
  if (names.empty()) names = linear_rgb.channels == 4 ? std::vector<std::string>{"R", "G", "B", "A"} : std::vector<std::string>{"R", "G", "B"};
  const bool named_ok = static_cast<int>(names.size()) == linear_rgb.channels && names.size() >= 3 && names[0] == "R" &&
                        names[1] == "G" && names[2] == "B";
  const bool rgba_exr = linear_rgb.channels > 3 && format == OutputFormat::Exr;
  if (!named_ok || (linear_rgb.channels != 3 && !rgba_exr) || linear_rgb.width < 1 || linear_rgb.height < 1) {
    throw OptionsError(path.string() + ": cannot write " + linear_rgb.to_string() +
                       ": expected RGB, 3 channels (more, named R, G, B first, to OpenEXR only)");
  }
  check_no_nan(path, linear_rgb);

  std::vector<ImageAttribute> attributes = output_attributes(meta);
  const bool overscan = meta.data_window.width() > 0 && !(meta.data_window == meta.display_window);
  if (overscan && (meta.data_window.width() != linear_rgb.width || meta.data_window.height() != linear_rgb.height ||
                   !meta.data_window.contains(meta.display_window))) {
    throw OptionsError(path.string() + ": data window " + meta.data_window.to_string() + " and display window " +
                       meta.display_window.to_string() + " for an image of " + std::to_string(linear_rgb.width) + " x " +
                       std::to_string(linear_rgb.height));
  }
  if (overscan && format == OutputFormat::Exr) {
    write_exr(path, PixelsView<float>{linear_rgb.width, linear_rgb.height, linear_rgb.channels, linear_rgb.data}, names, attributes,
              std::pair{meta.data_window, meta.display_window});
    return;
  }
  if (overscan) {
    // A format without windows: the frame only.
    const PixelBox& d = meta.display_window;
    Image frame(d.width(), d.height(), linear_rgb.channels);
    const auto c = static_cast<std::size_t>(linear_rgb.channels);
    for (int y = 0; y < d.height(); ++y) {
      const std::size_t from = (static_cast<std::size_t>(y + d.min_y - meta.data_window.min_y) * static_cast<std::size_t>(linear_rgb.width) +
                                static_cast<std::size_t>(d.min_x - meta.data_window.min_x)) * c;
      std::copy_n(linear_rgb.data.begin() + static_cast<std::ptrdiff_t>(from), static_cast<std::size_t>(d.width()) * c,
                  frame.data.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(y) * static_cast<std::size_t>(d.width()) * c));
    }
    OutputMetadata framed = meta;
    framed.data_window = framed.display_window = PixelBox{};
    write_output_image(path, frame, framed, channel_names);
    return;
  }

  if (rgba_exr) {
    write_exr(path, PixelsView<float>{linear_rgb.width, linear_rgb.height, linear_rgb.channels, linear_rgb.data}, names, attributes);
    return;
  }
  const PixelsView<float> linear{linear_rgb.width, linear_rgb.height, 3, linear_rgb.data};
  if (format == OutputFormat::Exr) {
    write_exr(path, linear, {"R", "G", "B"}, attributes);
    return;
  }
  if (format == OutputFormat::Hdr) {
    write_hdr(path, linear, attributes);
    return;
  }
  const auto quantise = [&](float value, double full_scale) {
    // NaN was refused above; +inf clamps to full scale like any highlight.
    const double encoded = std::clamp(static_cast<double>(srgb_encode(value)), 0.0, 1.0);
    return std::lround(encoded * full_scale);
  };
  if (format == OutputFormat::Tiff) {
    std::vector<std::uint16_t> codes(linear_rgb.data.size());
    for (std::size_t i = 0; i < codes.size(); ++i) codes[i] = static_cast<std::uint16_t>(quantise(linear_rgb.data[i], 65535.0));
    write_tiff(path, PixelsView<std::uint16_t>{linear_rgb.width, linear_rgb.height, 3, codes}, attributes);
    return;
  }
  std::vector<std::uint8_t> codes(linear_rgb.data.size());
  for (std::size_t i = 0; i < codes.size(); ++i) codes[i] = static_cast<std::uint8_t>(quantise(linear_rgb.data[i], 255.0));
  const PixelsView<std::uint8_t> encoded{linear_rgb.width, linear_rgb.height, 3, codes};
  if (format == OutputFormat::Png) {
    write_png(path, encoded, attributes);
  } else {
    write_jpeg(path, encoded, kJpegQuality, attributes);
  }
}

void write_float_exr(const fs::path& path, const Image& image, const std::vector<std::string>& channel_names) {
  if (to_lower_ascii(path.extension().string()) != ".exr") {
    throw OptionsError(path.string() + ": write_float_exr writes OpenEXR files only (extension .exr)");
  }
  if (image.channels < 1 || static_cast<std::size_t>(image.channels) != channel_names.size()) {
    throw OptionsError(path.string() + ": " + std::to_string(channel_names.size()) + " channel names for " + image.to_string());
  }
  write_exr(path, PixelsView<float>{image.width, image.height, image.channels, image.data}, channel_names,
            {{"Software", "lensmith"}});
}

std::vector<std::pair<std::string, std::string>> read_image_metadata(const fs::path& path) {
  return read_image_metadata_pairs(path);
}

}  // namespace lensmith

// `lensmith bokeh`: an all-in-focus image and its depth, photographed through a lens
// (docs/bokeh.md). Reads the inputs, builds the camera and the ray model, renders, writes.
#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>

#include "commands.h"
#include "openmp_team.h"
#include "progress_bar.h"
#include "lensmith/camera/camera_spec.h"
#include "lensmith/color/color_management.h"
#include "lensmith/color/rgb_primaries.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/stage_times.h"
#include "lensmith/core/units.h"
#include "lensmith/imageio/deep_raster.h"
#include "lensmith/imageio/frame_sequence.h"
#include "lensmith/imageio/image_file.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "lensmith/render/bokeh_renderer.h"
#include "lensmith/render/camera_metadata.h"
#include "lensmith/render/deep_image.h"
#include "lensmith/render/image_io.h"
#include "lensmith/render/ewa_renderer.h"
#include "lensmith/render/gather_renderer.h"
#include "lensmith/scene/lens_render.h"
#include "lensmith/scene/scene_json.h"
#include "lensmith/render/lightfield_renderer.h"
#include "lensmith/render/multiview_renderer.h"

namespace lensmith::cli {

namespace {


Aperture make_aperture(const BokehCommandOptions& o) {
  if (!o.aperture_image.empty()) {
    // The picture's luminance is the aperture's transmission over [-1, 1]^2 (top row = top).
    const Image picture = read_radiance_image(o.aperture_image);
    std::vector<float> transmission(picture.pixel_count());
    for (std::size_t i = 0; i < transmission.size(); ++i) {
      transmission[i] = (picture.data[3 * i] + picture.data[3 * i + 1] + picture.data[3 * i + 2]) / 3.0f;
    }
    return Aperture::mask(picture.width, picture.height, std::move(transmission));
  }
  if (o.blades) return Aperture::blades(*o.blades, o.blade_rotation_deg);
  return Aperture::circular();
}

// `image` with `count` more channels after its own, from `samples` (count per pixel).
Image with_channels(const Image& image, const std::vector<float>& samples, std::size_t count) {
  const auto base = static_cast<std::size_t>(image.channels), all = base + count;
  Image out(image.width, image.height, static_cast<int>(all), 0.0f);
  for (std::size_t i = 0; i < image.pixel_count(); ++i) {
    for (std::size_t c = 0; c < base; ++c) out.data[i * all + c] = image.data[i * base + c];
    for (std::size_t c = 0; c < count; ++c) out.data[i * all + base + c] = samples[i * count + c];
  }
  return out;
}

// `samples` (`count` channels per pixel) defocused like the picture, three channels at a time as a
// picture without colour fringes (they are not colours of one spectrum).
std::vector<float> defocus_channels(const std::vector<float>& samples, std::size_t count, const DepthMap& depth, const RayModel& model,
                                    const Aperture& aperture, BokehOptions options) {
  options.spectral = false;
  options.progress = nullptr;
  const std::size_t pixels = static_cast<std::size_t>(depth.width) * static_cast<std::size_t>(depth.height);
  std::vector<float> out(samples.size());
  for (std::size_t first = 0; first < count; first += 3) {
    const std::size_t n = std::min<std::size_t>(3, count - first);
    Image group(depth.width, depth.height, 3, 0.0f);
    for (std::size_t i = 0; i < pixels; ++i) {
      for (std::size_t c = 0; c < n; ++c) group.data[3 * i + c] = samples[i * count + first + c];
    }
    const Image blurred = render_bokeh(group, depth, model, aperture, options);
    for (std::size_t i = 0; i < pixels; ++i) {
      for (std::size_t c = 0; c < n; ++c) out[i * count + first + c] = blurred.data[3 * i + c];
    }
  }
  return out;
}

// A layered input that leaves pixels uncovered, written where alpha cannot go: said once.
void note_uncovered_without_alpha(const BokehCommandOptions& o, const GlobalOptions& global) {
  if (output_keeps_alpha(o.output) || global.quiet) return;
  std::cerr << "note: " << o.image << " leaves pixels uncovered (alpha < 1); only an OpenEXR output (.exr) keeps its alpha, " << o.output
            << " gets RGB over black\n";
}

// What every output records of how it was made.
// `input`: the picture's header (its OpenEXR windows, overscan, are the output's).
OutputMetadata output_metadata(const BokehCommandOptions& o, const std::string& lens_name, RayModelKind kind, const Camera& camera,
                               double focus_m, const Aperture& aperture, const RasterInfo& input) {
  OutputMetadata meta;
  if (input.has_overscan()) {
    meta.data_window = input.data_window;
    meta.display_window = input.display_window;
  }
  meta.lens = lens_name;
  meta.model = std::string(to_string(kind));
  meta.lensmith_version = LENSMITH_VERSION;
  meta.f_number = camera.f_number();
  meta.focus_m = focus_m;
  // The lens's real values in OpenEXR's standard attributes: focus from the image plane (mm -> m),
  // the f-number, the focal length and the image plane to entrance pupil distance (mm).
  const double pupil_offset_mm = camera.z_sensor_mm() - camera.z_perspective_mm();
  meta.camera = {{"focus", focus_m + m_from_mm(pupil_offset_mm)}, {"aperture", camera.f_number()},
                 {"focalLength", camera.first_order(camera.reference_wavelength_nm()).efl_mm}, {"entrancePupilOffset", pupil_offset_mm}};
  if (!std::isfinite(focus_m)) meta.camera.erase(meta.camera.begin());
  meta.extra = {{"aperture", aperture.to_string()}, {"method", o.method},
                {"vignetting", o.no_vignetting ? "off" : "natural"},
                {"spectral", o.no_spectral ? std::string("off") : std::to_string(o.spectral_samples) + " nodes"}};
  if (kind == RayModelKind::Seidel) meta.extra.emplace_back("seidel_coefficients", o.seidel_coefficients);
  return meta;
}

// A note when a picture's chromaticities attribute names primaries other than Rec.709 (ACEScg's AP1,
// say) and no --input-colorspace says how to convert them: the render is linear, so its numbers stay
// in the picture's space, but the spectral colour (dispersion) is computed for Rec.709 primaries.
void note_foreign_primaries(const std::string& image, const std::string& chromaticities) {
  const std::optional<std::array<double, 8>> parsed = parse_chromaticities(chromaticities);
  if (!parsed) return;
  const std::array<double, 8>& v = *parsed;
  const auto same = [&](const RgbPrimaries& p) {
    const double w[8] = {p.red.x, p.red.y, p.green.x, p.green.y, p.blue.x, p.blue.y, p.white.x, p.white.y};
    for (int i = 0; i < 8; ++i) {
      if (std::abs(v[i] - w[i]) > 1e-3) return false;  // OpenEXR stores them as floats; files round to 4 decimals
    }
    return true;
  };
  if (same(kRec709Primaries)) return;
  const std::string known = same(kAcesAp1Primaries) ? " (ACES AP1: ACEScg)" : same(kAcesAp0Primaries) ? " (ACES AP0: ACES2065-1)" : "";
  std::cerr << "note: " << image << "'s chromaticities are not Rec.709" << known
            << "; lensmith renders its numbers as they are and the output keeps them, but its spectral colour assumes Rec.709 "
               "primaries: give --input-colorspace with an OCIO config for exact colour (docs/color-management.md)\n";
}

// The colour management the options ask for (docs/color-management.md), or none. The output's colour
// space defaults to the input's for an OpenEXR output (ACEScg plates in, ACEScg out); PNG, JPEG and
// TIFF outputs are sRGB-encoded from the working space, as without colour management.
std::optional<ColorManagement> color_management(const BokehCommandOptions& o, const std::filesystem::path& output, bool layered) {
  if (o.input_colorspace.empty() && o.output_colorspace.empty()) {
    if (!o.ocio_config.empty() || !o.working_colorspace.empty()) {
      throw UsageError(std::string(o.ocio_config.empty() ? "--working-colorspace" : "--ocio") +
                       " converts nothing without --input-colorspace or --output-colorspace");
    }
    return std::nullopt;
  }
  const bool exr = output_keeps_alpha(output);
  if (!o.output_colorspace.empty() && !exr) {
    throw UsageError("--output-colorspace " + o.output_colorspace + ": " + output.string() +
                     " is written sRGB-encoded from linear Rec.709 (a picture to look at); colour spaces are for an .exr output");
  }
  if (!o.input_colorspace.empty() && !layered) {
    // 8/16-bit codes of a PNG, JPEG or TIFF are read as sRGB; converting them again would be wrong.
    const RasterInfo info = read_raster_info(o.image);
    for (const RasterChannel& channel : info.channels) {
      if ((channel.name == "R" || channel.name == "G" || channel.name == "B" || channel.name == "Y") && !is_floating_point(channel.type) &&
          !info.integers_are_linear) {
        throw UsageError("--input-colorspace " + o.input_colorspace + ": " + o.image + " stores " + to_string(channel.type) +
                         " codes, which lensmith reads as sRGB; colour spaces are for float pictures (OpenEXR, float TIFF, PFM, HDR)");
      }
    }
  }
  ColorManagementOptions c;
  c.config = o.ocio_config;
  c.input_colorspace = o.input_colorspace;
  c.output_colorspace = o.output_colorspace.empty() && exr ? o.input_colorspace : o.output_colorspace;
  c.working_colorspace = o.working_colorspace;
  return ColorManagement(c);
}

// Pixels added on each side of the picture to centre the lens's axis in it (overscan wider on one
// side than the other), cut off again before writing.
struct EdgeGrowth {
  int left = 0, top = 0, right = 0, bottom = 0;
  bool any() const { return left + top + right + bottom > 0; }
};

// What the output needs from the input besides the render: its chromaticities (passed through) and
// the growth to cut off, leaving the data window of data_width x data_height pixels.
struct OutputExtras {
  std::string chromaticities;
  EdgeGrowth growth;
  int data_width = 0, data_height = 0;
  int squeezed_width = 0;  // an anamorphic's picture narrowed to this width (anamorphic_output_width); 0: as rendered
};

// Writes the picture (RGB, or RGBA) in the output colour space, with the input's depth (--keep-depth)
// and its passes after it, squeezed for an anamorphic lens (OutputExtras::squeezed_width); returns the
// written size, "W x H".
std::string write_bokeh_output(Image out, OutputMetadata& meta, const BokehCommandOptions& o, DepthMap depth, OtherChannels other,
                        const std::optional<ColorManagement>& color, const OutputExtras& extras) {
  meta.chromaticities = extras.chromaticities;
  if (const EdgeGrowth& g = extras.growth; g.any()) {
    const int w = extras.data_width, h = extras.data_height;
    out.data = crop_pixels(out.data, out.width, out.channels, g.left, g.top, w, h);
    depth.z_m = crop_pixels(depth.z_m, depth.width, 1, g.left, g.top, w, h);
    depth.width = out.width = w;
    depth.height = out.height = h;
    if (!other.names.empty()) other.samples = crop_pixels(other.samples, w + g.left + g.right, static_cast<int>(other.names.size()), g.left, g.top, w, h);
  }
  if (const int narrow = extras.squeezed_width; narrow > 0) {
    // As the sensor records it: each sensor pixel integrates its share of a row; the depth is the
    // surface's under the pixel's centre (averaging depths would invent surfaces).
    const int w = out.width, h = out.height;
    out.data = squeeze_columns(out.data, w, h, out.channels, narrow);
    depth.z_m = squeeze_columns_nearest(depth.z_m, w, h, 1, narrow);
    if (!other.names.empty()) other.samples = squeeze_columns(other.samples, w, h, static_cast<int>(other.names.size()), narrow);
    out.width = depth.width = narrow;
    meta.camera.emplace_back("PixelAspectRatio", static_cast<double>(w) / narrow);
  }
  if (color && !color->options().output_colorspace.empty()) {
    color->working_to_output(out.data, out.channels);
    meta.extra.emplace_back("colorspace", color->options().output_colorspace);
    meta.extra.emplace_back("ocio_config", color->config_path());
  }
  std::vector<std::string> channels{"R", "G", "B"};
  if (out.channels == 4) channels.emplace_back("A");
  if (o.keep_depth) {
    // The depth as read (planar metres from the entrance pupil): a compositor's Z for the picture's
    // in-focus geometry; the blurred picture has no single depth per pixel.
    out = with_channels(out, depth.z_m, 1);
    channels.emplace_back("Z");
  }
  if (!other.names.empty()) {
    // After R, G, B (A, Z): the passes under their own names.
    out = with_channels(out, other.samples, other.names.size());
    channels.insert(channels.end(), other.names.begin(), other.names.end());
    meta.extra.emplace_back("other_channels", o.other_channels);
  }
  write_output_image(o.output, out, meta, channels);
  return std::to_string(out.width) + " x " + std::to_string(out.height);
}

}  // namespace

int run_bokeh(const BokehCommandOptions& o, const GlobalOptions& global) {
  const auto started = std::chrono::steady_clock::now();
  // Each stage's wall time, for --timings (the scatter method's).
  StageTimes timings;
  // The threads the reading, the render and the writing share, started first (openmp_team.h).
  start_openmp_team(o.threads > 0 ? o.threads : omp_get_max_threads());
  timings.lap("starting threads");
  const bool multiview = o.method == "multiview", lightfield = o.method == "lightfield", ewa = o.method == "ewa", gather = o.method == "gather";
  if (o.method != "scatter" && !o.scatter_options.empty()) {
    throw UsageError(o.scatter_options.front() + " is an option of --method scatter, not of --method " + o.method);
  }
  if (!multiview && !o.multiview_options.empty()) throw UsageError(o.multiview_options.front() + " is an option of --method multiview");
  if (!lightfield && !o.lightfield_options.empty()) throw UsageError(o.lightfield_options.front() + " is an option of --method lightfield");
  if (!ewa && !o.ewa_options.empty()) throw UsageError(o.ewa_options.front() + " is an option of --method ewa");
  if (!gather && o.hidden == "trace") throw UsageError("--hidden trace is for --method gather (Tan et al.'s hybrid), with --scene FILE");
  if (!gather && !o.gather_options.empty()) throw UsageError(o.gather_options.front() + " is an option of --method gather");
  // --hidden: scatter's extend or stretch, gather's trace (Tan et al.'s hybrid, which needs the scene).
  const bool traced = gather && o.hidden == "trace";
  if (gather && o.hidden != "trace" && o.hidden != "extend") {
    throw UsageError("--hidden " + o.hidden + " is for --method scatter; --method gather takes --hidden trace (with --scene FILE)");
  }
  if (traced && o.scene.empty()) {
    throw UsageError("--hidden trace needs --scene FILE: the analytic scene (lensmith-scene JSON) that the picture is the pinhole render of");
  }
  for (const std::string& name : o.gather_options) {
    if (!traced && (name == "--scene" || name == "--trace-rays")) throw UsageError(name + " is for --method gather --hidden trace");
  }
  // A sequence's pattern without --frames names no file: say what is missing rather than "cannot open".
  for (const std::string* path : {&o.image, &o.output}) {
    if (FramePattern::find(*path) && !std::filesystem::exists(*path)) {
      throw UsageError(*path + " names a sequence (its frame field): give --frames, e.g. --frames 1001-1100 (docs/sequences.md)");
    }
  }
  // Inputs.
  const std::filesystem::path output = o.output;
  const DepthSource depth_source = DepthSource::parse(o.depth.empty() ? o.image : o.depth);
  std::vector<std::filesystem::path> inputs{o.image, depth_source.file};
  if (!o.aperture_image.empty()) inputs.emplace_back(o.aperture_image);
  ensure_not_an_input(output, inputs);
  ensure_writable_location(output);
  if (o.keep_depth && !output_keeps_alpha(output)) {
    throw UsageError("--keep-depth needs an OpenEXR output (.exr): " + output.string() + " cannot hold a depth channel");
  }
  // The picture, its alpha, passes and depth are often one file: opened and decoded once, until the
  // depth is read.
  std::optional<ImageReadCache> read_cache(std::in_place);
  // A deep OpenEXR is layered input: its samples carry colour, alpha and depth together.
  const bool layered = is_deep_image(o.image);
  const std::optional<ColorManagement> color = color_management(o, output, layered);
  if (color && !global.quiet) {
    const ColorManagementOptions& c = color->options();
    std::cerr << "note: colour: " << (c.input_colorspace.empty() ? "linear Rec.709" : c.input_colorspace)
              << " -> linear Rec.709 (working space: " << color->working_route() << ") -> "
              << (c.output_colorspace.empty() ? (output_keeps_alpha(output) ? "linear Rec.709" : "sRGB-encoded") : c.output_colorspace)
              << ", OCIO config " << color->config_path() << "\n";
  }
  RadianceReadOptions read;
  read.highlight_gain = o.highlight_gain;
  read.highlight_threshold = o.highlight_threshold;
  read.validate();
  if (o.threads > 0) set_image_codec_threads(o.threads);
  if (layered && !o.depth.empty()) {
    throw UsageError(o.image + " is a deep image, whose samples carry their own Z: --depth is for flat pictures");
  }
  std::optional<Image> flat;
  int width = 0, height = 0;
  if (layered) {
    const DeepRaster header = read_deep_header(o.image);
    width = header.width;
    height = header.height;
    std::vector<std::string> unused;
    for (const std::string& name : header.channels) {
      if (name != "R" && name != "G" && name != "B" && name != "A" && name != "Z" && name != "ZBack") unused.push_back(name);
    }
    if (!unused.empty() && !global.quiet) {
      std::cerr << "note: " << o.image << " is deep; its channels besides R, G, B, A, Z and ZBack (" << unused.size()
                << ", e.g. " << unused.front() << ") are not read\n";
    }
    if (std::find(header.channels.begin(), header.channels.end(), "A") == header.channels.end() && !global.quiet) {
      std::cerr << "note: " << o.image << " is deep without an A channel: every sample is taken as opaque\n";
    }
  } else {
    flat = read_radiance_image(o.image, read);
    if (color) color->input_to_working(flat->data, 3);
    width = flat->width;
    height = flat->height;
  }
  timings.lap("reading the picture");
  // A transparent element (a CG layer over nothing) keeps its alpha: defocused with the same rays as
  // its (premultiplied) colour, into an RGBA OpenEXR.
  std::optional<std::vector<float>> alpha = layered ? std::nullopt : read_alpha(o.image);
  if (alpha && !output_keeps_alpha(output)) {
    if (!global.quiet) std::cerr << "note: " << o.image << " has alpha; only an OpenEXR output (.exr) keeps it, " << output.string() << " gets RGB\n";
    alpha.reset();
  }

  // Render passes (AOVs) of an EXR input: kept in focus as Nuke's defocus nodes leave the channels
  // they do not process, defocused with the picture's rays, or dropped.
  OtherChannels other = o.other_channels == "drop" || layered ? OtherChannels{} : read_other_channels(o.image);
  if (!other.names.empty() && !output_keeps_alpha(output)) {
    if (!global.quiet) {
      std::cerr << "note: " << o.image << " has " << other.names.size() << " other channels; only an OpenEXR output (.exr) keeps them\n";
    }
    other = {};
  }
  // The output is checked for values no computation should make; a pass's NaN or infinity is the
  // input's, and said as such.
  for (std::size_t i = 0; i < other.samples.size(); ++i) {
    if (std::isfinite(other.samples[i])) continue;
    const std::size_t pixel = i / other.names.size(), w = static_cast<std::size_t>(width);
    throw ImageFileError(o.image + ": channel " + other.names[i % other.names.size()] + " at pixel (" + std::to_string(pixel % w) + ", " +
                         std::to_string(pixel / w) + ") is " + format_number(other.samples[i]) +
                         ": the passes written beside the picture must be finite (--other-channels drop leaves them out)");
  }
  if (!other.names.empty() && !global.quiet) {
    std::string names;
    for (std::size_t i = 0; i < other.names.size() && i < 6; ++i) names += (i ? ", " : "") + other.names[i];
    if (other.names.size() > 6) names += ", ...";
    std::cerr << "note: " << other.names.size() << " other channels of " << o.image << " (" << names << ") "
              << (o.other_channels == "keep" ? "kept unchanged, in focus (--other-channels defocus blurs them with the picture, drop leaves them out)"
                                             : "defocused with the picture's rays")
              << "\n";
  }

  // Framing: the flags, else what the input EXR says of its own pinhole camera (lensmith scene
  // render writes lensmith:focal_length_mm and lensmith:sensor_width_mm), else 36 mm and the lens's EFL.
  CameraOptions camera;
  camera.f_number = o.f_number;
  camera.framing.sensor_width_mm = o.sensor_width_mm.value_or(36.0);
  camera.framing.focal_length_mm = o.pinhole_focal_length_mm;
  camera.framing.horizontal_fov_deg = o.hfov_deg;
  std::vector<std::string> from_file;
  const std::vector<std::pair<std::string, std::string>> attributes = read_image_metadata(o.image);
  // The RGB's primaries, when the picture says: passed through to the output when its numbers are
  // in the same colour space (no conversion, or output = input), and a note when they are not
  // Rec.709 and nothing says what they are.
  std::string input_chromaticities;
  for (const auto& [key, value] : attributes) {
    if (key == "chromaticities") input_chromaticities = value;
  }
  if (!input_chromaticities.empty() && o.input_colorspace.empty() && !global.quiet) note_foreign_primaries(o.image, input_chromaticities);
  OutputExtras extras;
  extras.chromaticities =
      !color || color->options().output_colorspace == color->options().input_colorspace ? input_chromaticities : std::string();
  for (const auto& [key, value] : attributes) {
    const std::optional<double> number = parse_finite_number(value);
    if (!number || !(*number > 0.0)) continue;
    // A squeezed plate (an anamorphic's, or lensmith's own squeezed output) has wide pixels: its pixels
    // do not look where a square pinhole frame says. Tolerance: OpenEXR stores the ratio as a float.
    constexpr double kSquareTolerance = 1e-6;
    if (key == "PixelAspectRatio" && std::abs(*number - 1.0) > kSquareTolerance) {
      throw UsageError(o.image + ": its pixels are not square (pixel aspect ratio " + value + "): lensmith bokeh reads pictures with "
                       "square pixels; desqueeze it first (e.g. oiiotool --resize), or render the input desqueezed (not implemented)");
    }
    if (key == "lensmith:focal_length_mm" && !o.pinhole_focal_length_mm && !o.hfov_deg) {
      camera.framing.focal_length_mm = *number;
      from_file.push_back("pinhole focal length " + value + " mm");
    }
    if (key == "lensmith:sensor_width_mm" && !o.sensor_width_mm) {
      camera.framing.sensor_width_mm = *number;
      from_file.push_back("sensor width " + value + " mm");
    }
  }
  if (!from_file.empty() && !global.quiet) {
    std::cerr << "note: framing from " << o.image << ":";
    for (std::size_t i = 0; i < from_file.size(); ++i) std::cerr << (i ? "," : "") << " " << from_file[i];
    std::cerr << " (its lensmith attributes; the flags override them)\n";
  }
  // The camera the file says made it (OpenEXR's standard attributes, Unreal's keys): what the flags
  // and lensmith's own attributes leave open.
  const CameraMetadata metadata = camera_metadata_from(attributes);
  std::vector<std::string> used;
  if (!o.f_number && metadata.f_number) {
    camera.f_number = metadata.f_number;
    used.push_back("f-number " + format_number(*metadata.f_number));
  }
  if (!camera.framing.focal_length_mm && !o.hfov_deg && metadata.focal_length_mm) {
    camera.framing.focal_length_mm = metadata.focal_length_mm;
    used.push_back("focal length " + format_number(*metadata.focal_length_mm) + " mm (the framing)");
  }
  if (!o.sensor_width_mm && metadata.sensor_width_mm &&
      std::none_of(attributes.begin(), attributes.end(), [](const auto& a) { return a.first == "lensmith:sensor_width_mm"; })) {
    camera.framing.sensor_width_mm = *metadata.sensor_width_mm;
    used.push_back("sensor width " + format_number(*metadata.sensor_width_mm) + " mm");
  }
  std::optional<double> thin_focal_mm = o.focal_length_mm;
  if (o.thin_lens && !thin_focal_mm && metadata.focal_length_mm) {
    thin_focal_mm = metadata.focal_length_mm;
    used.push_back("thin-lens focal length " + format_number(*metadata.focal_length_mm) + " mm");
  }
  std::optional<int> blades = o.blades;
  if (!o.blades && o.aperture_image.empty() && metadata.blades) {
    blades = metadata.blades;
    used.push_back(std::to_string(*metadata.blades) + " blades");
  }
  std::string lens_name;
  RayModelKind kind = o.model.empty() ? (o.thin_lens ? RayModelKind::Thin : RayModelKind::Seidel) : parse_ray_model_kind(o.model);
  // The lens (or thin lens) and the focal length the framing defaults to.
  std::optional<Prescription> lens;
  double default_focal_mm = 0.0;
  if (o.thin_lens) {
    if (kind != RayModelKind::Thin) {
      throw UsageError("--thin-lens has no prescription: only --model thin applies (got --model " + o.model + ")");
    }
    if (!thin_focal_mm) throw UsageError("--thin-lens needs --focal-length MM (or a focalLength attribute in the picture)");
    default_focal_mm = *thin_focal_mm;
    lens_name = "thin lens f = " + format_rounded(*thin_focal_mm, 6) + " mm";
  } else {
    if (o.lens.empty()) throw UsageError("give --lens LENS (a file or shipped lens name) or --thin-lens --focal-length MM");
    lens = load_lens(o.lens, global);
    lens_name = lens->name.empty() ? o.lens : lens->name;
    if (o.model.empty()) {
      if (const auto why = Camera::exact_model_only_for(*lens)) {
        // The default model is for round refracting lenses: the exact one photographs the others.
        kind = RayModelKind::Exact;
        if (!global.quiet) std::cerr << "note: " << lens_name << ": the exact model photographs this lens (" << *why << "; --model exact)\n";
      }
    }
    default_focal_mm = ParaxialSystem(*lens).efl_mm();
  }
  if (!o.focus_m && o.focus_pixel.empty() && !metadata.focus_from_pupil_m && !metadata.focus_from_image_plane_m) {
    throw UsageError("give --focus M (metres) or --focus-pixel X,Y (the picture has no focus attribute)");
  }
  DepthReadOptions depth_options;
  depth_options.kind = parse_depth_kind(o.depth_kind);
  depth_options.unit = parse_depth_unit(o.depth_unit);
  depth_options.invalid = parse_invalid_depth(o.invalid_depth);
  // Overscan: pixels beyond the frame, which light from outside it reaches the frame through. The
  // framing (sensor width, focal length, field of view) is the display window's; the pictures are
  // the data window, framed with the same focal length in pixels.
  const RasterInfo windows = layered ? RasterInfo{} : read_raster_info(o.image);
  if (windows.has_overscan()) {
    const PixelBox& data = windows.data_window;
    const PixelBox& shown = windows.display_window;
    // The lens's axis is the frame's centre. Overscan wider on one side than the other puts it off
    // the data window's centre: the pictures are grown by their edge pixels on the narrower sides
    // until it is centred, rendered whole, and cut back to the data window.
    const int left = shown.min_x - data.min_x, right = data.max_x - shown.max_x;
    const int top = shown.min_y - data.min_y, bottom = data.max_y - shown.max_y;
    extras.growth = {std::max(0, right - left), std::max(0, bottom - top), std::max(0, left - right), std::max(0, top - bottom)};
    const double focal_px = PinholeFrame::from_options(shown.width(), shown.height(), camera.framing, default_focal_mm).focal_length_px();
    camera.framing = PinholeFrameOptions{};
    camera.framing.focal_length_mm =
        focal_px * camera.framing.sensor_width_mm / (width + extras.growth.left + extras.growth.right);
    if (!global.quiet) {
      std::cerr << "note: " << o.image << " has overscan: data window " << data.to_string() << " around the frame " << shown.to_string()
                << "; the pixels outside the frame are photographed too (their light reaches the frame)";
      if (extras.growth.any()) {
        std::cerr << "; wider on one side, so the picture is extended by its edge pixels (" << extras.growth.left << " left, "
                  << extras.growth.top << " top, " << extras.growth.right << " right, " << extras.growth.bottom
                  << " bottom) to centre the lens's axis, and cut back";
      }
      std::cerr << "\n";
    }
  }
  const EdgeGrowth& grow = extras.growth;
  extras.data_width = width;
  extras.data_height = height;
  if (grow.any()) {
    flat->data = extend_edges(flat->data, width, height, 3, grow.left, grow.top, grow.right, grow.bottom);
    if (alpha) *alpha = extend_edges(*alpha, width, height, 1, grow.left, grow.top, grow.right, grow.bottom);
    if (!other.names.empty()) {
      other.samples = extend_edges(other.samples, width, height, static_cast<int>(other.names.size()), grow.left, grow.top, grow.right, grow.bottom);
    }
    width += grow.left + grow.right;
    height += grow.top + grow.bottom;
    flat->width = width;
    flat->height = height;
  }
  // The camera's framing is the pinhole frame the depth is read in (Camera::from_lens and thin_lens
  // build the same one).
  const PinholeFrame frame = PinholeFrame::from_options(width, height, camera.framing, default_focal_mm);
  std::optional<DeepImage> deep;
  if (layered) {
    deep = read_deep_image(o.image, depth_options, frame);
    if (color) {
      std::vector<float> rgb(deep->samples.size() * 3);
      for (std::size_t i = 0; i < deep->samples.size(); ++i) std::copy_n(deep->samples[i].rgb.begin(), 3, rgb.begin() + 3 * i);
      color->input_to_working(rgb, 3);
      for (std::size_t i = 0; i < deep->samples.size(); ++i) std::copy_n(rgb.begin() + 3 * i, 3, deep->samples[i].rgb.begin());
    }
  }
  // A layered input's depth per pixel is its front sample's, the nearest (for --focus-pixel,
  // --keep-depth and the models' nearest depth).
  DepthMap depth = layered ? deep->front_depth()
                           : read_depth(depth_source, depth_options,
                                        grow.any() ? frame.window(grow.left, grow.top, extras.data_width, extras.data_height) : frame);
  if (grow.any()) {
    depth.z_m = extend_edges(depth.z_m, depth.width, depth.height, 1, grow.left, grow.top, grow.right, grow.bottom);
    depth.width = width;
    depth.height = height;
  }
  read_cache.reset();
  timings.lap("reading alpha, passes, metadata and depth");
  if (!o.focus_pixel.empty()) {
    // X,Y: integers inside the image.
    const std::size_t comma = o.focus_pixel.find(',');
    const std::optional<double> x = comma == std::string::npos ? std::nullopt : parse_finite_number(o.focus_pixel.substr(0, comma));
    const std::optional<double> y = comma == std::string::npos ? std::nullopt : parse_finite_number(o.focus_pixel.substr(comma + 1));
    if (!x || !y || *x != std::floor(*x) || *y != std::floor(*y) || *x < 0 || *y < 0 || *x >= extras.data_width || *y >= extras.data_height) {
      throw UsageError("--focus-pixel " + o.focus_pixel + ": expected X,Y, whole pixels inside the " + std::to_string(extras.data_width) +
                       " x " + std::to_string(extras.data_height) + " image (0,0 = top left)");
    }
    const float z = depth.at(static_cast<int>(*x) + grow.left, static_cast<int>(*y) + grow.top);
    camera.focus_distance_m = z;
    if (!global.quiet) std::cerr << "note: focus " << format_rounded(z, 5) << " m, the depth at pixel (" << o.focus_pixel << ")\n";
  } else if (o.focus_m) {
    camera.focus_distance_m = *o.focus_m;
  } else if (metadata.focus_from_pupil_m) {
    camera.focus_distance_m = *metadata.focus_from_pupil_m;
    used.push_back("focus " + format_number(camera.focus_distance_m) + " m from the camera");
  } else {
    // OpenEXR's focus is measured from the image plane; lensmith's from the entrance pupil.
    const double d = *metadata.focus_from_image_plane_m;
    camera.focus_distance_m = metadata.entrance_pupil_offset_mm
                                  ? d - m_from_mm(*metadata.entrance_pupil_offset_mm)
                                  : CameraSpec{o.thin_lens ? thin_focal_mm : std::nullopt, camera, width, height}.pupil_focus_distance_m(
                                        kind, lens ? &*lens : nullptr, d);
    used.push_back("focus " + format_number(d) + " m from the image plane = " + format_rounded(camera.focus_distance_m, 6) +
                   " m from the entrance pupil" + (metadata.entrance_pupil_offset_mm ? " (its entrancePupilOffset)" : " (the lens's)"));
  }
  if (!used.empty() && !global.quiet) {
    std::cerr << "note: camera from " << o.image << "'s metadata:";
    for (std::size_t i = 0; i < used.size(); ++i) std::cerr << (i ? "," : "") << " " << used[i];
    std::cerr << " (the flags override it)\n";
  }
  std::optional<Camera> cam =
      CameraSpec{o.thin_lens ? thin_focal_mm : std::nullopt, camera, width, height}.camera(kind, lens ? &*lens : nullptr);
  if (!cam->is_thin_lens()) warn_about_aperture(*cam, global);
  // The thin model of a lens takes that lens's brightness across the frame where the renderer can
  // (a round refracting lens it can make at this f-number: IlluminationTable); said where it cannot.
  if (lens && cam->is_thin_lens() && !o.no_vignetting && !global.quiet) {
    const Camera* real = cam->real_lens();
    if (real == nullptr) {
      std::cerr << "note: " << lens_name << " cannot be made at f/" << format_number(cam->f_number())
                << ": the thin model keeps no falloff across the frame (at the lens's own f-numbers it has the real lens's)\n";
    } else if (real->exact_model_only() || real->squeeze() != 1.0) {
      std::cerr << "note: " << lens_name << ": the thin model keeps no falloff across the frame (it takes a real lens's only from "
                << "round refracting lenses; " << (real->exact_model_only() ? *real->exact_model_only() : std::string("it is anamorphic"))
                << "): --model exact has this lens's\n";
    }
  }
  extras.squeezed_width = anamorphic_output_width(*cam, extras.data_width, o.desqueeze, global);
  if (extras.squeezed_width > 0 && windows.has_overscan()) {
    throw UsageError(o.image + " has overscan (a data window beyond its display window): an anamorphic lens's picture with overscan "
                     "is written desqueezed only (give --desqueeze; squeezing the windows is not implemented)");
  }
  float nearest_m = std::numeric_limits<float>::infinity();
  for (float z : depth.z_m) nearest_m = std::min(nearest_m, z);
  RayModelOptions model_options;
  model_options.nearest_depth_m = std::isfinite(nearest_m) ? std::max(0.01, static_cast<double>(nearest_m)) : 1.0;
  model_options.seidel_coefficients = parse_seidel_coefficients(o.seidel_coefficients);
  if (!o.thin_lens) model_options.fit = fit_for_models({kind}, *cam, o.fit, global);
  else if (!o.fit.empty()) throw UsageError("--fit is for --model poly with --lens");
  const auto model = make_ray_model(kind, *cam, model_options);
  BokehCommandOptions aperture_options = o;
  aperture_options.blades = blades;
  const Aperture aperture = make_aperture(aperture_options);

  if (o.method != "scatter" && o.other_channels == "defocus" && !other.names.empty()) {
    throw UsageError("--other-channels defocus with --method " + o.method + ": not implemented (use keep or drop, or --method scatter)");
  }
  if (lightfield) {
    if (layered) throw UsageError("--method lightfield warps one surface per pixel: a deep (layered) input is not implemented; use --method multiview or scatter");
    if (alpha) throw UsageError("--method lightfield: a picture with transparent pixels (alpha) is not implemented; use --method scatter or multiview");
    LightfieldOptions options;
    options.threads = o.threads;
    options.views = o.views;
    options.mip_filter = !o.no_mip_filter;
    options.vignetting = !o.no_vignetting;
    options.spectral = !o.no_spectral;
    ProgressBar bar("bokeh", !global.quiet);
    options.progress = [&bar](double f) { bar.update(f); };
    LightfieldStatistics stats;
    const auto render_started = std::chrono::steady_clock::now();
    const Image out = render_lightfield(*flat, depth, *model, aperture, options, &stats);
    const double render_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - render_started).count();
    bar.finish();
    OutputMetadata meta = output_metadata(o, lens_name, kind, *cam, camera.focus_distance_m, aperture, windows);
    meta.extra.insert(meta.extra.end(), {{"views", std::to_string(options.views)}, {"mip_filter", options.mip_filter ? "on" : "off"},
                                         {"lightfield_colour", options.spectral ? "three wavelengths" : "reference wavelength"}});
    const std::string written = write_bokeh_output(out, meta, o, depth, other, color, extras);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    const double pixel_views = static_cast<double>(out.width) * out.height * options.views;
    std::ostringstream what;
    what << output.string() << " (" << written << ") in " << std::fixed << std::setprecision(2) << seconds
         << " s (rendering " << render_seconds << " s)\n  " << lens_name << ", model " << to_string(kind) << ", method lightfield, f/"
         << format_rounded(cam->f_number(), 3) << ", focus " << format_rounded(camera.focus_distance_m, 4) << " m, " << aperture.to_string()
         << " aperture\n  " << options.views << " views, "
         << (options.spectral ? std::string("each warped at three wavelengths, one per RGB channel")
                              : "each at " + format_rounded(cam->reference_wavelength_nm(), 4) + " nm (--no-spectral)")
         << "; " << stats.stopped
         << " warped rays stopped by the lens; " << format_rounded(100.0 * static_cast<double>(stats.holes) / pixel_views, 3)
         << " % of pixel views holes (no source landed), " << stats.unfilled_pixels << " pixels no view reached (input colour kept)";
    report_written(what.str(), global);
    return kExitOk;
  }
  if (ewa) {
    if (layered) throw UsageError("--method ewa splats one surface per pixel: a deep (layered) input is not implemented; use --method multiview or scatter");
    if (alpha) throw UsageError("--method ewa: a picture with transparent pixels (alpha) is not implemented; use --method scatter or multiview");
    EwaOptions options;
    options.threads = o.threads;
    options.vignetting = !o.no_vignetting;
    options.lens_psf = !o.circular_splats;
    options.level_of_detail = !o.no_level_of_detail;
    ProgressBar bar("bokeh", !global.quiet);
    options.progress = [&bar](double f) { bar.update(f); };
    EwaStatistics stats;
    const auto render_started = std::chrono::steady_clock::now();
    const Image out = render_ewa(*flat, depth, *model, aperture, options, &stats);
    const double render_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - render_started).count();
    bar.finish();
    OutputMetadata meta = output_metadata(o, lens_name, kind, *cam, camera.focus_distance_m, aperture, windows);
    meta.extra.insert(meta.extra.end(), {{"splat_kernel", options.lens_psf ? "lens psf" : "circular coc"},
                                         {"level_of_detail", options.level_of_detail ? "on" : "off"}});
    const std::string written = write_bokeh_output(out, meta, o, depth, other, color, extras);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    std::ostringstream what;
    what << output.string() << " (" << written << ") in " << std::fixed << std::setprecision(2) << seconds
         << " s (rendering " << render_seconds << " s)\n  " << lens_name << ", model " << to_string(kind) << ", method ewa, f/"
         << format_rounded(cam->f_number(), 3) << ", focus " << format_rounded(camera.focus_distance_m, 4) << " m, " << aperture.to_string()
         << " aperture\n  " << stats.splats << " splats ("
         << (options.lens_psf ? "the lens's PSF covariance" : "circular Gaussians of the CoC") << ", at "
         << format_rounded(cam->reference_wavelength_nm(), 4) << " nm: spectral colour is not implemented for ewa), "
         << format_rounded(static_cast<double>(stats.pixel_writes) / (static_cast<double>(out.width) * out.height), 3)
         << " pixel writes per pixel, " << stats.unfilled_pixels << " pixels no splat reached (input colour kept)";
    report_written(what.str(), global);
    return kExitOk;
  }
  if (gather) {
    if (layered) throw UsageError("--method gather gathers one surface per pixel: a deep (layered) input is not implemented; use --method multiview or scatter");
    if (alpha) throw UsageError("--method gather: a picture with transparent pixels (alpha) is not implemented; use --method scatter or multiview");
    GatherOptions options;
    options.threads = o.threads;
    options.vignetting = !o.no_vignetting;
    options.rings = o.rings;
    options.median = !o.no_median;
    options.trace_rays = o.trace_rays;
    std::optional<Scene> scene;
    if (traced) {
      scene = load_scene(o.scene);
      options.trace = [&](std::vector<GatherTraceRequest>& requests) {
        LensRenderOptions rays;
        rays.threads = o.threads;
        rays.spectral = !o.no_spectral;
        rays.spectral_samples = o.spectral_samples;
        trace_regions(*scene, *cam, requests, rays);
      };
    }
    ProgressBar bar("bokeh", !global.quiet);
    options.progress = [&bar](double f) { bar.update(f); };
    GatherStatistics stats;
    const auto render_started = std::chrono::steady_clock::now();
    const Image out = render_gather(*flat, depth, *model, aperture, options, &stats);
    const double render_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - render_started).count();
    bar.finish();
    OutputMetadata meta = output_metadata(o, lens_name, kind, *cam, camera.focus_distance_m, aperture, windows);
    meta.extra.insert(meta.extra.end(), {{"rings", std::to_string(options.rings)}, {"median", options.median ? "on" : "off"},
                                         {"hidden_surfaces", traced ? "trace " + o.scene : std::string("none")}});
    const std::string written = write_bokeh_output(out, meta, o, depth, other, color, extras);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    std::ostringstream what;
    what << output.string() << " (" << written << ") in " << std::fixed << std::setprecision(2) << seconds
         << " s (rendering " << render_seconds << " s)\n  " << lens_name << ", model " << to_string(kind) << ", method gather, f/"
         << format_rounded(cam->f_number(), 3) << ", focus " << format_rounded(camera.focus_distance_m, 4) << " m, " << aperture.to_string()
         << " aperture\n  " << stats.half_width << " x " << stats.half_height << " half resolution, " << stats.taps << " taps ("
         << options.rings << " rings), largest kernel radius " << format_rounded(stats.max_kernel_radius_px, 3) << " px, "
         << stats.gathered_pixels << " half-resolution pixels gathered, at " << format_rounded(cam->reference_wavelength_nm(), 4)
         << " nm (spectral colour is not implemented for gather)";
    if (traced) what << "; " << stats.traced_pixels << " half-resolution pixels traced into " << o.scene << " with " << stats.traced_rays << " rays";
    report_written(what.str(), global);
    return kExitOk;
  }
  if (multiview) {
    MultiviewOptions options;
    options.threads = o.threads;
    options.samples = o.samples;
    options.layers = o.layers;
    options.ray_grid_px = o.ray_grid_px;
    options.cone_tracing = !o.no_cone_tracing;
    options.vignetting = !o.no_vignetting;
    options.spectral = !o.no_spectral;
    options.spectral_samples = o.spectral_samples;
    ProgressBar bar("bokeh", !global.quiet);
    options.progress = [&bar](double f) { bar.update(f); };
    MultiviewStatistics stats;
    const auto render_started = std::chrono::steady_clock::now();
    DeepImage flat_scene;
    if (!layered) {
      flat_scene = deep_image_from_flat(*flat, depth);
      if (alpha) {
        // A transparent element: its samples cover their alpha (colour premultiplied, as read).
        for (std::size_t i = 0; i < flat_scene.samples.size(); ++i) flat_scene.samples[i].alpha = std::clamp((*alpha)[i], 0.0f, 1.0f);
      }
    }
    const DeepImage& scene = layered ? *deep : flat_scene;
    const Image rgba = render_multiview(scene, *model, aperture, options, &stats);
    const double render_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - render_started).count();
    bar.finish();
    const bool transparent = scene.max_transparency() > 1e-4;
    if (transparent && layered) note_uncovered_without_alpha(o, global);
    const Image out = rgba.leading_channels(transparent && output_keeps_alpha(output) ? 4 : 3);
    OutputMetadata meta = output_metadata(o, lens_name, kind, *cam, camera.focus_distance_m, aperture, windows);
    meta.extra.insert(meta.extra.end(), {{"samples", std::to_string(options.samples)}, {"layers", std::to_string(options.layers)},
                                         {"cone_tracing", options.cone_tracing ? "on" : "off"}});
    const std::string written = write_bokeh_output(out, meta, o, depth, other, color, extras);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    std::ostringstream what;
    what << output.string() << " (" << written << ") in " << std::fixed << std::setprecision(2) << seconds
         << " s (rendering " << render_seconds << " s)\n  " << lens_name << ", model " << to_string(kind) << ", method multiview, f/"
         << format_rounded(cam->f_number(), 3) << ", focus " << format_rounded(camera.focus_distance_m, 4) << " m, " << aperture.to_string()
         << " aperture\n  " << stats.layers << " of " << options.layers << " depth layers hold samples, "
         << format_rounded(stats.layer_spacing_px, 3) << " px apart; largest blur " << format_rounded(stats.max_abs_coc_px, 3) << " px; "
         << options.samples << " lens rays per pixel, " << stats.stopped_rays
         << " stopped by the lens, " << stats.lost_rays << " fell through what the input knows";
    if (layered) what << "; layered input: " << scene.sample_count() << " deep samples";
    report_written(what.str(), global);
    return kExitOk;
  }

  // Render.
  BokehOptions options;
  options.threads = o.threads;
  options.hidden = parse_hidden_surfaces(o.hidden);
  options.split_edge_pixels = o.edge_pixels == "split";
  options.vignetting = !o.no_vignetting;
  options.reuse_shapes = !o.no_shape_reuse;
  options.interpolated_rays = !o.rays_per_pixel;
  options.light_images = !o.mesh_footprints;
  options.spectral = !o.no_spectral;
  options.spectral_samples = o.spectral_samples;
  options.layer_spacing_px = o.layer_spacing_px;
  options.splat.subrows = o.subrows;
  options.max_blur_px = o.max_blur_px;
  ProgressBar bar("bokeh", !global.quiet);
  options.progress = [&bar](double f) { bar.update(f); };
  BokehStatistics stats;
  const auto render_started = std::chrono::steady_clock::now();
  timings.lap("lens and model");
  Image out = layered ? render_bokeh(*deep, *model, aperture, options, &stats) : render_bokeh(*flat, depth, *model, aperture, options, &stats);
  const bool layered_alpha = layered && deep->max_transparency() > 1e-4;
  if (layered_alpha) note_uncovered_without_alpha(o, global);
  if (layered_alpha && output_keeps_alpha(output)) {
    // Alpha through the same rays: the samples' alphas as their colour (premultiplied: alpha times
    // one), without vignetting, as for a flat picture's alpha below.
    DeepImage coverage_image = *deep;
    for (DeepSample& sample : coverage_image.samples) sample.rgb = {sample.alpha, sample.alpha, sample.alpha};
    BokehOptions coverage = options;
    coverage.vignetting = false;
    coverage.spectral = false;
    coverage.progress = nullptr;
    const Image a = render_bokeh(coverage_image, *model, aperture, coverage);
    std::vector<float> channel(a.pixel_count());
    for (std::size_t i = 0; i < channel.size(); ++i) channel[i] = std::clamp(a.data[i * 3], 0.0f, 1.0f);
    out = with_channels(out, channel, 1);
  } else if (alpha) {
    // Alpha through the same model without vignetting (an opaque surface stays opaque however little
    // light the lens takes from it).
    BokehOptions coverage = options;
    coverage.vignetting = false;
    std::vector<float> a = defocus_channels(*alpha, 1, depth, *model, aperture, coverage);
    for (float& v : a) v = std::clamp(v, 0.0f, 1.0f);
    out = with_channels(out, a, 1);
  }
  // Passes with the lens's vignetting, so that light passes keep adding up to the picture.
  if (o.other_channels == "defocus" && !other.names.empty()) {
    other.samples = defocus_channels(other.samples, other.names.size(), depth, *model, aperture, options);
  }
  const double render_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - render_started).count();
  bar.finish();
  for (const StageTimes::Stage& stage : stats.stages.stages()) timings.add(stage.name, stage.ms);
  // The render's checks before its first stage, and the alpha and other channels defocused after it.
  const double rest_ms = 1000.0 * render_seconds - stats.stages.total_ms();
  if (rest_ms > 0.05) timings.add("checks, alpha and other channels", rest_ms);
  timings.restart();

  OutputMetadata meta = output_metadata(o, lens_name, kind, *cam, camera.focus_distance_m, aperture, windows);
  meta.extra.insert(meta.extra.end(), {{"hidden_surfaces", std::string(to_string(options.hidden))}, {"edge_pixels", o.edge_pixels}});
  const int out_width = out.width, out_height = out.height;
  // Moved, not copied: the picture and depth are frame-sized (copying them cost the street scene's
  // process 4 MB of fresh memory).
  const std::string written = write_bokeh_output(std::move(out), meta, o, std::move(depth), std::move(other), color, extras);
  timings.lap("writing");
  if (o.timings) std::cerr << "timings: " << timings << "\n";
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  std::ostringstream what;
  what << output.string() << " (" << written << ") in " << std::fixed << std::setprecision(2) << seconds
       << " s (rendering " << render_seconds << " s)\n  " << lens_name << ", model " << to_string(kind) << (kind == RayModelKind::Seidel ? " (" + o.seidel_coefficients + " terms)" : std::string()) << ", f/"
       << format_rounded(cam->f_number(), 3) << ", focus " << format_rounded(camera.focus_distance_m, 4) << " m, " << aperture.to_string()
       << " aperture\n  " << stats.layers << " depth layers " << format_rounded(stats.layer_spacing_px, 3) << " px apart, largest blur "
       << format_rounded(stats.max_abs_coc_px, 3) << " px; " << stats.footprints << " footprints";
  if (stats.copied_pixels > 0) what << ", " << stats.copied_pixels << " sharp pixels copied";
  if (stats.triangles > 0) what << " (" << stats.triangles << " triangles)";
  if (stats.light_images > 0) what << ", drawn from " << stats.light_images << " light images";
  if (stats.reused_shapes > 0) what << ", " << stats.reused_shapes << " drawn from a neighbour's mapped shape";
  if (layered) {
    what << "; layered input: " << stats.deep_samples << " deep samples";
    if (stats.volume_slabs > 0) what << " (volumes cut into " << stats.volume_slabs << " slabs)";
    what << ", " << stats.hidden_sources << " hidden background pixels filled in where the file has none";
  } else {
    what << "; " << stats.hidden_sources << " hidden background pixels filled in, " << stats.split_edge_pixels
         << " edge pixels split between two surfaces";
  }
  if (stats.clamped_depths > 0) what << "; " << stats.clamped_depths << " pixels nearer than the lens serves (or beyond --max-blur) clamped";
  report_written(what.str(), global);
  if (stats.unaimed_rays > 0 && !global.quiet) {
    std::cerr << "warning: " << stats.unaimed_rays << " rays of the " << to_string(kind)
              << " model could not be aimed at their stop points and were drawn as stopped: a failure of the model, not the lens's vignetting\n";
  }
  // A tilt, a shift or strong distortion photographs past the input's frame: the band between is made of
  // copies of the input's edge (streaks). Below this share of the frame (the Canon 35 mm's distortion:
  // 4.4 px of 427) it goes unremarked.
  constexpr double kEdgeGapShare = 0.02;
  if (stats.edge_gap_px > kEdgeGapShare * std::min(out_width, out_height) && !global.quiet) {
    std::cerr << "note: the lens photographs up to " << format_rounded(stats.edge_gap_px, 3)
              << " px past the input's edge (a tilt, a shift or distortion): that band repeats the input's edge pixels; "
                 "render the input with overscan (docs/sequences.md, \"Overscan\")\n";
  }
  return kExitOk;
}

}  // namespace lensmith::cli

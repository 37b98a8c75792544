// `lensmith scene render`: an analytic scene (docs/scene-format.md) through a pinhole (the
// all-in-focus picture and planar depth that `lensmith bokeh` takes) or, as ground truth, through
// the exact prescription or an ideal thin lens with the framing `lensmith bokeh` uses.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "commands.h"
#include "progress_bar.h"
#include "lensmith/camera/camera.h"
#include "lensmith/camera/camera_spec.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "lensmith/render/image_io.h"
#include "lensmith/scene/lens_render.h"
#include "lensmith/render/deep_image.h"
#include "lensmith/scene/pinhole_render.h"
#include "lensmith/scene/scene_json.h"

namespace lensmith::cli {

namespace {

// The framing of `--pinhole` without --pinhole-focal-length: the examples' 50 mm (examples/scenes).
constexpr double kDefaultPinholeFocalMm = 50.0;


void write_depth(const std::filesystem::path& path, const DepthMap& depth) {
  Image z(depth.width, depth.height, 1);
  z.data = depth.z_m;
  write_float_exr(path, z, {"Z"});
}

}  // namespace

int run_scene_render(const SceneRenderOptions& o, const GlobalOptions& global) {
  const auto started = std::chrono::steady_clock::now();
  const int modes = (o.pinhole ? 1 : 0) + (o.lens.empty() ? 0 : 1) + (o.thin_lens ? 1 : 0);
  if (modes != 1) {
    throw UsageError("give exactly one of --pinhole, --lens LENS or --thin-lens --focal-length MM");
  }
  const std::filesystem::path output = o.output;
  ensure_not_an_input(output, {o.scene});
  ensure_writable_location(output);
  if (!o.depth.empty()) {
    ensure_not_an_input(o.depth, {o.scene});
    if (std::filesystem::absolute(o.depth).lexically_normal() == std::filesystem::absolute(output).lexically_normal()) {
      throw UsageError("--depth " + o.depth + " is the output image: give the depth another file");
    }
  }
  if (o.layers > 0 && !output_keeps_alpha(output)) {
    throw UsageError("--layers writes a deep OpenEXR: give -o a .exr file, not " + output.string());
  }
  const Scene scene = load_scene(o.scene);

  OutputMetadata meta;
  meta.lensmith_version = LENSMITH_VERSION;
  meta.extra = {{"scene", o.scene}};
  Image rgb;
  std::string summary;
  if (o.pinhole) {
    PinholeFrameOptions framing;
    framing.sensor_width_mm = o.sensor_width_mm;
    const PinholeFrame frame =
        PinholeFrame::from_options(o.width_px, o.height_px, framing, o.pinhole_focal_length_mm.value_or(kDefaultPinholeFocalMm));
    PinholeRenderOptions options;
    options.threads = o.threads;
    meta.model = "pinhole";
    meta.extra.push_back({"frame", frame.to_string()});
    // The framing, which lensmith bokeh reads back (unless its flags say otherwise).
    meta.extra.push_back({"focal_length_mm", format_number(o.pinhole_focal_length_mm.value_or(kDefaultPinholeFocalMm))});
    meta.extra.push_back({"sensor_width_mm", format_number(o.sensor_width_mm)});
    if (o.layers > 0) {
      const DeepImage deep = render_pinhole_layers(scene, frame, o.layers, options);
      meta.model = "pinhole, " + std::to_string(o.layers) + " peeled layers";
      meta.extra.push_back({"layers", std::to_string(o.layers)});
      write_deep_image(output, deep, meta);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      std::ostringstream what;
      what << output.string() << " (" << deep.width << " x " << deep.height << ", deep) in " << std::fixed << std::setprecision(2)
           << seconds << " s\n  pinhole, focal length " << format_rounded(frame.focal_length_px(), 5) << " px, up to " << o.layers
           << " surfaces per ray: " << deep.to_string();
      report_written(what.str(), global);
      return kExitOk;
    }
    PinholeRender out = render_pinhole(scene, frame, options);
    rgb = std::move(out.rgb);
    if (!o.depth.empty()) write_depth(o.depth, out.depth);
    summary = "pinhole, focal length " + format_rounded(frame.focal_length_px(), 5) + " px, horizontal field of view " +
              format_rounded(frame.horizontal_fov_deg(), 4) + " deg";
  } else {
    if (!o.focus_m) throw UsageError("rendering through a lens needs --focus M (metres from the entrance pupil)");
    CameraOptions camera_options;
    camera_options.focus_distance_m = *o.focus_m;
    camera_options.f_number = o.f_number;
    camera_options.framing.sensor_width_mm = o.sensor_width_mm;
    camera_options.framing.focal_length_mm = o.pinhole_focal_length_mm;
    LensRenderOptions options;
    options.spp = o.spp;
    options.noise_target = o.noise_target;
    options.max_spp = o.max_spp.value_or(std::max(options.max_spp, o.spp));
    options.threads = o.threads;
    options.spectral = !o.no_spectral;
    options.spectral_samples = o.spectral_samples;
    options.seed = o.seed;
    options.validate();
    ProgressBar bar("scene", !global.quiet);
    options.progress = [&bar](double f) { bar.update(f); };
    std::optional<Camera> camera;
    LensRender out;
    int squeezed_width = 0;
    if (o.thin_lens) {
      if (!o.focal_length_mm) throw UsageError("--thin-lens needs --focal-length MM");
      camera = CameraSpec{*o.focal_length_mm, camera_options, o.width_px, o.height_px}.camera(RayModelKind::Thin, nullptr);
      meta.lens = "thin lens f = " + format_number(*o.focal_length_mm) + " mm";
      meta.model = "thin lens ground truth";
      out = render_through_thin_lens(scene, *camera, options);
    } else {
      const Prescription lens = load_lens(o.lens, global);
      meta.lens = lens.name.empty() ? o.lens : lens.name;
      meta.model = "exact trace ground truth";
      camera = CameraSpec{std::nullopt, camera_options, o.width_px, o.height_px}.camera(RayModelKind::Exact, &lens);
      warn_about_aperture(*camera, global);
      squeezed_width = anamorphic_output_width(*camera, o.width_px, o.desqueeze, global);
      out = render_through_lens(scene, *camera, options);
    }
    bar.finish();
    // The spectral estimator is unbiased but a single wavelength's RGB has negative components, so a
    // noisy pixel can fall below 0; files hold radiance (>= 0, as read_radiance_image requires).
    std::size_t clamped = 0;
    for (float& v : out.rgb.data) {
      if (v < 0.0f) {
        v = 0.0f;
        ++clamped;
      }
    }
    meta.f_number = camera->f_number();
    meta.focus_m = *o.focus_m;
    meta.extra.push_back({"spp", std::to_string(out.spp_used)});
    meta.extra.push_back({"estimated_relative_error", format_number(out.estimated_relative_error)});
    meta.extra.push_back({"seed", std::to_string(o.seed)});
    meta.extra.push_back(
        {"spectral", options.spectral && !o.thin_lens ? std::to_string(options.spectral_samples) + " nodes" : "off"});
    meta.extra.push_back({"rays", out.rays.to_string()});
    meta.extra.push_back({"negative_values_clamped", std::to_string(clamped)});
    meta.extra.push_back({"frame", camera->frame().to_string()});
    std::ostringstream s;
    s << meta.lens << ", f/" << format_rounded(camera->f_number(), 3) << ", focus " << format_rounded(*o.focus_m, 4) << " m, "
      << out.spp_used << " samples per pixel, estimated relative error " << format_rounded(out.estimated_relative_error, 2)
      << "\n  rays: " << out.rays.to_string();
    if (clamped > 0) s << "\n  " << clamped << " negative channel values (spectral noise) clamped to 0: raise --spp";
    summary = s.str();
    rgb = std::move(out.rgb);
    if (squeezed_width > 0) {
      // As the sensor records it (the picture rendered at the input's framing, each sensor pixel
      // integrating its share of a row); viewers desqueeze by the pixel aspect ratio.
      rgb.data = squeeze_columns(rgb.data, rgb.width, rgb.height, rgb.channels, squeezed_width);
      meta.camera.emplace_back("PixelAspectRatio", static_cast<double>(rgb.width) / squeezed_width);
      rgb.width = squeezed_width;
    }
  }
  write_output_image(output, rgb, meta);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  std::ostringstream what;
  what << output.string() << (o.depth.empty() ? std::string() : " and " + o.depth) << " (" << rgb.width << " x " << rgb.height
       << ") in " << std::fixed << std::setprecision(2) << seconds << " s\n  " << summary;
  report_written(what.str(), global);
  return kExitOk;
}

}  // namespace lensmith::cli

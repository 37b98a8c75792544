// `lensmith validate`: how close the fast ray models come to the exact tracer, in numbers and
// pictures (docs/validation.md): PSFs against exact forward tracing, and with --scene whole pictures
// of `lensmith bokeh` against analytic scenes rendered through the lens.
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "commands.h"
#include "lensmith/camera/camera_spec.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/text_file.h"
#include "lensmith/plot/canvas.h"
#include "lensmith/render/image_io.h"
#include "lensmith/validate/image_validation.h"
#include "lensmith/validate/psf_validation.h"

namespace lensmith::cli {

int run_validate(const ValidateCommandOptions& o, const GlobalOptions& global) {
  const Prescription lens = load_lens(o.lens, global);
  CameraOptions camera_options;
  camera_options.focus_distance_m = o.focus_m;
  camera_options.f_number = o.f_number;
  const Camera camera = CameraSpec{std::nullopt, camera_options, o.width_px, o.height_px}.camera(RayModelKind::Exact, &lens);
  warn_about_aperture(camera, global);
  std::vector<RayModelKind> models;
  for (const std::string& m : o.models) models.push_back(parse_ray_model_kind(m));
  PsfValidationOptions psf;
  psf.pupil_samples_per_axis = o.pupil_samples;
  RayModelOptions model_options;
  model_options.fit = fit_for_models(models, camera, o.fit, global);
  model_options.nearest_depth_m = std::isinf(o.focus_m) ? 1.0 : std::max(0.05, 0.4 * o.focus_m);
  model_options.seidel_coefficients = parse_seidel_coefficients(o.seidel_coefficients);
  const PsfValidation result = validate_point_spreads(camera, models, Aperture::circular(), psf, model_options);
  const std::string psf_tables = result.to_markdown();

  const std::filesystem::path dir = o.out;
  std::filesystem::create_directories(dir);
  OutputMetadata meta;
  meta.lens = lens.name;
  meta.f_number = camera.f_number();
  meta.focus_m = o.focus_m;
  meta.model = "exact | model | difference";
  write_output_image(dir / "psf.png",
                     psf_grid_figure(camera, models, Aperture::circular(), psf, model_options, plot::Canvas::find_default_font().value_or("")),
                     meta);

  std::ostringstream report;
  report << "# lensmith validate: " << lens.name << "\n\n"
         << "f/" << camera.f_number() << ", focused at " << o.focus_m << " m (sensor at z = " << std::fixed
         << std::setprecision(4) << camera.z_sensor_mm() << " mm), frame " << o.width_px << " x " << o.height_px
         << " px on a 36 mm sensor.\n\n"
         << "## PSF level: each model against exact forward tracing\n\n"
         << "Fields are fractions of the frame's half-width; PSFs from a " << psf.pupil_samples_per_axis << " x "
         << psf.pupil_samples_per_axis << " pupil grid, compared on " << psf.bins << " x " << psf.bins
         << " bins over a window at least " << psf.min_half_width_px
         << " output pixels either side of the exact centroid (overlap = 1 - L1/2 of the normalised PSFs).\n\n"
         << psf_tables << "\n![PSFs: exact | model | difference, per model](psf.png)\n\n"
         << "## Image level\n\n";
  ImageValidation images;
  if (o.scenes.empty()) {
    report << "No scene given (`--scene FILE`, e.g. examples/scenes/*.json): skipped.\n";
  } else {
    ImageValidationOptions image_options;
    for (const std::string& s : o.scenes) image_options.scenes.emplace_back(s);
    image_options.models = models;
    image_options.fit = model_options.fit;
    image_options.seidel_coefficients = model_options.seidel_coefficients;
    image_options.width_px = o.image_width_px;
    image_options.height_px = o.image_height_px;
    image_options.spp = o.image_spp;
    image_options.layers = o.image_layers;
    image_options.methods = o.image_methods;
    image_options.multiview_samples = o.image_samples;
    image_options.lightfield_views = o.image_views;
    image_options.gather_trace_rays = o.image_trace_rays;
    image_options.picture_dir = dir;
    images = validate_images(lens, camera_options, image_options);
    report << "`lensmith bokeh` with each model and method (scatter; multiview with " << o.image_samples
           << " lens rays per pixel; lightfield with " << o.image_views << " views and ewa, flat input only; gather on the flat input and as "
           << "Tan et al.'s hybrid, with up to " << o.image_trace_rays
           << " exact rays per half-resolution pixel traced into the scene where its ray mask says, input `flat + traced rays`) on the pinhole render of each scene"
           << (o.image_layers > 0 ? " (flat: picture and depth) and on its " + std::to_string(o.image_layers) +
                                        " depth-peeled layers as a deep image (layered)"
                                  : std::string())
           << ", against the scene rendered through the lens by the exact tracer (" << o.image_spp << " samples per pixel), "
           << o.image_width_px << " x " << o.image_height_px << " px; PSNR and SSIM on x/(1+x) values, "
           << "over the frame and within " << image_options.band_radius_px << " px of depth edges. Pictures: "
           << "`<scene>-truth.png`, `<scene>-<model>[-<method>][-layered|-traced].png` and its `-error.png`; time: the render alone.\n\n"
           << images.to_markdown();
  }
  const std::string text = report.str();
  write_file_atomically((dir / "report.md").string(), text);

  std::cout << psf_tables.substr(0, psf_tables.find("\n\n")) << "\n";
  if (!images.entries.empty()) std::cout << "\n" << images.to_markdown();
  report_written((dir / "report.md").string() + " and " + (dir / "psf.png").string(), global);
  bool failed = false;
  for (const PsfModelSummary& s : result.summaries) {
    if (o.min_overlap && s.worst_overlap < *o.min_overlap) {
      std::cerr << "lensmith validate: " << to_string(s.model) << " worst PSF overlap " << s.worst_overlap
                << " is below --min-overlap " << *o.min_overlap << "\n";
      failed = true;
    }
    if (o.max_centroid_offset_um && s.max_centroid_offset_um > *o.max_centroid_offset_um) {
      std::cerr << "lensmith validate: " << to_string(s.model) << " centroid offset " << s.max_centroid_offset_um
                << " um exceeds --max-centroid-offset " << *o.max_centroid_offset_um << "\n";
      failed = true;
    }
  }
  for (const ImageValidationEntry& e : images.entries) {
    if (o.min_edge_psnr_db && e.comparison.edge_psnr_db < *o.min_edge_psnr_db) {
      std::cerr << "lensmith validate: " << to_string(e.model) << " (" << e.method << ", " << e.input << ") on " << e.scene << ": edge PSNR "
                << e.comparison.edge_psnr_db << " dB is below --min-edge-psnr " << *o.min_edge_psnr_db << "\n";
      failed = true;
    }
  }
  return failed ? kExitThreshold : kExitOk;
}

}  // namespace lensmith::cli

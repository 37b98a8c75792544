#include "lensmith/validate/image_validation.h"

#include <iomanip>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/render/bokeh_renderer.h"
#include "lensmith/render/image_io.h"
#include "lensmith/scene/lens_render.h"
#include "lensmith/scene/pinhole_render.h"
#include "lensmith/scene/scene_json.h"

namespace lensmith {

void ImageValidationOptions::validate() const {
  if (width_px < 16 || height_px < 16) throw OptionsError("image validation needs frames of at least 16 x 16 px");
  if (spp < 1) throw OptionsError("ground-truth samples per pixel must be >= 1");
  if (!(band_radius_px > 0.0)) throw OptionsError("the depth-edge band radius must be > 0 px");
  for (RayModelKind k : models) {
    if (k == RayModelKind::Exact || k == RayModelKind::Thin) {
      throw OptionsError("image validation scores paraxial, seidel or poly, not " + std::string(to_string(k)));
    }
  }
}

ImageValidation validate_images(const Prescription& lens, const CameraOptions& camera_options, const ImageValidationOptions& options) {
  options.validate();
  ImageValidation out;
  for (const std::filesystem::path& file : options.scenes) {
    const Scene scene = load_scene(file);
    const std::string name = file.stem().string();
    const Camera camera = Camera::from_lens(lens, camera_options, options.width_px, options.height_px);
    PinholeRenderOptions pinhole_options;
    pinhole_options.threads = options.threads;
    const PinholeRender pinhole = render_pinhole(scene, camera.frame(), pinhole_options);
    LensRenderOptions truth_options;
    truth_options.spp = options.spp;
    truth_options.threads = options.threads;
    const LensRender truth = render_through_lens(scene, camera, truth_options);
    out.scenes.push_back(name);
    out.unblurred.push_back(compare_images(pinhole.rgb, truth.rgb, pinhole.depth, options.band_radius_px));
    float nearest_m = std::numeric_limits<float>::infinity();
    for (float z : pinhole.depth.z_m) nearest_m = std::min(nearest_m, z);
    RayModelOptions model_options;
    model_options.fit = options.fit;
    model_options.seidel_coefficients = options.seidel_coefficients;
    model_options.nearest_depth_m = std::isfinite(nearest_m) ? std::max(0.01, static_cast<double>(nearest_m)) : 1.0;
    OutputMetadata meta;
    meta.lens = lens.name;
    meta.f_number = camera.f_number();
    meta.focus_m = camera_options.focus_distance_m;
    if (!options.picture_dir.empty()) {
      std::filesystem::create_directories(options.picture_dir);
      meta.model = "exact (ground truth)";
      write_output_image(options.picture_dir / (name + "-truth.png"), truth.rgb, meta);
    }
    for (RayModelKind kind : options.models) {
      const auto model = make_ray_model(kind, camera, model_options);
      BokehOptions bokeh;
      bokeh.threads = options.threads;
      const Image result = render_bokeh(pinhole.rgb, pinhole.depth, *model, Aperture::circular(), bokeh);
      out.entries.push_back({name, kind, compare_images(result, truth.rgb, pinhole.depth, options.band_radius_px)});
      if (!options.picture_dir.empty()) {
        meta.model = std::string(to_string(kind));
        write_output_image(options.picture_dir / (name + "-" + meta.model + ".png"), result, meta);
        write_output_image(options.picture_dir / (name + "-" + meta.model + "-error.png"), error_map(result, truth.rgb), meta);
      }
    }
  }
  return out;
}

std::string ImageValidation::to_markdown() const {
  std::ostringstream os;
  os << std::fixed;
  os << "| scene | model | PSNR (dB) | SSIM | edge PSNR (dB) | edge SSIM |\n|---|---|---|---|---|---|\n";
  auto row = [&os](const std::string& scene, const std::string& model, const ImageComparison& c) {
    os << "| " << scene << " | " << model << " | " << std::setprecision(2) << c.psnr_db << " | " << std::setprecision(4)
       << c.ssim << " | " << std::setprecision(2) << c.edge_psnr_db << " | " << std::setprecision(4) << c.edge_ssim << " |\n";
  };
  for (std::size_t s = 0; s < scenes.size(); ++s) {
    row(scenes[s], "(input, unblurred)", unblurred[s]);
    for (const ImageValidationEntry& e : entries) {
      if (e.scene == scenes[s]) row(e.scene, std::string(to_string(e.model)), e.comparison);
    }
  }
  return os.str();
}

}  // namespace lensmith

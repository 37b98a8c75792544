#include "lensmith/validate/image_validation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <iomanip>
#include <optional>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "lensmith/plot/canvas.h"
#include "lensmith/render/bokeh_renderer.h"
#include "lensmith/render/deep_image.h"
#include "lensmith/render/image_io.h"
#include "lensmith/render/ewa_renderer.h"
#include "lensmith/render/gather_renderer.h"
#include "lensmith/render/lightfield_renderer.h"
#include "lensmith/render/multiview_renderer.h"
#include "lensmith/scene/lens_render.h"
#include "lensmith/scene/pinhole_render.h"
#include "lensmith/scene/scene_json.h"

namespace lensmith {

void ImageValidationOptions::validate() const {
  if (width_px < 16 || height_px < 16) throw OptionsError("image validation needs frames of at least 16 x 16 px");
  if (spp < 1) throw OptionsError("ground-truth samples per pixel must be >= 1");
  if (!(band_radius_px > 0.0)) throw OptionsError("the depth-edge band radius must be > 0 px");
  if (layers < 0 || layers > kMaxPeeledLayers) {
    throw OptionsError("layered input needs 1.." + std::to_string(kMaxPeeledLayers) + " layers (0: flat only), got " + std::to_string(layers));
  }
  for (const std::string& m : methods) {
    if (m != "scatter" && m != "multiview" && m != "lightfield" && m != "ewa" && m != "gather") {
      throw OptionsError("image validation methods are scatter, multiview, lightfield, ewa and gather, not " + m);
    }
  }
  if (multiview_samples < 1 || multiview_samples > 4096) throw OptionsError("multiview samples must be 1 to 4096");
  if (lightfield_views < 1 || lightfield_views > 1024) throw OptionsError("lightfield views must be 1 to 1024");
  if (gather_trace_rays < 1 || gather_trace_rays > 4096) throw OptionsError("gather trace rays must be 1 to 4096 per pixel");
  for (RayModelKind k : models) {
    if (k == RayModelKind::Exact || k == RayModelKind::Thin) {
      throw OptionsError("image validation scores paraxial, seidel or poly, not " + std::string(to_string(k)));
    }
  }
}

namespace {

// The input of gather's hybrid run (Tan et al.): the flat picture and rays into the scene.
constexpr const char* kTracedInput = "flat + traced rays";

// Pixels where hidden surfaces can show in the picture through the lens: those whose first surface
// hides most of another (two or more samples, the first of alpha >= 0.5), widened by half the
// largest blur diameter of the hidden ones (a square, capped at kMaxHiddenReachPx).
constexpr double kMaxHiddenReachPx = 64.0;
std::vector<std::uint8_t> hidden_surface_region(const DeepImage& layers, const Camera& camera) {
  const int w = layers.width, h = layers.height;
  std::vector<std::uint8_t> seed(static_cast<std::size_t>(w) * h, 0);
  double reach = 0.0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const auto p = layers.pixel(x, y);
      if (p.size() < 2 || p.front().alpha < 0.5f) continue;
      seed[static_cast<std::size_t>(y) * w + x] = 1;
      for (std::size_t k = 1; k < p.size(); ++k) {
        reach = std::max(reach, 0.5 * std::abs(camera.signed_coc_px(inverse_depth_per_mm(p[k].z_m))));
      }
    }
  }
  const int r = static_cast<int>(std::ceil(std::min(reach, kMaxHiddenReachPx)));
  // Separable square dilation by r: rows, then columns.
  std::vector<std::uint8_t> rows(seed.size(), 0), out(seed.size(), 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (!seed[static_cast<std::size_t>(y) * w + x]) continue;
      for (int i = std::max(0, x - r); i <= std::min(w - 1, x + r); ++i) rows[static_cast<std::size_t>(y) * w + i] = 1;
    }
  }
  for (int x = 0; x < w; ++x) {
    for (int y = 0; y < h; ++y) {
      if (!rows[static_cast<std::size_t>(y) * w + x]) continue;
      for (int j = std::max(0, y - r); j <= std::min(h - 1, y + r); ++j) out[static_cast<std::size_t>(j) * w + x] = 1;
    }
  }
  return out;
}

// The scene's pictures side by side, `<scene>-methods.png`: per model a row of its methods'
// pictures (the truth first) and under it a row of their error maps, each labelled with its model,
// method and input and with its PSNR over the frame and the depth-edge band.
void write_contact_sheet(const std::filesystem::path& dir, const std::string& scene, const std::vector<ImageValidationEntry>& entries,
                         const std::vector<std::string>& stems) {
  constexpr int kPad = 4, kLabel = 18;
  constexpr double kFontPx = 12.0;
  const plot::Canvas truth = plot::Canvas::read_image((dir / (scene + "-truth.png")).string());
  const int cw = truth.width(), ch = truth.height();
  std::vector<RayModelKind> models;
  std::vector<std::vector<std::size_t>> rows;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const auto at = std::find(models.begin(), models.end(), entries[i].model);
    if (at == models.end()) {
      models.push_back(entries[i].model);
      rows.push_back({i});
    } else {
      rows[static_cast<std::size_t>(at - models.begin())].push_back(i);
    }
  }
  std::size_t columns = 0;
  for (const auto& row : rows) columns = std::max(columns, row.size() + 1);
  const int cell_w = cw + kPad, cell_h = ch + kLabel + kPad;
  plot::Canvas sheet(static_cast<int>(columns) * cell_w + kPad, static_cast<int>(rows.size()) * 2 * cell_h + kPad, plot::kWhite);
  sheet.set_font(plot::Canvas::find_default_font());
  auto place = [&](const plot::Canvas& picture, int column, int row, const std::string& label) {
    const int x0 = kPad + column * cell_w, y0 = kPad + row * cell_h;
    sheet.text({static_cast<double>(x0), static_cast<double>(y0 + kLabel - 5)}, label, kFontPx, plot::kBlack);
    sheet.paste(picture, x0, y0 + kLabel);
  };
  std::ostringstream psnr;
  psnr << std::fixed << std::setprecision(2);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    place(truth, 0, static_cast<int>(2 * r), "truth (exact tracer)");
    for (std::size_t k = 0; k < rows[r].size(); ++k) {
      const ImageValidationEntry& e = entries[rows[r][k]];
      const std::string& stem = stems[rows[r][k]];
      place(plot::Canvas::read_image((dir / (stem + ".png")).string()), static_cast<int>(k + 1), static_cast<int>(2 * r),
            std::string(to_string(e.model)) + ", " + e.method + ", " + e.input);
      psnr.str("");
      psnr << "error: " << e.comparison.psnr_db << " dB, edge " << e.comparison.edge_psnr_db << " dB";
      place(plot::Canvas::read_image((dir / (stem + "-error.png")).string()), static_cast<int>(k + 1), static_cast<int>(2 * r + 1), psnr.str());
    }
  }
  sheet.write_png((dir / (scene + "-methods.png")).string());
}

}  // namespace

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
    const std::size_t first_entry = out.entries.size();
    std::vector<std::string> stems;  // of this scene's entries' pictures
    std::optional<DeepImage> layered;
    if (options.layers > 0) layered = render_pinhole_layers(scene, camera.frame(), options.layers, pinhole_options);
    const std::string layered_input = "layered " + std::to_string(options.layers);
    std::vector<std::uint8_t> hidden_region;
    if (layered) hidden_region = hidden_surface_region(*layered, camera);
    std::size_t hidden_count = 0;
    for (std::uint8_t m : hidden_region) hidden_count += m;
    out.hidden_pixels.push_back(hidden_count);
    for (RayModelKind kind : options.models) {
      const auto model = make_ray_model(kind, camera, model_options);
      BokehOptions bokeh;
      bokeh.threads = options.threads;
      MultiviewOptions multiview;
      multiview.threads = options.threads;
      multiview.samples = options.multiview_samples;
      std::optional<DeepImage> flat_scene;
      LightfieldOptions lightfield;
      lightfield.threads = options.threads;
      lightfield.views = options.lightfield_views;
      EwaOptions ewa;
      ewa.threads = options.threads;
      GatherOptions gather;
      gather.threads = options.threads;
      for (const std::string& method : options.methods) {
        const bool lee = method == "multiview", yu = method == "lightfield", krivanek = method == "ewa", jimenez = method == "gather";
        if (lee && !flat_scene) flat_scene = deep_image_from_flat(pinhole.rgb, pinhole.depth);
        for (const bool deep : {false, true}) {
          // lightfield, ewa: one surface per pixel; gather's second run is Tan et al.'s hybrid, the
          // flat picture with rays traced into the scene where the ray mask says.
          if (deep && (yu || krivanek || (!layered && !jimenez))) continue;
          const auto started = std::chrono::steady_clock::now();
          Image result;
          if (yu) {
            result = render_lightfield(pinhole.rgb, pinhole.depth, *model, Aperture::circular(), lightfield);
          } else if (krivanek) {
            result = render_ewa(pinhole.rgb, pinhole.depth, *model, Aperture::circular(), ewa);
          } else if (jimenez) {
            GatherOptions run = gather;
            if (deep) {
              run.trace_rays = options.gather_trace_rays;
              run.trace = [&](std::vector<GatherTraceRequest>& requests) {
                LensRenderOptions rays;
                rays.threads = options.threads;
                trace_regions(scene, camera, requests, rays);
              };
            }
            result = render_gather(pinhole.rgb, pinhole.depth, *model, Aperture::circular(), run);
          } else if (lee) {
            result = render_multiview(deep ? *layered : *flat_scene, *model, Aperture::circular(), multiview).leading_channels(3);
          } else {
            result = deep ? render_bokeh(*layered, *model, Aperture::circular(), bokeh)
                          : render_bokeh(pinhole.rgb, pinhole.depth, *model, Aperture::circular(), bokeh);
          }
          const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
          // Both scored on the same band: the flat picture's depth edges.
          const double hidden_psnr = hidden_count > 0 ? psnr(result, truth.rgb, &hidden_region) : std::numeric_limits<double>::quiet_NaN();
          const std::string input = !deep ? std::string("flat") : jimenez ? std::string(kTracedInput) : layered_input;
          out.entries.push_back({name, kind, method, input,
                                 compare_images(result, truth.rgb, pinhole.depth, options.band_radius_px), hidden_psnr, seconds});
          if (!options.picture_dir.empty()) {
            const std::string method_tag = method == "scatter" ? std::string() : "-" + method;
            meta.model = std::string(to_string(kind)) + (method == "scatter" ? std::string() : ", " + method) +
                         (deep ? ", " + input : std::string());
            const std::string stem = name + "-" + std::string(to_string(kind)) + method_tag + (deep ? (jimenez ? "-traced" : "-layered") : "");
            write_output_image(options.picture_dir / (stem + ".png"), result, meta);
            write_output_image(options.picture_dir / (stem + "-error.png"), error_map(result, truth.rgb), meta);
            stems.push_back(stem);
          }
        }
      }
    }
    if (!options.picture_dir.empty()) {
      write_contact_sheet(options.picture_dir, name,
                          std::vector<ImageValidationEntry>(out.entries.begin() + static_cast<std::ptrdiff_t>(first_entry), out.entries.end()),
                          stems);
    }
  }
  return out;
}

std::string ImageValidation::to_markdown() const {
  std::ostringstream os;
  os << std::fixed;
  os << "| scene | model | method | input | PSNR (dB) | SSIM | edge PSNR (dB) | edge SSIM | hidden-surface PSNR (dB) | time (s) |\n"
     << "|---|---|---|---|---|---|---|---|---|---|\n";
  auto row = [&os](const std::string& scene, const std::string& model, const std::string& method, const std::string& input,
                   const ImageComparison& c, double hidden_psnr, const std::string& time) {
    os << "| " << scene << " | " << model << " | " << method << " | " << input << " | " << std::setprecision(2) << c.psnr_db << " | "
       << std::setprecision(4) << c.ssim << " | " << std::setprecision(2) << c.edge_psnr_db << " | " << std::setprecision(4)
       << c.edge_ssim << " | ";
    if (std::isnan(hidden_psnr)) {
      os << "-";
    } else {
      os << std::setprecision(2) << hidden_psnr;
    }
    os << " | " << time << " |\n";
  };
  for (std::size_t s = 0; s < scenes.size(); ++s) {
    row(scenes[s], "(unblurred)", "-", "flat", unblurred[s], std::numeric_limits<double>::quiet_NaN(), "");
    for (const ImageValidationEntry& e : entries) {
      if (e.scene != scenes[s]) continue;
      std::ostringstream t;
      t << std::fixed << std::setprecision(2) << e.seconds;
      row(e.scene, std::string(to_string(e.model)), e.method, e.input, e.comparison, e.hidden_psnr_db, t.str());
    }
  }
  for (std::size_t s = 0; s < scenes.size() && s < hidden_pixels.size(); ++s) {
    os << "\n" << scenes[s] << ": " << hidden_pixels[s] << " pixels where hidden surfaces can show";
  }
  if (!hidden_pixels.empty()) os << "\n";
  return os.str();
}

}  // namespace lensmith

#include "lensmith/validate/psf_validation.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <memory>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "lensmith/plot/canvas.h"
#include "lensmith/plot/plot_axes.h"
#include "lensmith/render/image_io.h"

namespace lensmith {

namespace {

std::vector<double> depths_for(const Camera& camera, const PsfValidationOptions& options) {
  if (!options.depths_m.empty()) return options.depths_m;
  const double focus = m_from_mm(camera.focus_distance_mm());
  if (std::isinf(focus)) return {1.0, 3.0, 10.0, kInfinity};
  return {0.5 * focus, 0.8 * focus, focus, 2.0 * focus, kInfinity};
}

ScenePoint scene_point(const Camera& camera, double relative_field, double depth_m) {
  const double tan_x = relative_field * 0.5 * camera.frame().width_px() / camera.frame().focal_length_px();
  return {tan_x, 0.0, inverse_depth_per_mm(depth_m)};
}

std::string depth_text(double depth_m) {
  if (std::isinf(depth_m)) return "inf";
  std::ostringstream os;
  os << std::setprecision(4) << depth_m;
  return os.str();
}

}  // namespace

void PsfValidationOptions::validate() const {
  for (double f : relative_fields) {
    if (!(f >= 0.0 && f <= 1.0)) throw OptionsError("relative fields must lie in 0..1");
  }
  for (double d : depths_m) {
    if (!(d > 0.0)) throw OptionsError("PSF depths must be > 0 m (inf allowed)");
  }
  for (double w : wavelengths_nm) {
    if (!(w >= 380.0 && w <= 780.0)) throw OptionsError("PSF wavelengths must lie in 380..780 nm");
  }
  if (relative_fields.empty() || wavelengths_nm.empty()) throw OptionsError("give at least one field and one wavelength");
  if (pupil_samples_per_axis < 2 || pupil_samples_per_axis > 512) throw OptionsError("pupil samples per axis must be 2..512");
  if (bins < 2 || bins > 512) throw OptionsError("bins must be 2..512");
  if (!(min_half_width_px >= 0.0 && std::isfinite(min_half_width_px))) throw OptionsError("min half width must be >= 0 px");
}

PsfValidation validate_point_spreads(const Camera& camera, const std::vector<RayModelKind>& models,
                                     const Aperture& aperture, const PsfValidationOptions& options,
                                     const RayModelOptions& model_options) {
  options.validate();
  if (camera.is_thin_lens()) throw OptionsError("PSF validation needs a lens prescription (the exact model traces it)");
  const auto exact = make_ray_model(RayModelKind::Exact, camera, model_options);
  std::vector<std::unique_ptr<RayModel>> fast;
  for (RayModelKind k : models) {
    if (k == RayModelKind::Exact || k == RayModelKind::Thin) {
      throw OptionsError("PSF validation compares paraxial, seidel or poly with exact, not " + std::string(to_string(k)));
    }
    fast.push_back(make_ray_model(k, camera, model_options));
  }
  const double min_half_width_mm = options.min_half_width_px / std::abs(camera.px_per_sensor_mm());
  PsfValidation out;
  for (double field : options.relative_fields) {
    for (double depth : depths_for(camera, options)) {
      const ScenePoint point = scene_point(camera, field, depth);
      for (double wavelength : options.wavelengths_nm) {
        const PointSpread reference = trace_point_spread(*exact, point, wavelength, aperture, options.pupil_samples_per_axis);
        for (std::size_t m = 0; m < fast.size(); ++m) {
          PsfValidationEntry e;
          e.relative_field = field;
          e.depth_m = depth;
          e.wavelength_nm = wavelength;
          e.model = models[m];
          e.exact_rms_radius_um = um_from_mm(reference.rms_radius_mm);
          e.exact_transmitted = reference.transmitted();
          if (!reference.x_mm.empty()) {
            const PointSpread model = trace_point_spread(*fast[m], point, wavelength, aperture, options.pupil_samples_per_axis);
            e.comparison = compare_point_spreads(reference, model, options.bins, min_half_width_mm);
            e.compared = true;
          }
          out.entries.push_back(e);
        }
      }
    }
  }
  for (RayModelKind k : models) {
    PsfModelSummary s;
    s.model = k;
    double sum = 0.0;
    for (const PsfValidationEntry& e : out.entries) {
      if (e.model != k || !e.compared) continue;
      ++s.compared;
      sum += e.comparison.overlap;
      s.worst_overlap = std::min(s.worst_overlap, e.comparison.overlap);
      s.max_centroid_offset_um = std::max(s.max_centroid_offset_um, e.comparison.centroid_offset_um);
      if (std::isfinite(e.comparison.rms_radius_ratio)) {
        s.worst_rms_ratio_error = std::max(s.worst_rms_ratio_error, std::abs(e.comparison.rms_radius_ratio - 1.0));
      }
    }
    s.mean_overlap = s.compared ? sum / static_cast<double>(s.compared) : 0.0;
    out.summaries.push_back(s);
  }
  return out;
}

std::string PsfValidation::to_markdown() const {
  std::ostringstream os;
  os << std::fixed;
  os << "| model | PSFs compared | mean overlap | worst overlap | max centroid offset (um) | worst RMS-radius ratio error |\n"
     << "|---|---|---|---|---|---|\n";
  for (const PsfModelSummary& s : summaries) {
    os << "| " << to_string(s.model) << " | " << s.compared << " | " << std::setprecision(4) << s.mean_overlap << " | "
       << s.worst_overlap << " | " << std::setprecision(2) << s.max_centroid_offset_um << " | " << std::setprecision(1)
       << 100.0 * s.worst_rms_ratio_error << " % |\n";
  }
  os << "\n| field | depth (m) | wavelength (nm) | model | exact RMS radius (um) | exact rays passing | centroid offset (um) | RMS ratio | overlap |\n"
     << "|---|---|---|---|---|---|---|---|---|\n";
  for (const PsfValidationEntry& e : entries) {
    os << "| " << std::setprecision(2) << e.relative_field << " | " << depth_text(e.depth_m) << " | " << std::setprecision(1)
       << e.wavelength_nm << " | " << to_string(e.model) << " | " << std::setprecision(2) << e.exact_rms_radius_um << " | "
       << std::setprecision(3) << e.exact_transmitted << " | ";
    if (e.compared) {
      os << std::setprecision(2) << e.comparison.centroid_offset_um << " | " << std::setprecision(3)
         << e.comparison.rms_radius_ratio << " | " << std::setprecision(4) << e.comparison.overlap << " |\n";
    } else {
      os << "- | - | - |\n";
    }
  }
  return os.str();
}

namespace {

// One row of the PSF grid: which point it shows and the comparison window's half-width.
struct PsfGridRow {
  double relative_field = 0.0;
  double depth_m = 0.0;
  double half_width_mm = 0.0;  // 0 when the exact model lost every ray (an empty row)
};

struct PsfGrid {
  Image tiles;
  int tile = 0;  // tile side, px
  int gap = 0;   // between tiles and around the block, px
  std::vector<PsfGridRow> rows;
};

PsfGrid psf_grid(const Camera& camera, const std::vector<RayModelKind>& models, const Aperture& aperture,
                 const PsfValidationOptions& options, const RayModelOptions& model_options) {
  options.validate();
  const auto exact = make_ray_model(RayModelKind::Exact, camera, model_options);
  std::vector<std::unique_ptr<RayModel>> fast;
  for (RayModelKind k : models) fast.push_back(make_ray_model(k, camera, model_options));
  const std::vector<double> depths = depths_for(camera, options);
  const int bins = options.bins, gap = 4;
  const int zoom = std::max(1, 96 / bins);  // tiles of about 96 px, whatever the bin count
  const int tile = bins * zoom;
  const int columns = 1 + 2 * static_cast<int>(models.size());
  const int rows = static_cast<int>(options.relative_fields.size() * depths.size());
  std::vector<PsfGridRow> rows_info;
  Image out(columns * (tile + gap) + gap, rows * (tile + gap) + gap, 3, 0.08f);
  const double wavelength = camera.reference_wavelength_nm();
  int row = 0;
  for (double field : options.relative_fields) {
    for (double depth : depths) {
      const ScenePoint point = scene_point(camera, field, depth);
      PsfGridRow info{field, depth, 0.0};
      const PointSpread reference = trace_point_spread(*exact, point, wavelength, aperture, options.pupil_samples_per_axis);
      auto put = [&](const Image& binned, int column, int channel_mask, float scale) {
        for (int y = 0; y < tile; ++y) {
          for (int x = 0; x < tile; ++x) {
            const float v = std::min(1.0f, binned.at(x / zoom, y / zoom, 0) * scale);
            for (int c = 0; c < 3; ++c) {
              out.at(gap + column * (tile + gap) + x, gap + row * (tile + gap) + y, c) = (channel_mask >> c & 1) ? v : 0.0f;
            }
          }
        }
      };
      if (!reference.x_mm.empty()) {
        std::vector<PointSpread> spreads;
        for (const auto& m : fast) spreads.push_back(trace_point_spread(*m, point, wavelength, aperture, options.pupil_samples_per_axis));
        double half = 0.0;
        const double min_half_width_mm = options.min_half_width_px / std::abs(camera.px_per_sensor_mm());
        for (const PointSpread& s : spreads) half = std::max(half, comparison_half_width_mm(reference, s, min_half_width_mm));
        info.half_width_mm = half;
        const Image ref = bin_point_spread(reference, reference.centroid_x_mm, reference.centroid_y_mm, half, bins);
        const float peak = *std::max_element(ref.data.begin(), ref.data.end());
        const float scale = peak > 0.0f ? 1.0f / peak : 1.0f;
        put(ref, 0, 7, scale);
        for (std::size_t m = 0; m < spreads.size(); ++m) {
          const Image mod = bin_point_spread(spreads[m], reference.centroid_x_mm, reference.centroid_y_mm, half, bins);
          Image diff = mod;
          for (std::size_t i = 0; i < diff.data.size(); ++i) diff.data[i] = std::abs(mod.data[i] - ref.data[i]);
          put(mod, 1 + 2 * static_cast<int>(m), 7, scale);
          put(diff, 2 + 2 * static_cast<int>(m), 1, scale);  // red
        }
      }
      rows_info.push_back(info);
      ++row;
    }
  }
  return {std::move(out), tile, gap, std::move(rows_info)};
}

}  // namespace

Image psf_grid_picture(const Camera& camera, const std::vector<RayModelKind>& models, const Aperture& aperture,
                       const PsfValidationOptions& options, const RayModelOptions& model_options) {
  return psf_grid(camera, models, aperture, options, model_options).tiles;
}

Image psf_grid_figure(const Camera& camera, const std::vector<RayModelKind>& models, const Aperture& aperture,
                      const PsfValidationOptions& options, const RayModelOptions& model_options, const std::string& font_path) {
  const PsfGrid grid = psf_grid(camera, models, aperture, options, model_options);
  constexpr double kFontPx = 13.0;
  const plot::Rgb kText{0.1f, 0.1f, 0.1f}, kNote{0.38f, 0.38f, 0.38f};
  const double label_width = 190.0, top = 60.0, bottom = 34.0;
  plot::Canvas canvas(static_cast<int>(label_width + grid.tiles.width + 10), static_cast<int>(top + grid.tiles.height + bottom));
  if (!font_path.empty()) canvas.set_font(font_path);
  // The tiles as they were encoded before (linear values shown through sRGB), on the white figure.
  for (int y = 0; y < grid.tiles.height; ++y) {
    for (int x = 0; x < grid.tiles.width; ++x) {
      const plot::Rgb c{srgb_encode(grid.tiles.at(x, y, 0)), srgb_encode(grid.tiles.at(x, y, 1)), srgb_encode(grid.tiles.at(x, y, 2))};
      canvas.fill_rect({label_width + x, top + y}, {label_width + x + 1.0, top + y + 1.0}, c);
    }
  }
  canvas.text({10.0, 8.0},
              "PSFs at " + plot::tick_label(camera.reference_wavelength_nm(), 0.1) +
                  " nm, each tile scaled to the exact PSF's peak; |diff| = |model - exact| in red",
              kFontPx, kText, plot::HAlign::Left, plot::VAlign::Top);
  // Column labels: exact, then each model and its difference.
  auto column_centre = [&](int column) { return label_width + grid.gap + column * (grid.tile + grid.gap) + 0.5 * grid.tile; };
  canvas.text({column_centre(0), top - 6.0}, "exact", kFontPx, kText, plot::HAlign::Centre, plot::VAlign::Bottom);
  for (std::size_t m = 0; m < models.size(); ++m) {
    canvas.text({column_centre(1 + 2 * static_cast<int>(m)), top - 6.0}, to_string(models[m]), kFontPx, kText, plot::HAlign::Centre,
                plot::VAlign::Bottom);
    canvas.text({column_centre(2 + 2 * static_cast<int>(m)), top - 6.0}, "|diff|", kFontPx, kText, plot::HAlign::Centre, plot::VAlign::Bottom);
  }
  // Row labels: the field and depth, the window, and a scale bar on the sensor in micrometres.
  for (std::size_t r = 0; r < grid.rows.size(); ++r) {
    const PsfGridRow& row = grid.rows[r];
    const double y0 = top + grid.gap + static_cast<double>(r) * (grid.tile + grid.gap);
    canvas.text({10.0, y0 + 4.0}, "field " + plot::tick_label(row.relative_field, 0.01) + ", depth " + depth_text(row.depth_m) + (std::isinf(row.depth_m) ? "" : " m"),
                kFontPx, kText, plot::HAlign::Left, plot::VAlign::Top);
    if (row.half_width_mm <= 0.0) {
      canvas.text({10.0, y0 + 24.0}, "no exact ray reaches the sensor", kFontPx * 0.9, kNote, plot::HAlign::Left, plot::VAlign::Top);
      continue;
    }
    const double window_um = um_from_mm(2.0 * row.half_width_mm);
    canvas.text({10.0, y0 + 24.0}, "tile " + plot::tick_label(window_um, window_um < 10.0 ? 0.01 : 0.1) + " \xC2\xB5m across", kFontPx * 0.9,
                kNote, plot::HAlign::Left, plot::VAlign::Top);
    const std::vector<double> ticks = plot::nice_ticks(0.0, window_um, 3);
    const double bar_um = ticks.size() > 1 ? ticks[1] - ticks[0] : window_um;
    const double bar_px = bar_um / window_um * grid.tile;
    const double by = y0 + 56.0;
    canvas.line({10.0, by}, {10.0 + bar_px, by}, plot::LineStyle{kText, 2.5});
    canvas.line({10.0, by - 4.0}, {10.0, by + 4.0}, plot::LineStyle{kText, 1.2});
    canvas.line({10.0 + bar_px, by - 4.0}, {10.0 + bar_px, by + 4.0}, plot::LineStyle{kText, 1.2});
    canvas.text({16.0 + bar_px, by}, plot::tick_label(bar_um, bar_um) + " \xC2\xB5m", kFontPx * 0.9, kText, plot::HAlign::Left,
                plot::VAlign::Middle);
  }
  canvas.text({10.0, canvas.height() - 10.0}, "field: fraction of the frame's half-width; depth: from the entrance pupil; scale bars: on the sensor",
              kFontPx * 0.9, kNote, plot::HAlign::Left, plot::VAlign::Bottom);
  Image out(canvas.width(), canvas.height(), 3);
  for (int y = 0; y < canvas.height(); ++y) {
    for (int x = 0; x < canvas.width(); ++x) {
      const plot::Rgb c = canvas.pixel(x, y);
      out.at(x, y, 0) = srgb_decode(c.r);
      out.at(x, y, 1) = srgb_decode(c.g);
      out.at(x, y, 2) = srgb_decode(c.b);
    }
  }
  return out;
}

}  // namespace lensmith

#include "lensmith/validate/psf_validation.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <memory>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"

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

Image psf_grid_picture(const Camera& camera, const std::vector<RayModelKind>& models, const Aperture& aperture,
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
  Image out(columns * (tile + gap) + gap, rows * (tile + gap) + gap, 3, 0.08f);
  const double wavelength = camera.reference_wavelength_nm();
  int row = 0;
  for (double field : options.relative_fields) {
    for (double depth : depths) {
      const ScenePoint point = scene_point(camera, field, depth);
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
      ++row;
    }
  }
  return out;
}

}  // namespace lensmith

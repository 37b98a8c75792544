// `lensmith analyze --what ...`: the real-ray analyses that have one curve or picture per lens:
// distortion, field curves, chromatic focal shift, relative illumination and the unvignetted pupil.
// A table, one JSON object (docs/cli.md) and optionally a PNG picture.
#include <cmath>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "json_output.h"
#include "lensmith/analysis/chromatic_focal_shift.h"
#include "lensmith/analysis/distortion_curve.h"
#include "lensmith/analysis/field_curves.h"
#include "lensmith/analysis/pupil_shape.h"
#include "lensmith/analysis/relative_illumination.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "lensmith/plot/analysis_plots.h"

namespace lensmith::cli {

namespace {



ojson distortion_json(const DistortionCurve& d) {
  ojson points = ojson::array();
  for (const auto& p : d.points) {
    points.push_back({{"relative_field", p.relative_field}, {"field_value", p.field_value}, {"real_height_mm", p.real_height_mm},
                      {"paraxial_height_mm", p.paraxial_height_mm}, {"distortion_percent", p.distortion_percent}});
  }
  return {{"analysis", "distortion"}, {"lens", d.lens_name}, {"wavelength_nm", d.wavelength_nm}, {"field_unit", d.field_unit},
          {"image_plane_z_mm", d.image_plane_z_mm}, {"paraxial_reference", d.paraxial_reference}, {"points", points}};
}

ojson field_curves_json(const FieldCurves& f) {
  ojson curves = ojson::array();
  for (const auto& c : f.curves) {
    ojson points = ojson::array();
    for (const auto& p : c.points) {
      points.push_back({{"relative_field", p.relative_field}, {"field_value", p.field_value},
                        {"tangential_mm", number_or_null(p.tangential_mm)}, {"sagittal_mm", number_or_null(p.sagittal_mm)}});
    }
    curves.push_back({{"wavelength_nm", c.wavelength_nm}, {"points", points}});
  }
  return {{"analysis", "field-curves"}, {"lens", f.lens_name}, {"field_unit", f.field_unit}, {"image_plane_z_mm", f.image_plane_z_mm},
          {"paraxial_focus_z_mm", f.paraxial_focus_z_mm}, {"pupil_step", f.pupil_step}, {"curves", curves}};
}

ojson focal_shift_json(const ChromaticFocalShift& c) {
  ojson points = ojson::array();
  for (const auto& p : c.points) {
    points.push_back({{"wavelength_nm", p.wavelength_nm}, {"image_distance_mm", p.image_distance_mm}, {"shift_mm", p.shift_mm},
                      {"extrapolated", p.extrapolated}});
  }
  return {{"analysis", "focal-shift"}, {"lens", c.lens_name}, {"reference_wavelength_nm", c.reference_wavelength_nm},
          {"reference_image_distance_mm", c.reference_image_distance_mm}, {"range_mm", c.range_mm()}, {"points", points}};
}

ojson illumination_json(const RelativeIllumination& r) {
  ojson points = ojson::array();
  for (const auto& p : r.points) {
    points.push_back({{"relative_field", p.relative_field}, {"field_value", p.field_value}, {"rays_in_pupil", p.rays_in_pupil},
                      {"rays_passed", p.rays_passed}, {"vignetting_factor", p.vignetting_factor},
                      {"projected_solid_angle_sr", p.projected_solid_angle_sr}, {"relative_illumination", p.relative_illumination},
                      {"chief_ray_angle_deg", p.chief_ray_angle_deg}, {"cos4_estimate", p.cos4_estimate}});
  }
  return {{"analysis", "illumination"}, {"lens", r.lens_name}, {"wavelength_nm", r.wavelength_nm}, {"field_unit", r.field_unit},
          {"pupil_grid", r.pupil_grid}, {"points", points}};
}

ojson pupil_json(const PupilShape& s) {
  ojson fields = ojson::array();
  for (const auto& f : s.fields) {
    // One string per grid row, top (py = +1) first: '#' passes, 'x' lost, '.' outside the pupil.
    ojson rows = ojson::array();
    for (int r = 0; r < f.grid; ++r) {
      std::string row;
      for (int c = 0; c < f.grid; ++c) {
        const PupilCell& cell = f.cell(r, c);
        row += !cell.inside ? '.' : cell.status == RayStatus::Ok ? '#' : 'x';
      }
      rows.push_back(row);
    }
    ojson outline = ojson::array();
    for (const auto& p : f.outline) outline.push_back({p.px, p.py});
    ojson losses = ojson::array();
    for (const auto& l : f.losses) losses.push_back({{"surface", l.surface}, {"status", std::string(to_string(l.status))}, {"rays", l.rays}});
    fields.push_back({{"relative_field", f.relative_field}, {"field_value", f.field_value}, {"grid", f.grid},
                      {"rays_in_pupil", f.rays_in_pupil}, {"rays_passed", f.rays_passed}, {"area_fraction", f.area_fraction},
                      {"centroid", {{"px", f.centroid.px}, {"py", f.centroid.py}}}, {"outline", outline}, {"losses", losses},
                      {"mask", rows}});
  }
  return {{"analysis", "pupil"}, {"lens", s.lens_name}, {"wavelength_nm", s.wavelength_nm}, {"field_unit", s.field_unit},
          {"fields", fields}};
}

// Prints the result, writes the picture: the same three steps for every analysis.
template <typename Result, typename Json, typename Plot>
int report(const Result& result, const AnalyzeCommandOptions& options, const GlobalOptions& global, Json json, Plot plot) {
  if (!options.common.png.empty()) write_picture(plot(result, make_plot_options(global)), options.common.png, options.common.lens, global);
  if (options.common.json) {
    std::cout << json(result).dump(2) << "\n";
  } else {
    std::cout << result.to_string();
  }
  return kExitOk;
}

}  // namespace

int run_analyze(const AnalyzeCommandOptions& options, const GlobalOptions& global) {
  const Prescription lens = load_lens(options.common.lens, global);
  const std::string& what = options.what;
  if (what == "focal-shift") {
    FocalShiftOptions o;
    o.wavelengths_nm = options.common.wavelengths_nm;
    if (options.samples) o.samples = *options.samples;
    return report(compute_chromatic_focal_shift(lens, o), options, global, focal_shift_json, plot::plot_chromatic_focal_shift);
  }
  if (what == "pupil") {
    const AnalysisContext context(lens, make_analysis_options(options.common));
    PupilShapeOptions o;
    if (options.grid) o.grid = *options.grid;
    return report(compute_pupil_shape(context, o), options, global, pupil_json, plot::plot_pupil_shape);
  }
  // The curves against field sample the field themselves; --fields does not apply.
  RealRayCommandOptions common = options.common;
  common.relative_fields = {0.0, 1.0};
  const AnalysisContext context(lens, make_analysis_options(common));
  if (what == "distortion") {
    DistortionOptions o;
    if (options.samples) o.field_samples = *options.samples;
    return report(compute_distortion(context, o), options, global, distortion_json, plot::plot_distortion);
  }
  if (what == "field-curves") {
    FieldCurveOptions o;
    if (options.samples) o.field_samples = *options.samples;
    return report(compute_field_curves(context, o), options, global, field_curves_json, plot::plot_field_curves);
  }
  if (what == "illumination") {
    IlluminationOptions o;
    if (options.samples) o.field_samples = *options.samples;
    if (options.grid) o.pupil_grid = *options.grid;
    return report(compute_relative_illumination(context, o), options, global, illumination_json, plot::plot_relative_illumination);
  }
  throw UsageError("--what " + what + ": must be distortion, field-curves, focal-shift, illumination or pupil");
}

}  // namespace lensmith::cli

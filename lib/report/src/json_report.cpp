// The JSON reports (json_report.h), moved here from the command's subcommands so that the command
// and the Python module write one schema.
#include "lensmith/report/json_report.h"

#include <cmath>
#include <string>

#include "lensmith/analysis/chromatic_focal_shift.h"
#include "lensmith/analysis/distortion_curve.h"
#include "lensmith/analysis/field_curves.h"
#include "lensmith/analysis/wavefront.h"
#include "lensmith/analysis/mtf.h"
#include "lensmith/analysis/pupil_shape.h"
#include "lensmith/analysis/ray_fan.h"
#include "lensmith/analysis/relative_illumination.h"
#include "lensmith/analysis/spot_diagram.h"
#include "lensmith/core/units.h"
#include "lensmith/design/optimizer.h"
#include "lensmith/paraxial/paraxial_spectral_table.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "lensmith/polyfit/lens_fit.h"
#include "lensmith/seidel/aberration_vector.h"
#include "lensmith/seidel/seidel_analysis.h"

namespace lensmith {

ojson number_or_null(double v) { return std::isfinite(v) ? ojson(v) : ojson(nullptr); }

namespace {

ojson ray_table_json(const ParaxialRayTable& t) {
  ojson rows = ojson::array();
  for (const auto& r : t.rows) {
    rows.push_back({{"surface", r.surface}, {"y_mm", r.y_mm}, {"u", r.u_after}, {"i", r.i}, {"n_after", r.n_after}});
  }
  return {{"object_slope", t.object_slope}, {"object_height_mm", t.object_height_mm}, {"surfaces", rows},
          {"image_height_mm", t.image_height_mm}};
}

ojson sums_json(const SeidelSums& s) {
  return {{"S1", s.S1}, {"S2", s.S2}, {"S3", s.S3}, {"S4", s.S4}, {"S5", s.S5}, {"C1", s.C1}, {"C2", s.C2}};
}

ojson losses_json(const RayLossCount& l) {
  return {{"total", l.total()},          {"vignetted", l.vignetted},         {"missed", l.missed},
          {"tir", l.total_internal_reflection}, {"not_converged", l.not_converged}, {"invalid_input", l.invalid_input}};
}

ojson statistics_json(const SpotStatistics& s) {
  return {{"traced", s.traced},
          {"passed", s.passed},
          {"lost", losses_json(s.lost)},
          {"centroid_x_mm", number_or_null(s.centroid_x_mm)},
          {"centroid_y_mm", number_or_null(s.centroid_y_mm)},
          {"rms_radius_chief_um", number_or_null(um_from_mm(s.rms_radius_chief_mm))},
          {"geo_radius_chief_um", number_or_null(um_from_mm(s.geo_radius_chief_mm))},
          {"rms_radius_centroid_um", number_or_null(um_from_mm(s.rms_radius_centroid_mm))},
          {"geo_radius_centroid_um", number_or_null(um_from_mm(s.geo_radius_centroid_mm))}};
}

ojson samples_json(const std::vector<FanSample>& samples, const char* pupil_key, const char* error_key) {
  ojson out = ojson::array();
  for (const FanSample& s : samples) {
    out.push_back({{pupil_key, s.pupil},
                   {error_key, s.ok() ? ojson(um_from_mm(s.error_mm)) : ojson(nullptr)},
                   {"status", std::string(to_string(s.status))},
                   {"surface", s.surface > 0 ? ojson(s.surface) : ojson(nullptr)}});
  }
  return out;
}

}  // namespace

ojson info_json(const Prescription& lens, const ParaxialSystem& p) {
  ojson o;
  o["name"] = lens.name;
  o["wavelength_nm"] = p.wavelength_nm();
  o["object_distance_mm"] = number_or_null(p.object_distance_mm());
  o["aperture"] = lens.aperture.to_string();  // as the file specifies it; the pupils below are what it gives
  o["field"] = lens.field ? ojson(lens.field->to_string()) : ojson(nullptr);
  o["ray_aiming"] = lens.ray_aiming == RayAiming::RealStop ? "real" : "paraxial";
  o["efl_mm"] = p.efl_mm();
  o["bfl_mm"] = p.bfl_mm();
  o["ffl_mm"] = p.ffl_mm();
  o["front_focal_length_mm"] = p.front_focal_length_mm();
  o["rear_focal_length_mm"] = p.rear_focal_length_mm();
  o["z_front_focal_mm"] = p.z_front_focal_mm();
  o["z_rear_focal_mm"] = p.z_rear_focal_mm();
  o["z_front_principal_mm"] = p.z_front_principal_mm();
  o["z_rear_principal_mm"] = p.z_rear_principal_mm();
  o["z_front_nodal_mm"] = p.z_front_nodal_mm();
  o["z_rear_nodal_mm"] = p.z_rear_nodal_mm();
  o["z_last_surface_mm"] = p.z_last_surface_mm();
  o["stop_surface"] = p.stop_surface();
  o["stop_flagged"] = p.stop_was_flagged();
  if (p.entrance_pupil_at_infinity()) {
    // Object-space telecentric: no finite pupil, and no infinite-conjugate F-number.
    o["entrance_pupil"] = {{"z_mm", nullptr}, {"diameter_mm", nullptr}, {"at_infinity", true}};
  } else {
    o["entrance_pupil"] = {{"z_mm", p.entrance_pupil().z_mm}, {"diameter_mm", p.entrance_pupil().diameter_mm}};
  }
  o["exit_pupil"] = {{"z_mm", p.exit_pupil().z_mm}, {"diameter_mm", p.exit_pupil().diameter_mm}};
  o["f_number"] = p.entrance_pupil_at_infinity() ? ojson(nullptr) : ojson(p.f_number());
  o["working_f_number"] = p.working_f_number();
  o["image_space_na"] = p.image_space_na();
  o["image_space_na_of_angle"] = p.image_space_na_of_angle();  // n' sin(atan u'), OpticStudio's Image Space NA
  auto h = p.lagrange_invariant();
  o["lagrange_invariant"] = h ? ojson(*h) : ojson(nullptr);
  o["image_distance_mm"] = number_or_null(p.image_distance_mm());
  o["z_image_mm"] = number_or_null(p.z_image_mm());
  o["magnification"] = p.magnification();
  o["image_plane_distance_mm"] = p.image_plane_distance_mm();
  const auto& m = p.system_matrix();
  o["system_matrix"] = {{"a11", m.a11}, {"a12", m.a12}, {"a21", m.a21}, {"a22", m.a22}};
  o["marginal_ray"] = ray_table_json(p.marginal_ray());
  o["chief_ray"] = p.chief_ray() ? ray_table_json(*p.chief_ray()) : ojson(nullptr);
  return o;
}

ojson spectral_json(const ParaxialSpectralTable& table) {
  ojson rows = ojson::array();
  for (const auto& s : table.samples()) {
    rows.push_back({{"wavelength_nm", s.wavelength_nm}, {"efl_mm", s.efl_mm}, {"bfl_mm", s.bfl_mm}, {"ffl_mm", s.ffl_mm},
                    {"z_front_principal_mm", s.z_front_principal_mm}, {"z_rear_principal_mm", s.z_rear_principal_mm},
                    {"entrance_pupil", {{"z_mm", s.z_entrance_pupil_mm}, {"diameter_mm", s.entrance_pupil_diameter_mm}}},
                    {"exit_pupil", {{"z_mm", s.z_exit_pupil_mm}, {"diameter_mm", s.exit_pupil_diameter_mm}}},
                    {"image_distance_mm", number_or_null(s.image_distance_mm)}, {"magnification", s.magnification},
                    {"extrapolated", s.extrapolated}});
  }
  return rows;
}

ojson seidel_json(const Prescription& lens, const SeidelAnalysis& seidel) {
  ojson o;
  o["name"] = lens.name;
  o["wavelength_nm"] = seidel.wavelength_nm();
  const double d = seidel.paraxial().object_distance_mm();
  o["object_distance_mm"] = std::isinf(d) ? ojson(nullptr) : ojson(d);
  o["entrance_pupil_diameter_mm"] = seidel.paraxial().entrance_pupil().diameter_mm;
  o["lagrange_invariant"] = seidel.lagrange_invariant();
  o["image_space_slope"] = seidel.image_slope();
  o["sums"] = sums_json(seidel.sums());
  o["colour_wavelengths_nm"] = {seidel.colour_wavelengths_nm()[0], seidel.colour_wavelengths_nm()[1]};
  ojson surfaces = ojson::array();
  for (std::size_t k = 0; k < seidel.surfaces().size(); ++k) {
    ojson row = sums_json(seidel.surfaces()[k]);
    row["surface"] = k + 1;
    row["aspheric"] = sums_json(seidel.aspheric_parts()[k]);
    surfaces.push_back(row);
  }
  o["surfaces"] = surfaces;
  const WavefrontCoefficients w = seidel.wavefront().in_waves(seidel.wavelength_nm());
  o["wavefront_waves"] = {{"W040", w.W040}, {"W131", w.W131}, {"W222", w.W222}, {"W220", w.W220}, {"W311", w.W311}, {"W020", w.W020}, {"W111", w.W111}};
  const WavefrontCoefficients wmm = seidel.wavefront();
  o["wavefront_mm"] = {{"W040", wmm.W040}, {"W131", wmm.W131}, {"W222", wmm.W222}, {"W220", wmm.W220}, {"W311", wmm.W311}, {"W020", wmm.W020}, {"W111", wmm.W111}};
  const TransverseAberrations t = seidel.transverse();
  o["transverse_mm"] = {{"TSA", t.TSA}, {"TCO", t.TCO}, {"TAS", t.TAS}, {"SAS", t.SAS}, {"PTB", t.PTB}, {"DST", t.DST}, {"TAX", t.TAX}, {"TLAT", t.TLAT}};
  const LongitudinalAberrations l = seidel.longitudinal();
  o["longitudinal_mm"] = {{"LSA", l.LSA}, {"LTAS", l.LTAS}, {"LSAS", l.LSAS}, {"LPTZ", l.LPTZ}, {"LAX", l.LAX}};
  const FieldCurvatures f = seidel.field_curvatures();
  o["field_curvatures_per_mm"] = {{"tangential", f.tangential_per_mm}, {"sagittal", f.sagittal_per_mm}, {"petzval", f.petzval_per_mm}};
  o["petzval_radius_mm"] = std::isinf(f.petzval_radius_mm()) ? ojson(nullptr) : ojson(f.petzval_radius_mm());
  const AberrationCoefficients c = AberrationCoefficients::from(seidel);
  o["born_wolf"] = {{"B", c.B_mm}, {"C", c.C_mm}, {"D", c.D_mm}, {"E", c.E_mm}, {"F", c.F_mm}, {"units", "mm; rho = 1 at the pupil edge, y0 = 1 at the maximum field"},
                    {"pupil_radius_mm", c.pupil_radius_mm}, {"max_field_tangent", c.max_field_tangent}};
  const BornWolfUnits u = c.in_born_wolf_units();
  o["born_wolf_units"] = {{"B", u.B}, {"C", u.C}, {"D", u.D}, {"E", u.E}, {"F", u.F},
                          {"D0_mm", std::isinf(u.D0_mm) ? ojson(nullptr) : ojson(u.D0_mm)}, {"D1_mm", u.D1_mm}};
  return o;
}

ojson spot_json(const SpotDiagram& d) {
  ojson o;
  o["lens"] = d.lens_name;
  if (d.sampling.kind == PupilSampling::Kind::Hexapolar) {
    o["sampling"] = {{"kind", "hexapolar"}, {"rings", d.sampling.rings}, {"rays", d.sampling.count()}};
  } else {
    o["sampling"] = {{"kind", "random"}, {"rays", d.sampling.count()}, {"seed", d.sampling.seed}};
  }
  o["wavelengths_nm"] = d.wavelengths_nm;
  o["reference_wavelength_nm"] = d.reference_wavelength_nm;
  o["field_unit"] = d.field_unit;
  o["image_plane_z_mm"] = d.image_plane_z_mm;
  ojson fields = ojson::array();
  for (const FieldSpot& f : d.fields) {
    ojson field;
    field["relative_field"] = f.relative_field;
    field["field_value"] = f.field_value;
    field["chief"] = {{"x_mm", f.chief.x_mm}, {"y_mm", f.chief.y_mm}};
    field["polychromatic"] = statistics_json(f.polychromatic);
    ojson spots = ojson::array();
    for (const Spot& s : f.spots) {
      ojson spot = statistics_json(s.stats);
      spot["wavelength_nm"] = s.wavelength_nm;
      ojson px = ojson::array(), py = ojson::array(), x = ojson::array(), y = ojson::array();
      for (std::size_t i = 0; i < s.points.size(); ++i) {
        px.push_back(s.pupil[i].px);
        py.push_back(s.pupil[i].py);
        x.push_back(s.points[i].x_mm);
        y.push_back(s.points[i].y_mm);
      }
      spot["rays"] = {{"px", px}, {"py", py}, {"x_mm", x}, {"y_mm", y}};
      spots.push_back(spot);
    }
    field["spots"] = spots;
    fields.push_back(field);
  }
  o["fields"] = fields;
  return o;
}

ojson fan_json(const RayFan& fan) {
  ojson o;
  o["lens"] = fan.lens_name;
  o["wavelengths_nm"] = fan.wavelengths_nm;
  o["reference_wavelength_nm"] = fan.reference_wavelength_nm;
  o["field_unit"] = fan.field_unit;
  o["image_plane_z_mm"] = fan.image_plane_z_mm;
  ojson fields = ojson::array();
  for (const FieldFan& f : fan.fields) {
    ojson curves = ojson::array();
    for (const FanCurve& c : f.curves) {
      curves.push_back({{"wavelength_nm", c.wavelength_nm},
                        {"tangential", samples_json(c.tangential, "py", "ey_um")},
                        {"sagittal", samples_json(c.sagittal, "px", "ex_um")}});
    }
    fields.push_back({{"relative_field", f.relative_field},
                      {"field_value", f.field_value},
                      {"chief", {{"x_mm", f.chief.x_mm}, {"y_mm", f.chief.y_mm}}},
                      {"curves", curves}});
  }
  o["fields"] = fields;
  return o;
}

ojson wavefront_json(const Wavefront& w, bool include_map) {
  auto fan = [](const std::vector<OpdSample>& samples, bool tangential) {
    ojson out = ojson::array();
    for (const OpdSample& s : samples) {
      out.push_back({{tangential ? "py" : "px", tangential ? s.py : s.px},
                     {"opd_waves", number_or_null(s.opd_waves)},
                     {"status", std::string(to_string(s.status))}});
    }
    return out;
  };
  ojson maps = ojson::array();
  for (const WavefrontMap& m : w.maps) {
    ojson o{{"relative_field", m.relative_field},
            {"field_value", m.field_value},
            {"wavelength_nm", m.wavelength_nm},
            {"reference", {{"x_mm", m.reference.x_mm}, {"y_mm", m.reference.y_mm}, {"z_mm", m.reference.z_mm}}},
            {"reference_radius_mm", m.reference_radius_mm},
            {"rms_waves", m.rms_waves},
            {"rms_tilt_removed_waves", m.rms_tilt_removed_waves},
            {"pv_waves", m.pv_waves},
            {"rays", m.samples},
            {"lost", m.lost.total()},
            {"zernike", m.zernike},
            {"tangential_fan", fan(m.tangential, true)},
            {"sagittal_fan", fan(m.sagittal, false)}};
    if (include_map) {
      ojson grid = ojson::array();
      for (const OpdSample& s : m.map) grid.push_back(number_or_null(s.opd_waves));
      o["grid"] = m.grid;
      o["map_waves"] = grid;
    }
    maps.push_back(o);
  }
  return {{"analysis", "wavefront"},
          {"lens", w.lens_name},
          {"wavelengths_nm", w.wavelengths_nm},
          {"reference_wavelength_nm", w.reference_wavelength_nm},
          {"image_plane_z_mm", w.image_plane_z_mm},
          {"exit_pupil_z_mm", w.exit_pupil_z_mm},
          {"zernike_ordering", std::string(to_string(w.ordering))},
          {"maps", maps}};
}

ojson psf_json(const Psf& psf, bool include_grid) {
  ojson fields = ojson::array();
  for (const FieldPsf& f : psf.fields) {
    double peak = 0.0;
    for (double v : f.intensity) peak = std::max(peak, v);
    ojson o{{"relative_field", f.relative_field},
            {"field_value", f.field_value},
            {"centre", {{"x_mm", f.centre.x_mm}, {"y_mm", f.centre.y_mm}, {"z_mm", f.centre.z_mm}}},
            {"strehl", f.strehl},
            {"peak", peak},
            {"centroid_x_um", um_from_mm(f.centroid_x_mm)},
            {"centroid_y_um", um_from_mm(f.centroid_y_mm)}};
    if (include_grid) o["intensity"] = f.intensity;
    fields.push_back(o);
  }
  return {{"analysis", "psf"},
          {"lens", psf.lens_name},
          {"wavelengths_nm", psf.wavelengths_nm},
          {"size", psf.size},
          {"spacing_um", um_from_mm(psf.spacing_mm)},
          {"fields", fields}};
}

ojson through_focus_mtf_json(const ThroughFocusMtf& mtf) {
  ojson fields = ojson::array();
  for (const MtfCurve& c : mtf.fields) {
    fields.push_back({{"relative_field", c.relative_field},
                      {"field_value", c.field_value},
                      {"tangential", c.tangential},
                      {"sagittal", c.sagittal},
                      {"diffraction_limit", c.diffraction_limit}});
  }
  return {{"analysis", "through_focus_mtf"},
          {"lens", mtf.lens_name},
          {"frequency_per_mm", mtf.frequency_per_mm},
          {"focus_shifts_mm", mtf.focus_shifts_mm},
          {"fields", fields}};
}

ojson mtf_json(const Mtf& mtf) {
  ojson fields = ojson::array();
  for (const MtfCurve& c : mtf.fields) {
    fields.push_back({{"relative_field", c.relative_field},
                      {"field_value", c.field_value},
                      {"strehl", c.strehl},
                      {"tangential", c.tangential},
                      {"sagittal", c.sagittal},
                      {"diffraction_limit", c.diffraction_limit},
                      {"geometric_tangential", c.geometric_tangential},
                      {"geometric_sagittal", c.geometric_sagittal}});
  }
  return {{"analysis", "mtf"},
          {"lens", mtf.lens_name},
          {"wavelengths_nm", mtf.wavelengths_nm},
          {"cutoff_per_mm", mtf.cutoff_per_mm},
          {"frequencies_per_mm", mtf.frequencies_per_mm},
          {"fields", fields}};
}

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

ojson fit_json(const LensFit& fit) {
  const LensFitErrors& e = fit.errors();
  const LensFitTiming& t = fit.timing();
  ojson j;
  j["lens"] = fit.lens_name();
  j["prescription_hash"] = fit.lens_hash();
  j["degree"] = fit.options().degree;
  j["terms"] = fit.term_budget();
  j["symmetry"] = std::string(to_string(fit.symmetry()));
  j["terms_sensor_to_outer"] = fit.sensor_to_outer().size();
  j["terms_outer_to_sensor"] = fit.outer_to_sensor().size();
  j["clip_surfaces"] = ojson::array();
  for (const ClipSurface& c : fit.clip_surfaces()) j["clip_surfaces"].push_back(c.surface);
  j["test_rays"] = e.test_rays;
  j["position_rms_um"] = e.position_rms_um;
  j["position_p99_um"] = e.position_p99_um;
  j["direction_rms_mrad"] = e.direction_rms_mrad;
  j["stop_rms_um"] = e.stop_rms_um;
  j["transmittance_rms"] = e.transmittance_rms;
  j["sensor_position_rms_um"] = e.sensor_position_rms_um;
  j["sensor_position_p99_um"] = e.sensor_position_p99_um;
  j["sensor_direction_rms_mrad"] = e.sensor_direction_rms_mrad;
  j["vignetting_mismatch"] = e.vignetting_mismatch;
  j["fit_seconds"] = t.fit_seconds;
  // The speed only where it was measured (LensFit::measure_speed; `lensmith fit` does, a fit made in
  // a render does not).
  if (t.speed_measured()) {
    j["exact_ns_per_ray"] = t.exact_ns_per_ray;
    j["poly_ns_per_ray"] = t.poly_ns_per_ray;
    j["speedup"] = t.exact_ns_per_ray / t.poly_ns_per_ray;
  } else {
    j["exact_ns_per_ray"] = nullptr;
    j["poly_ns_per_ray"] = nullptr;
    j["speedup"] = nullptr;
  }
  return j;
}

ojson optimize_json(const OptimizeResult& result, const std::vector<OptimizeProgress>& history) {
  ojson variables = ojson::array();
  for (std::size_t j = 0; j < result.merit_function.variables.size(); ++j) {
    const DesignVariable& v = result.merit_function.variables[j];
    variables.push_back({{"name", v.name()},
                         {"unit", v.unit()},
                         {"surface", v.surface},
                         {"start", number_or_null(result.start_values[j])},
                         {"result", number_or_null(result.result_values[j])},
                         {"min", v.min ? number_or_null(*v.min) : ojson(nullptr)},
                         {"max", v.max ? number_or_null(*v.max) : ojson(nullptr)},
                         {"at_bound", static_cast<bool>(result.at_bound[j])}});
  }
  ojson operands = ojson::array();
  for (std::size_t i = 0; i < result.merit_function.operands.size(); ++i) {
    const Operand& o = result.merit_function.operands[i];
    ojson row = {{"operand", o.label()},
                 {"unit", o.unit()},
                 {"goal", o.goal()},
                 {"target", o.target ? number_or_null(*o.target) : ojson(nullptr)},
                 {"min", o.min ? number_or_null(*o.min) : ojson(nullptr)},
                 {"max", o.max ? number_or_null(*o.max) : ojson(nullptr)},
                 {"weight", o.weight},
                 {"start", number_or_null(result.before.operands[i].value)},
                 {"result", number_or_null(result.after.operands[i].value)},
                 {"start_merit", number_or_null(result.before.operands[i].contribution)},
                 {"result_merit", number_or_null(result.after.operands[i].contribution)}};
    if (!result.after.operands[i].failure.empty()) row["failure"] = result.after.operands[i].failure;
    operands.push_back(row);
  }
  ojson substitutions = ojson::array();
  for (const SubstitutedGlass& s : result.substitutions) {
    substitutions.push_back({{"surface", s.surface}, {"model_nd", s.model_nd}, {"model_vd", s.model_vd}, {"glass", s.glass}, {"nd", s.nd}, {"vd", s.vd}});
  }
  ojson steps = ojson::array();
  for (const OptimizeProgress& p : history) {
    steps.push_back({{"stage", p.stage}, {"iteration", p.iteration}, {"merit", number_or_null(p.merit)}, {"step_accepted", p.step_accepted}});
  }
  return {{"lens", result.start.name},
          {"merit_start", number_or_null(result.before.merit)},
          {"merit_result", number_or_null(result.after.merit)},
          {"iterations", result.iterations},
          {"evaluations", result.evaluations},
          {"termination", result.termination},
          {"variables", variables},
          {"operands", operands},
          {"substitutions", substitutions},
          {"history", steps}};
}

}  // namespace lensmith

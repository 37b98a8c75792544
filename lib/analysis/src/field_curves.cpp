// Tangential and sagittal foci from symmetric pairs of real rays around the chief ray: the finite-ray
// form of Coddington's equations (Welford sec. 9.4; Kingslake, Lens Design Fundamentals, ch. 4).
#include "lensmith/analysis/field_curves.h"

#include <cmath>
#include <limits>
#include <sstream>

#include "analysis_detail.h"
#include "lensmith/core/errors.h"

namespace lensmith {

using analysis_detail::fixed;

void FieldCurveOptions::validate() const {
  analysis_detail::check_count("FieldCurveOptions::field_samples", field_samples, 2, 1001);
  if (!(pupil_step > 0.0 && pupil_step <= 0.1)) {
    throw OptionsError("FieldCurveOptions::pupil_step = " + fixed(pupil_step, 6) + ": must lie in (0, 0.1]");
  }
}

namespace {

// z offset from the image plane where two rays cross, in one transverse coordinate: each ray is
// h(z) = h0 + (z - z0) t with t its slope (direction component / n) and h0 its height on the plane.
double crossing_offset_mm(double h_a, double t_a, double h_b, double t_b) {
  const double dt = t_a - t_b;
  if (dt == 0.0) return std::numeric_limits<double>::quiet_NaN();
  return -(h_a - h_b) / dt;
}

}  // namespace

FieldCurves compute_field_curves(const AnalysisContext& context, const FieldCurveOptions& options) {
  options.validate();
  FieldCurves out;
  out.lens_name = context.lens().name;
  out.field_unit = context.field_unit();
  out.image_plane_z_mm = context.tracer().image_plane_z_mm();
  ParaxialOptions paraxial_options;
  paraxial_options.wavelength_nm = context.reference_wavelength_nm();
  out.paraxial_focus_z_mm = ParaxialSystem(context.lens(), paraxial_options).z_image_mm();
  out.pupil_step = options.pupil_step;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double d = options.pupil_step;

  const std::vector<double> fields = analysis_detail::relative_field_samples(options.field_samples);
  if (fields.back() > 0.0) (void)context.field_at(1.0);  // a lens without a field fails here, clearly
  for (double wavelength : context.wavelengths_nm()) {
    FieldCurveSet set;
    set.wavelength_nm = wavelength;
    for (double relative : fields) {
      FieldCurvePoint p;
      p.relative_field = relative;
      p.field_value = context.field_value(relative);
      const FieldPoint field = context.field_at(relative);
      // Rays near the chief ray, traced without clipping: the focus is a local property of the beam.
      const TracedRay t_plus = context.trace_unclipped(field, {0.0, d}, wavelength);
      const TracedRay t_minus = context.trace_unclipped(field, {0.0, -d}, wavelength);
      const TracedRay s_plus = context.trace_unclipped(field, {d, 0.0}, wavelength);
      const TracedRay s_minus = context.trace_unclipped(field, {-d, 0.0}, wavelength);
      p.tangential_mm = nan;
      p.sagittal_mm = nan;
      if (t_plus.ok() && t_minus.ok()) {
        const Ray& a = t_plus.image_ray;
        const Ray& b = t_minus.image_ray;
        p.tangential_mm = crossing_offset_mm(a.position_mm.y(), a.direction.y() / a.direction.z(), b.position_mm.y(),
                                             b.direction.y() / b.direction.z());
      }
      if (s_plus.ok() && s_minus.ok()) {
        const Ray& a = s_plus.image_ray;
        const Ray& b = s_minus.image_ray;
        p.sagittal_mm = crossing_offset_mm(a.position_mm.x(), a.direction.x() / a.direction.z(), b.position_mm.x(),
                                           b.direction.x() / b.direction.z());
      }
      set.points.push_back(p);
    }
    out.curves.push_back(std::move(set));
  }
  return out;
}

std::string FieldCurves::to_string() const {
  std::ostringstream os;
  os << "Field curves: " << lens_name << "\n";
  os << "Focus minus image plane along z, mm (image plane z = " << fixed(image_plane_z_mm, 4) << " mm, paraxial focus z = "
     << fixed(paraxial_focus_z_mm, 4) << " mm); T tangential, S sagittal; real rays at pupil +/-" << pupil_step << "\n\n";
  char cell[96];
  std::snprintf(cell, sizeof cell, "%10s %12s", "relative", ("field " + field_unit).c_str());
  os << cell;
  for (const auto& c : curves) {
    std::snprintf(cell, sizeof cell, "   T %8.2f nm   S %8.2f nm", c.wavelength_nm, c.wavelength_nm);
    os << cell;
  }
  os << "\n";
  if (curves.empty()) return os.str();
  for (std::size_t i = 0; i < curves.front().points.size(); ++i) {
    const auto& p0 = curves.front().points[i];
    std::snprintf(cell, sizeof cell, "%10.3f %12.4f", p0.relative_field, p0.field_value);
    os << cell;
    for (const auto& c : curves) {
      std::snprintf(cell, sizeof cell, "   %13.6f   %13.6f", c.points[i].tangential_mm, c.points[i].sagittal_mm);
      os << cell;
    }
    os << "\n";
  }
  return os.str();
}

}  // namespace lensmith

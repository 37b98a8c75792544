// Real-ray distortion against the paraxial image height (Welford sec. 9.2; OpticStudio "Field
// Curvature and Distortion", F-Tan(Theta)).
#include "lensmith/analysis/distortion_curve.h"

#include <cmath>
#include <sstream>

#include "analysis_detail.h"
#include "lensmith/core/errors.h"

namespace lensmith {

using analysis_detail::fixed;

namespace {
// Relative field at which the on-axis limit is evaluated: distortion proper is ~1e-8 of its
// full-field value there, while the heights (~1e-4 of the full image height) are still far above
// rounding (1e-13 mm).
constexpr double kAxialLimitField = 1e-4;
}  // namespace

void DistortionOptions::validate() const {
  analysis_detail::check_count("DistortionOptions::field_samples", field_samples, 2, 1001);
  for (double f : relative_fields) {
    if (!(f >= 0.0 && f <= 1.0)) throw OptionsError("DistortionOptions::relative_fields: " + std::to_string(f) + " is not in [0, 1]");
  }
}

DistortionCurve compute_distortion(const AnalysisContext& context, const DistortionOptions& options) {
  options.validate();
  DistortionCurve out;
  out.lens_name = context.lens().name;
  out.wavelength_nm = context.reference_wavelength_nm();
  out.field_unit = context.field_unit();
  out.image_plane_z_mm = context.tracer().image_plane_z_mm();

  ParaxialOptions paraxial_options;
  paraxial_options.wavelength_nm = out.wavelength_nm;
  const ParaxialSystem paraxial(context.lens(), paraxial_options);
  const bool at_infinity = std::isinf(paraxial.object_distance_mm());
  const double n_object = context.tracer().index_after(0, out.wavelength_nm);
  out.paraxial_reference = at_infinity ? "n f tan(theta), f = " + fixed(paraxial.efl_mm(), 4) + " mm"
                                       : "m h, m = " + fixed(paraxial.magnification(), 6);

  // Probe the field before tracing: a lens without a field fails here with a clear message.
  (void)context.field_at(1.0);
  const std::vector<double> fields =
      options.relative_fields.empty() ? analysis_detail::relative_field_samples(options.field_samples) : options.relative_fields;
  for (double relative : fields) {
    DistortionPoint p;
    p.relative_field = relative;
    p.field_value = context.field_value(relative);
    // On axis 0/0: take the limit, at a field small enough that distortion proper (which grows as the
    // field squared) has vanished. What remains is the chief ray's slope times the distance between
    // the image plane and the paraxial focus, a constant fraction of the height.
    const double traced = relative == 0.0 ? kAxialLimitField : relative;
    const TracedRay chief = context.reference_ray(context.field_at(traced), out.wavelength_nm);
    p.real_height_mm = chief.image_ray.position_mm.y();
    const Eigen::Vector3d& d = chief.object_ray.direction;
    if (at_infinity) {
      // Paraxial image height of a collimated beam of slope u: n u f (system matrix on (n u, y)).
      p.paraxial_height_mm = n_object * (d.y() / d.z()) * paraxial.efl_mm();
    } else {
      // Object height: the chief ray extended back to the object plane, then the paraxial magnification.
      const double z_object = -paraxial.object_distance_mm();
      const Eigen::Vector3d& s = chief.object_ray.position_mm;
      const double h = s.y() + (z_object - s.z()) * d.y() / d.z();
      p.paraxial_height_mm = paraxial.magnification() * h;
    }
    p.distortion_percent = p.paraxial_height_mm == 0.0 ? 0.0 : 100.0 * (p.real_height_mm - p.paraxial_height_mm) / p.paraxial_height_mm;
    if (relative == 0.0) p.real_height_mm = p.paraxial_height_mm = 0.0;
    out.points.push_back(p);
  }
  return out;
}

std::string DistortionCurve::to_string() const {
  std::ostringstream os;
  os << "Distortion: " << lens_name << "\n";
  os << "Real chief ray at " << fixed(wavelength_nm, 4) << " nm on the image plane (z = " << fixed(image_plane_z_mm, 4)
     << " mm) against the paraxial image height " << paraxial_reference << "\n\n";
  char line[160];
  std::snprintf(line, sizeof line, "%10s %12s %16s %18s %14s\n", "relative", ("field " + field_unit).c_str(), "real y mm",
                "paraxial y mm", "distortion %");
  os << line;
  for (const auto& p : points) {
    std::snprintf(line, sizeof line, "%10.3f %12.4f %16.6f %18.6f %14.5f\n", p.relative_field, p.field_value, p.real_height_mm,
                  p.paraxial_height_mm, p.distortion_percent);
    os << line;
  }
  return os.str();
}

}  // namespace lensmith

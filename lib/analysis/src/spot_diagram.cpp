// Spot diagrams and their RMS / geometric radii (Welford ch. 9; OpticStudio "Standard Spot Diagram").
#include "lensmith/analysis/spot_diagram.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "lensmith/core/units.h"

namespace lensmith {

namespace {

std::string micrometres(double mm) {
  if (!std::isfinite(mm)) return "     -";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%10.3f", um_from_mm(mm));
  return buffer;
}

// Rounding residue such as -1e-17 would print as "-0.000000".
double tidy(double mm) { return std::abs(mm) < 1e-12 ? 0.0 : mm; }

}  // namespace

SpotStatistics spot_statistics(const std::vector<ImagePoint>& points, const ImagePoint& reference) {
  SpotStatistics s;
  s.traced = points.size();
  s.passed = points.size();
  if (points.empty()) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    s.centroid_x_mm = s.centroid_y_mm = nan;
    s.rms_radius_chief_mm = s.geo_radius_chief_mm = s.rms_radius_centroid_mm = s.geo_radius_centroid_mm = nan;
    return s;
  }
  double sx = 0.0, sy = 0.0;
  for (const auto& p : points) {
    sx += p.x_mm;
    sy += p.y_mm;
  }
  const double count = static_cast<double>(points.size());
  s.centroid_x_mm = sx / count;
  s.centroid_y_mm = sy / count;
  double sum_chief = 0.0, sum_centroid = 0.0;
  for (const auto& p : points) {
    const double rc2 = (p.x_mm - reference.x_mm) * (p.x_mm - reference.x_mm) + (p.y_mm - reference.y_mm) * (p.y_mm - reference.y_mm);
    const double rm2 = (p.x_mm - s.centroid_x_mm) * (p.x_mm - s.centroid_x_mm) + (p.y_mm - s.centroid_y_mm) * (p.y_mm - s.centroid_y_mm);
    sum_chief += rc2;
    sum_centroid += rm2;
    s.geo_radius_chief_mm = std::max(s.geo_radius_chief_mm, std::sqrt(rc2));
    s.geo_radius_centroid_mm = std::max(s.geo_radius_centroid_mm, std::sqrt(rm2));
  }
  s.rms_radius_chief_mm = std::sqrt(sum_chief / count);
  s.rms_radius_centroid_mm = std::sqrt(sum_centroid / count);
  return s;
}

std::string SpotStatistics::to_string() const {
  std::ostringstream os;
  os << "passed " << passed << " of " << traced << " (" << lost.to_string() << "), RMS " << micrometres(rms_radius_chief_mm)
     << " um about the chief ray, " << micrometres(rms_radius_centroid_mm) << " um about the centroid, GEO "
     << micrometres(geo_radius_chief_mm) << " um";
  return os.str();
}

double SpotDiagram::airy_radius_mm(double wavelength_nm) const {
  constexpr double kAiryFirstZero = 1.21967;  // first zero of J1(pi x) / (pi x), in units of lambda N
  return kAiryFirstZero * mm_from_nm(wavelength_nm) * working_f_number;
}

SpotDiagram compute_spot_diagram(const AnalysisContext& context, const SpotOptions& options) {
  options.validate();
  SpotDiagram out;
  out.lens_name = context.lens().name;
  out.sampling = options.sampling;
  out.wavelengths_nm = context.wavelengths_nm();
  out.reference_wavelength_nm = context.reference_wavelength_nm();
  out.field_unit = context.field_unit();
  out.image_plane_z_mm = context.tracer().image_plane_z_mm();
  out.working_f_number = context.paraxial().working_f_number();
  const std::vector<PupilCoordinate> pupil = options.sampling.samples();

  for (double relative : context.relative_fields()) {
    FieldSpot field_spot;
    field_spot.relative_field = relative;
    field_spot.field_value = context.field_value(relative);
    field_spot.field_label = context.field_label(relative);
    const FieldPoint field = context.field_at(relative);
    field_spot.chief = ImagePoint::from(context.reference_ray(field, context.reference_wavelength_nm()).image_ray.position_mm);

    std::vector<ImagePoint> all_points;
    RayLossCount all_lost;
    for (double wavelength : context.wavelengths_nm()) {
      Spot spot;
      spot.wavelength_nm = wavelength;
      RayLossCount lost;
      for (const PupilCoordinate& p : pupil) {
        const TracedRay ray = context.trace(field, p, wavelength);
        if (!ray.ok()) {
          lost.add(ray.status);
          continue;
        }
        spot.pupil.push_back(p);
        spot.points.push_back(ImagePoint::from(ray.image_ray.position_mm));
      }
      spot.stats = spot_statistics(spot.points, field_spot.chief);
      spot.stats.traced = pupil.size();
      spot.stats.lost = lost;
      all_points.insert(all_points.end(), spot.points.begin(), spot.points.end());
      all_lost += lost;
      field_spot.spots.push_back(std::move(spot));
    }
    field_spot.polychromatic = spot_statistics(all_points, field_spot.chief);
    field_spot.polychromatic.traced = pupil.size() * context.wavelengths_nm().size();
    field_spot.polychromatic.lost = all_lost;
    out.fields.push_back(std::move(field_spot));
  }
  return out;
}

std::string SpotDiagram::to_string() const {
  std::ostringstream os;
  char line[256];
  os << "Spot diagram: " << lens_name << "\n";
  os << "Pupil sampling: " << sampling.to_string() << "; reference: chief ray at " << reference_wavelength_nm
     << " nm; image plane z = " << image_plane_z_mm << " mm\n";
  os << "Radii in micrometres. RMS and GEO about the chief ray; RMS* about the centroid.\n\n";
  std::snprintf(line, sizeof line, "%-22s %10s %10s %10s %10s %10s %12s %12s  %s\n", "field", "lambda nm", "RMS", "GEO", "RMS*",
                "GEO*", "chief x mm", "chief y mm", "rays");
  os << line;
  for (const FieldSpot& f : fields) {
    auto row = [&](const std::string& wavelength, const SpotStatistics& s) {
      std::snprintf(line, sizeof line, "%-22s %10s %s %s %s %s %12.6f %12.6f  %zu/%zu", f.field_label.c_str(), wavelength.c_str(),
                    micrometres(s.rms_radius_chief_mm).c_str(), micrometres(s.geo_radius_chief_mm).c_str(),
                    micrometres(s.rms_radius_centroid_mm).c_str(), micrometres(s.geo_radius_centroid_mm).c_str(),
                    tidy(f.chief.x_mm), tidy(f.chief.y_mm), s.passed, s.traced);
      os << line;
      if (s.lost.total() > 0) os << " (" << s.lost.to_string() << ")";
      os << "\n";
    };
    for (const Spot& s : f.spots) {
      char w[32];
      std::snprintf(w, sizeof w, "%.4f", s.wavelength_nm);
      row(w, s.stats);
    }
    if (f.spots.size() > 1) row("poly", f.polychromatic);
  }
  return os.str();
}

}  // namespace lensmith

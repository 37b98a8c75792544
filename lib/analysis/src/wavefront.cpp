// OPD against the reference sphere at the exit pupil (Welford, Aberrations of Optical Systems, sec. 5.2
// and 9.2): each real ray followed back from the image plane to the sphere, its optical path there
// compared with the chief ray's. Details and conventions: lensmith/analysis/wavefront.h, docs/wavefront.md.
#include "lensmith/analysis/wavefront.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include <Eigen/Dense>

#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/units.h"
#include "lensmith/trace/fresnel.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "analysis_detail.h"

namespace lensmith {

namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// The reference sphere of one field and wavelength, and the chief ray's optical path to it.
struct ReferenceSphere {
  Eigen::Vector3d centre_mm;
  double radius_mm = 0.0;
  bool pupil_before_image = true;  // the sphere is met going back from the image plane
  double chief_path_mm = 0.0;
  double image_index = 1.0;
  double wavelength_mm = 0.0;

  // OPD (waves) of a traced ray; NaN when it never meets the sphere.
  double opd_waves(const TracedRay& r) const {
    const Eigen::Vector3d q = r.image_ray.position_mm, d = r.image_ray.direction;
    const Eigen::Vector3d qc = q - centre_mm;
    const double b = d.dot(qc), c = qc.squaredNorm() - radius_mm * radius_mm;
    const double disc = b * b - c;
    if (disc < 0.0) return kNan;
    const double t = pupil_before_image ? -b - std::sqrt(disc) : -b + std::sqrt(disc);
    const double path = r.optical_path_mm + image_index * t;
    return (chief_path_mm - path) / wavelength_mm;
  }
};

}  // namespace

void WavefrontOptions::validate() const {
  analysis_detail::check_count("WavefrontOptions::grid", grid, 8, 1024);
  if (fan_samples < 3 || fan_samples > 1001 || fan_samples % 2 == 0) {
    throw OptionsError("WavefrontOptions::fan_samples = " + std::to_string(fan_samples) + ": must be odd, 3 to 1001");
  }
  if (zernike_terms < 1 || zernike_terms > max_zernike_terms(ordering)) {
    throw OptionsError("WavefrontOptions::zernike_terms = " + std::to_string(zernike_terms) + ": must be 1 to " +
                       std::to_string(max_zernike_terms(ordering)) + " for the " + std::string(to_string(ordering)) + " ordering");
  }
}

Wavefront compute_wavefront(const AnalysisContext& context, const WavefrontOptions& options) {
  options.validate();
  Wavefront out;
  out.lens_name = context.lens().name;
  out.wavelengths_nm = context.wavelengths_nm();
  out.reference_wavelength_nm = context.reference_wavelength_nm();
  out.image_plane_z_mm = context.tracer().image_plane_z_mm();
  out.exit_pupil_z_mm = context.paraxial().exit_pupil().z_mm;
  out.ordering = options.ordering;
  const Glass& image_medium = context.lens().surfaces.back().medium;

  for (double relative : context.relative_fields()) {
    const FieldPoint field = context.field_at(relative);
    const Eigen::Vector3d centre = context.reference_ray(field, context.reference_wavelength_nm()).image_ray.position_mm;
    for (double wavelength : context.wavelengths_nm()) {
      WavefrontMap m;
      m.relative_field = relative;
      m.field_value = context.field_value(relative);
      m.field_label = context.field_label(relative);
      m.wavelength_nm = wavelength;
      m.reference = ImagePoint::from(centre);
      m.grid = options.grid;

      // The sphere through the chief ray's crossing of the exit pupil's plane.
      const TracedRay chief = context.reference_ray(field, wavelength);
      const Eigen::Vector3d q = chief.image_ray.position_mm, d = chief.image_ray.direction;
      if (!(std::abs(d.z()) > 0.0)) throw ComputationError("field " + m.field_label + ": the chief ray runs along the image plane");
      const double t = (out.exit_pupil_z_mm - q.z()) / d.z();
      const Eigen::Vector3d on_pupil = q + t * d;
      ReferenceSphere sphere;
      sphere.centre_mm = centre;
      sphere.radius_mm = (on_pupil - centre).norm();
      // Below a micrometre the exit pupil lies on the image plane: no sphere to refer to.
      constexpr double kMinRadiusMm = 1e-3;
      if (!(sphere.radius_mm > kMinRadiusMm)) {
        throw ComputationError("field " + m.field_label + ": the exit pupil lies on the image plane, so the wavefront has no reference sphere");
      }
      sphere.pupil_before_image = (on_pupil - centre).dot(d) < 0.0;
      sphere.image_index = std::abs(image_medium.index(wavelength));
      // The chief ray meets the sphere at on_pupil, or where it crosses the sphere nearest that point
      // (its centre is the reference wavelength's image point, not this wavelength's).
      sphere.wavelength_mm = mm_from_nm(wavelength);
      sphere.chief_path_mm = 0.0;
      sphere.chief_path_mm = -sphere.opd_waves(chief) * sphere.wavelength_mm;  // the chief ray's own path to the sphere
      if (!std::isfinite(sphere.chief_path_mm)) {
        throw ComputationError("field " + m.field_label + ": the chief ray does not meet the reference sphere");
      }
      m.reference_radius_mm = sphere.pupil_before_image ? sphere.radius_mm : -sphere.radius_mm;

      auto sample = [&](double px, double py) {
        OpdSample s{px, py, kNan, RayStatus::Ok};
        thread_local std::vector<SurfaceHit> path;  // reused: no allocation per ray
        path.clear();
        const TracedRay r = context.trace(field, {px, py}, wavelength, options.transmittance ? &path : nullptr);
        s.status = r.status;
        if (r.ok()) {
          s.x_mm = r.image_ray.position_mm.x();
          s.y_mm = r.image_ray.position_mm.y();
          s.opd_waves = sphere.opd_waves(r);
          if (!std::isfinite(s.opd_waves)) s.status = RayStatus::Missed;
          // The amplitude is the square root of the intensity transmittance.
          if (options.transmittance) s.amplitude = std::sqrt(path_transmittance(context.tracer(), r.object_ray.direction, path, wavelength));
        }
        return s;
      };

      // The map: grid x grid points from -1 to 1, those inside the unit pupil traced.
      const int n = options.grid;
      m.map.assign(static_cast<std::size_t>(n) * static_cast<std::size_t>(n), OpdSample{});
#pragma omp parallel for schedule(dynamic, 1)
      for (int row = 0; row < n; ++row) {
        const double py = -1.0 + 2.0 * row / (n - 1);
        for (int col = 0; col < n; ++col) {
          const double px = -1.0 + 2.0 * col / (n - 1);
          OpdSample& s = m.map[static_cast<std::size_t>(row) * static_cast<std::size_t>(n) + static_cast<std::size_t>(col)];
          if (px * px + py * py > 1.0) {
            s = OpdSample{px, py, kNan, RayStatus::Ok};
            continue;
          }
          s = sample(px, py);
        }
      }
      for (int i = 0; i < options.fan_samples; ++i) {
        const double p = -1.0 + 2.0 * i / (options.fan_samples - 1);
        m.tangential.push_back(sample(0.0, p));
        m.sagittal.push_back(sample(p, 0.0));
      }

      // Statistics over the passed points: piston, then piston and tilt removed; P-V; the Zernike fit.
      std::vector<double> xs, ys, ws;
      for (const OpdSample& s : m.map) {
        if (s.px * s.px + s.py * s.py > 1.0) continue;
        if (s.status != RayStatus::Ok) {
          m.lost.add(s.status);
          continue;
        }
        xs.push_back(s.px);
        ys.push_back(s.py);
        ws.push_back(s.opd_waves);
      }
      m.samples = ws.size();
      if (ws.size() < 3) {
        throw ComputationError("field " + m.field_label + ", " + format_number(wavelength) + " nm: only " + std::to_string(ws.size()) +
                               " rays of the pupil grid pass (" + m.lost.to_string() + "): no wavefront");
      }
      double mean = 0.0;
      for (double w : ws) mean += w;
      mean /= static_cast<double>(ws.size());
      double sum2 = 0.0, lo = ws.front(), hi = ws.front();
      for (double w : ws) {
        sum2 += (w - mean) * (w - mean);
        lo = std::min(lo, w);
        hi = std::max(hi, w);
      }
      m.rms_waves = std::sqrt(sum2 / static_cast<double>(ws.size()));
      m.pv_waves = hi - lo;
      Eigen::MatrixXd a(static_cast<Eigen::Index>(ws.size()), 3);
      Eigen::VectorXd b(static_cast<Eigen::Index>(ws.size()));
      for (std::size_t k = 0; k < ws.size(); ++k) {
        a.row(static_cast<Eigen::Index>(k)) << 1.0, xs[k], ys[k];
        b(static_cast<Eigen::Index>(k)) = ws[k];
      }
      const Eigen::VectorXd residual = b - a * a.colPivHouseholderQr().solve(b);
      m.rms_tilt_removed_waves = std::sqrt(residual.squaredNorm() / static_cast<double>(ws.size()));
      m.zernike = fit_zernike(options.ordering, options.zernike_terms, xs, ys, ws);
      out.maps.push_back(std::move(m));
    }
  }
  return out;
}

std::string Wavefront::to_string() const {
  std::ostringstream os;
  char cell[96];
  os << "Wavefront: " << lens_name << "\n";
  os << "OPD in waves against the reference sphere: centred on the chief ray of " << reference_wavelength_nm
     << " nm on the image plane (z = " << image_plane_z_mm << " mm), through the exit pupil (z = " << exit_pupil_z_mm
     << " mm); W > 0 where the wavefront leads it.\n";
  for (const WavefrontMap& m : maps) {
    std::snprintf(cell, sizeof cell, "%.4f", m.wavelength_nm);
    os << "\nField " << m.field_label << " (relative " << m.relative_field << "), " << cell << " nm: ";
    std::snprintf(cell, sizeof cell, "RMS %.4f waves (%.4f with tilt removed), P-V %.4f waves", m.rms_waves, m.rms_tilt_removed_waves,
                  m.pv_waves);
    os << cell << ", reference sphere radius " << m.reference_radius_mm << " mm, " << m.samples << " rays, " << m.lost.to_string()
       << "\n";
    os << "  Zernike " << lensmith::to_string(ordering) << " coefficients (waves):\n";
    for (std::size_t j = 0; j < m.zernike.size(); ++j) {
      std::snprintf(cell, sizeof cell, "  Z%-3zu %+10.5f", j + 1, m.zernike[j]);
      os << cell << ((j + 1) % 4 == 0 || j + 1 == m.zernike.size() ? "\n" : "");
    }
  }
  return os.str();
}

}  // namespace lensmith

// One real ray, surface by surface (Welford ch. 4 for the quantities; the tracer does the work).
#include "lensmith/analysis/ray_trace_listing.h"

#include <cmath>
#include <sstream>

#include "analysis_detail.h"
#include "lensmith/core/errors.h"

namespace lensmith {

using analysis_detail::fixed;

void RayTraceOptions::validate() const {
  if (!std::isfinite(pupil.px) || !std::isfinite(pupil.py) || pupil.px * pupil.px + pupil.py * pupil.py > 1.0) {
    throw OptionsError("RayTraceOptions::pupil = (" + fixed(pupil.px, 6) + ", " + fixed(pupil.py, 6) +
                       "): must lie in the unit disc (px^2 + py^2 <= 1)");
  }
  if (wavelength_nm && !(*wavelength_nm > 100.0 && *wavelength_nm < 20000.0)) {
    throw OptionsError("RayTraceOptions::wavelength_nm = " + fixed(*wavelength_nm, 4) + ": must lie in (100, 20000) nm");
  }
  if (field.kind == FieldPoint::Kind::AngleDeg && !(std::abs(field.x) < 90.0 && std::abs(field.y) < 90.0)) {
    throw OptionsError("RayTraceOptions::field = " + field.to_string() + ": field angles must lie in (-90, 90) degrees");
  }
}

RayTraceListing trace_ray_listing(const Prescription& lens, const RayTraceOptions& options) {
  options.validate();
  lens.validate();
  TracerOptions tracer_options;
  tracer_options.image_plane = options.image_plane;
  const SequentialTracer tracer(lens, tracer_options);
  AimOptions aim;
  aim.aiming = options.aiming.value_or(lens.ray_aiming);
  const RayAimer aimer(tracer, aim);

  RayTraceListing out;
  out.lens_name = lens.name;
  out.field = options.field;
  out.pupil = options.pupil;
  out.wavelength_nm = options.wavelength_nm.value_or(lens.primary_wavelength_nm());
  out.image_plane_z_mm = tracer.image_plane_z_mm();
  const AimedRay aimed = aimer.make_ray(options.field, options.pupil, out.wavelength_nm);
  out.object_ray = aimed.ray;
  if (!aimed.ok()) {
    out.status = aimed.status;
    out.surface = aimed.surface;
    return out;
  }
  const TraceResult result = tracer.trace_forward(aimed.ray, &out.hits);
  out.folded = !lens.is_coaxial();
  if (out.folded) {
    for (const SurfaceHit& h : out.hits) {
      const SurfaceFrame frame = tracer.surface_frame(h.surface);
      SurfaceHit local = h;
      local.point_mm = frame.to_local(h.point_mm);
      local.direction_after = frame.axes.transpose() * h.direction_after;
      local.normal = frame.axes.transpose() * h.normal;
      out.local_hits.push_back(local);
    }
  }
  out.status = result.status;
  out.surface = result.surface;
  if (result.ok()) {
    out.image = ImagePoint::from(result.ray.position_mm);
    out.image_direction = result.ray.direction;
  }
  return out;
}

std::string RayTraceListing::to_string() const {
  std::ostringstream os;
  os << "Real ray: " << lens_name << "\n";
  os << "Field: " << field.to_string() << "; pupil (" << fixed(pupil.px, 4) << ", " << fixed(pupil.py, 4) << "), "
     << fixed(wavelength_nm, 4) << " nm\n";
  os << "Positions in mm, z = 0 at the vertex of surface 1; l, m, n: direction cosines after the surface\n\n";
  char line[192];
  std::snprintf(line, sizeof line, "%8s %14s %14s %14s %12s %12s %12s\n", "surface", "x", "y", "z", "l", "m", "n");
  os << line;
  const Eigen::Vector3d& p0 = object_ray.position_mm;
  const Eigen::Vector3d& d0 = object_ray.direction;
  std::snprintf(line, sizeof line, "%8s %14.6f %14.6f %14.6f %12.8f %12.8f %12.8f\n", "start", p0.x(), p0.y(), p0.z(), d0.x(), d0.y(),
                d0.z());
  os << line;
  for (const SurfaceHit& h : hits) {
    std::snprintf(line, sizeof line, "%8d %14.6f %14.6f %14.6f %12.8f %12.8f %12.8f\n", h.surface, h.point_mm.x(), h.point_mm.y(),
                  h.point_mm.z(), h.direction_after.x(), h.direction_after.y(), h.direction_after.z());
    os << line;
  }
  if (image) {
    std::snprintf(line, sizeof line, "%8s %14.6f %14.6f %14.6f %12.8f %12.8f %12.8f\n", "image", image->x_mm, image->y_mm, image->z_mm,
                  image_direction.x(), image_direction.y(), image_direction.z());
    os << line;
  }
  if (folded) {
    os << "\nIn each surface's own frame (as OpticStudio's Single Ray Trace lists it: z is the sag; the image in its own\n"
          "plane's frame, z reversed where light arrives toward its -z):\n";
    std::snprintf(line, sizeof line, "%8s %14s %14s %14s %12s %12s %12s\n", "surface", "x", "y", "z", "l", "m", "n");
    os << line;
    for (const SurfaceHit& h : local_hits) {
      std::snprintf(line, sizeof line, "%8d %14.6f %14.6f %14.6f %12.8f %12.8f %12.8f\n", h.surface, h.point_mm.x(), h.point_mm.y(),
                    h.point_mm.z(), h.direction_after.x(), h.direction_after.y(), h.direction_after.z());
      os << line;
    }
  }
  if (image) {
    os << "\nStatus: ok (reached the image plane at z = " << fixed(image_plane_z_mm, 6) << " mm)\n";
  } else {
    os << "\nStatus: " << lensmith::to_string(status);
    if (surface > 0) os << " at surface " << surface;
    os << " (the ray does not reach the image plane)\n";
  }
  return os.str();
}

}  // namespace lensmith

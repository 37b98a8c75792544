// The meridional cross-section of a lens with real ray bundles (lens_layout.h).
#include "lensmith/analysis/lens_layout.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "lensmith/core/errors.h"

namespace lensmith {

namespace {

// Points along each sag curve: enough that a strongly curved surface looks smooth at 1000 px.
constexpr int kProfileSamples = 64;
// The drawn part of a ray in object space, as a fraction of the total track: long enough to see the
// bundle's angle, short enough that the lens stays the larger part of the picture.
constexpr double kObjectSpaceFraction = 0.2;
// The pupil's rim rays are aimed this little inside it: a ray aimed exactly at the stop's edge is cut
// or passed by rounding, and the picture should show the beam the stop passes.
constexpr double kRimInset = 1e-4;
// Keeps the drawn semi-diameter where the sag is defined (a hemisphere is drawn to 99.9 % of R).
constexpr double kInsideSagDomain = 0.999;

// The surface's section by its local y-z plane, placed by its frame and drawn in the global y-z plane (a
// coaxial surface: its sag curve at its vertex; a tilted or folded one where it lies).
// Drawn from y_min to y_max (mm, local): the semi-diameter either side, or a decentred aperture's extent.
std::vector<LayoutPoint> profile_of(const Surface& s, const SurfaceFrame& frame, double y_min_mm, double y_max_mm) {
  std::vector<LayoutPoint> points;
  for (int i = 0; i <= kProfileSamples; ++i) {
    const double y = y_min_mm + (y_max_mm - y_min_mm) * i / kProfileSamples;
    double sag = 0.0, dx = 0.0, dy = 0.0;
    if (!s.sag_and_slope(0.0, y, sag, dx, dy)) sag = s.sag_mm(std::abs(y));
    const Eigen::Vector3d p = frame.to_global(Eigen::Vector3d(0.0, y, sag));
    points.push_back({p.z(), p.y()});
  }
  return points;
}

std::string fixed(int decimals, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

}  // namespace

void LayoutOptions::validate() const {
  if (rays_per_field < 1 || rays_per_field > 101) {
    throw OptionsError("LayoutOptions::rays_per_field = " + std::to_string(rays_per_field) + ": must be 1 to 101");
  }
}

double LayoutSurface::edge_z_mm() const { return profile.empty() ? vertex_z_mm : profile.back().z_mm; }

LensLayout compute_lens_layout(const AnalysisContext& context, const LayoutOptions& options) {
  options.validate();
  const Prescription& lens = context.lens();
  const SequentialTracer& tracer = context.tracer();
  LensLayout out;
  out.lens_name = lens.name;
  out.wavelength_nm = context.reference_wavelength_nm();
  out.relative_fields = context.relative_fields();
  out.stop_surface = context.paraxial().stop_surface();
  out.image_plane_z_mm = tracer.image_plane_z_mm();
  out.total_track_mm = out.image_plane_z_mm - tracer.vertex_z_mm(1);
  const int count = static_cast<int>(lens.surfaces.size());
  const double lead_mm = kObjectSpaceFraction * std::max(std::abs(out.total_track_mm), 1.0);

  // Rays first: surfaces without a clear semi-diameter are drawn as high as the rays go there.
  std::vector<double> ray_height(static_cast<std::size_t>(count) + 1, 0.0);
  for (double relative : out.relative_fields) {
    out.field_labels.push_back(context.field_label(relative));
    const FieldPoint field = context.field_at(relative);
    for (int i = 0; i < options.rays_per_field; ++i) {
      LayoutRay ray;
      ray.relative_field = relative;
      ray.pupil_py = options.rays_per_field == 1 ? 0.0 : (1.0 - kRimInset) * (-1.0 + 2.0 * i / (options.rays_per_field - 1));
      std::vector<SurfaceHit> path;
      const TracedRay traced = context.trace(field, {0.0, ray.pupil_py}, out.wavelength_nm, &path);
      ray.status = traced.status;
      ray.surface = traced.surface;
      if (!path.empty()) {
        // Object space: from a plane lead_mm before surface 1 (at most 3 lead_mm of ray for steep fields).
        const Eigen::Vector3d d = traced.object_ray.direction.normalized();
        const double length = std::min((path.front().point_mm.z() - (tracer.vertex_z_mm(1) - lead_mm)) / std::max(d.z(), 1e-9), 3.0 * lead_mm);
        const Eigen::Vector3d start = path.front().point_mm - length * d;
        ray.path.push_back({start.z(), start.y()});
      }
      for (const SurfaceHit& hit : path) {
        ray.path.push_back({hit.point_mm.z(), hit.point_mm.y()});
        double& h = ray_height[static_cast<std::size_t>(hit.surface)];
        h = std::max(h, std::abs(hit.point_mm.y()));
      }
      if (traced.ok()) {
        const Eigen::Vector3d on_image = tracer.image_point_in_global_frame(traced.image_ray.position_mm);
        ray.path.push_back({on_image.z(), on_image.y()});
        out.image_half_height_mm = std::max(out.image_half_height_mm, std::abs(traced.image_ray.position_mm.y()));
      }
      out.rays.push_back(std::move(ray));
    }
  }

  const ParaxialSystem& paraxial = context.paraxial();
  for (int k = 1; k <= count; ++k) {
    const Surface& s = lens.surfaces[static_cast<std::size_t>(k - 1)];
    LayoutSurface ls;
    ls.surface = k;
    ls.vertex_z_mm = tracer.vertex_z_mm(k);
    ls.is_stop = out.stop_surface && *out.stop_surface == k;
    ls.glass_after = !s.medium.is_air() && !s.mirror;
    ls.mirror = s.mirror;
    ls.semi_diameter_given = s.semi_diameter_mm.has_value();
    double h = s.semi_diameter_mm.value_or(ray_height[static_cast<std::size_t>(k)]);
    if (!(h > 0.0)) {
      h = std::abs(paraxial.marginal_ray().rows.at(static_cast<std::size_t>(k - 1)).y_mm);
      if (paraxial.chief_ray()) h += std::abs(paraxial.chief_ray()->rows.at(static_cast<std::size_t>(k - 1)).y_mm);
    }
    ls.semi_diameter_mm = std::min(h, kInsideSagDomain * s.max_semi_diameter_mm());
    if (!s.is_coordinate_break()) {
      double y_min = -ls.semi_diameter_mm, y_max = ls.semi_diameter_mm;
      if (s.aperture && !s.aperture->obscuration && s.aperture->decenter_y_mm != 0.0) {
        // An off-axis mirror or a decentred element: only the part its aperture keeps.
        const double half = s.aperture->shape == SurfaceAperture::Shape::Circular ? s.aperture->half_x_mm : s.aperture->half_y_mm;
        y_min = std::max(y_min, s.aperture->decenter_y_mm - half);
        y_max = std::min(y_max, s.aperture->decenter_y_mm + half);
      }
      ls.profile = profile_of(s, tracer.surface_frame(k), y_min, y_max);
    }
    out.surfaces.push_back(std::move(ls));
  }
  // A ray stopped outside a clear aperture met the surface's sphere beyond the lens's rim: end it
  // where it reaches the plane of that rim (the mount) instead, which is where the picture shows it stopped.
  for (LayoutRay& r : out.rays) {
    if (r.status != RayStatus::Vignetted || r.surface < 1 || r.path.size() < 2) continue;
    const double rim_z = out.surfaces[static_cast<std::size_t>(r.surface - 1)].edge_z_mm();
    const LayoutPoint a = r.path[r.path.size() - 2], b = r.path.back();
    if ((a.z_mm - rim_z) * (b.z_mm - rim_z) < 0.0) {
      const double t = (rim_z - a.z_mm) / (b.z_mm - a.z_mm);
      r.path.back() = {rim_z, a.y_mm + t * (b.y_mm - a.y_mm)};
    }
  }
  if (out.image_half_height_mm <= 0.0) {
    for (const LayoutSurface& s : out.surfaces) out.image_half_height_mm = std::max(out.image_half_height_mm, 0.25 * s.semi_diameter_mm);
  }
  for (std::size_t e = 0; e < 2; ++e) {
    const double sign = e == 0 ? -1.0 : 1.0;
    const Eigen::Vector3d end =
        tracer.image_point_in_global_frame(Eigen::Vector3d(0.0, sign * out.image_half_height_mm, out.image_plane_z_mm));
    out.image_plane_ends[e] = {end.z(), end.y()};
  }

  for (int k = 1; k < count; ++k) {
    const LayoutSurface& front = out.surfaces[static_cast<std::size_t>(k - 1)];
    const LayoutSurface& back = out.surfaces[static_cast<std::size_t>(k)];
    if (!front.glass_after) continue;
    LayoutElement e;
    e.front_surface = k;
    e.back_surface = k + 1;
    e.glass = lens.surfaces[static_cast<std::size_t>(k - 1)].medium.name();
    // The smaller surface steps out flat (at its edge z) to the larger semi-diameter; the edge joins them.
    const double edge = std::max(front.semi_diameter_mm, back.semi_diameter_mm);
    e.outline.push_back({front.edge_z_mm(), edge});
    for (auto it = front.profile.rbegin(); it != front.profile.rend(); ++it) e.outline.push_back(*it);
    e.outline.push_back({front.edge_z_mm(), -edge});
    e.outline.push_back({back.edge_z_mm(), -edge});
    for (const LayoutPoint& p : back.profile) e.outline.push_back(p);
    e.outline.push_back({back.edge_z_mm(), edge});
    out.elements.push_back(std::move(e));
  }
  return out;
}

std::string LensLayout::to_string() const {
  std::ostringstream os;
  os << lens_name << ": " << surfaces.size() << " surfaces, " << elements.size() << " glass element"
     << (elements.size() == 1 ? "" : "s") << " (cemented groups count each glass)\n";
  for (const LayoutElement& e : elements) {
    os << "  element surfaces " << e.front_surface << "-" << e.back_surface << "  " << e.glass << ", centre thickness "
       << fixed(3, surfaces[static_cast<std::size_t>(e.back_surface - 1)].vertex_z_mm -
                             surfaces[static_cast<std::size_t>(e.front_surface - 1)].vertex_z_mm)
       << " mm, semi-diameters " << fixed(3, surfaces[static_cast<std::size_t>(e.front_surface - 1)].semi_diameter_mm) << " / "
       << fixed(3, surfaces[static_cast<std::size_t>(e.back_surface - 1)].semi_diameter_mm) << " mm\n";
  }
  if (stop_surface) {
    os << "  stop: surface " << *stop_surface << " at z = " << fixed(3, surfaces[static_cast<std::size_t>(*stop_surface - 1)].vertex_z_mm)
       << " mm, semi-diameter " << fixed(3, surfaces[static_cast<std::size_t>(*stop_surface - 1)].semi_diameter_mm) << " mm\n";
  }
  os << "  total track (surface 1 to the image plane): " << fixed(3, total_track_mm) << " mm\n";
  std::size_t lost = 0;
  for (const LayoutRay& r : rays) lost += r.status == RayStatus::Ok ? 0 : 1;
  os << "  rays: " << rays.size() << " traced at " << fixed(2, wavelength_nm) << " nm, " << lost << " stopped before the image\n";
  return os.str();
}

}  // namespace lensmith

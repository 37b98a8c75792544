// RayAimer: rays aimed at the paraxial entrance pupil (Welford, Aberrations of Optical Systems, sec. 4.6) and
// real-stop aiming by Newton iteration, checked against the stop they aim at, against each other where they
// must agree (a stop in front of the lens), against the paraxial chief and marginal rays of a finite
// object (W. J. Smith's Cooke triplet, Modern Optical Engineering, 4th ed., ch. 6), and against brute force:
// dense backward scans from the stop point say which rays exist, and the aimer must find exactly those.
#include "lensmith/trace/ray_aiming.h"

#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "lensmith/prescription/lens_library.h"
#include "reference_lenses.h"

using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using namespace lensmith;
using lensmith::testing::make_surface;
using lensmith::testing::sasian_triplet;
using lensmith::testing::smith_cooke_triplet;

namespace {

// A few ulps of ~100-mm coordinates.
constexpr double kArithmetic_mm = 1e-12;
// See sequential_tracer_test.cpp: third-order departure of a ray at relative size s from the paraxial ray,
// heights within 1 mm x s^2, slopes within 0.1 x s^2, plus rounding of the divided coordinates.
constexpr double kThirdOrderHeight_mm = 1.0;
constexpr double kThirdOrderSlope = 0.1;
constexpr double kDividedRounding = 1e-12;

const std::vector<PupilCoordinate> kPupils = {{0.0, 0.0}, {0.0, 1.0}, {0.0, -1.0}, {1.0, 0.0},
                                              {0.6, 0.3}, {-0.5, 0.5}, {0.7, -0.7}, {-0.3, -0.8}};

AimOptions real_stop() {
  AimOptions options;
  options.aiming = RayAiming::RealStop;
  return options;
}

double slope_y(const Eigen::Vector3d& direction) { return direction.y() / direction.z(); }

// A crossing this far (mm) behind the previous refracting crossing means the two surfaces overlap there.
constexpr double kOverlap_mm = 1e-9;
// Brute-force scans: stop-space directions up to this angle from the axis; meridional scans in this many steps
// (0.0085 degrees), skew scans on a square grid of this many cells a side.
constexpr double kScanMaxAngleDeg = 85.0;
constexpr int kMeridionalSamples = 20000;
constexpr int kSkewCells = 200;

// The paraxial marginal-ray height at the stop: what pupil coordinate 1 means.
// The stop radius pupil coordinate 1 means; how it is chosen is checked against OpticStudio's below.
double stop_radius_of(const RayAimer& aimer) { return aimer.stop_radius_mm(); }

// True when no refracting crossing of `path` lies behind the previous one: a real ray never runs backward through
// glass or air between two surfaces. Planes with the same index on both sides (a stop, a dummy) are skipped:
// meeting them "behind" leaves the ray on its straight line.
bool physical_path(const SequentialTracer& tracer, const std::vector<SurfaceHit>& path, double wavelength_nm) {
  const SurfaceHit* previous = nullptr;
  for (const SurfaceHit& hit : path) {
    if (tracer.index_after(hit.surface - 1, wavelength_nm) == tracer.index_after(hit.surface, wavelength_nm)) continue;
    if (previous && (hit.point_mm - previous->point_mm).dot(previous->direction_after) < -kOverlap_mm) return false;
    previous = &hit;
  }
  return true;
}

// Checks a ray the aimer returned: traced without clipping, it crosses the stop at (px, py) x stop radius within
// the tolerance, along a physical path.
void check_on_stop(const SequentialTracer& unclipped, const RayAimer& aimer, const AimedRay& aimed,
                   const PupilCoordinate& pupil) {
  REQUIRE(aimed.ok());
  const int stop = aimer.paraxial().stop_surface();
  std::vector<SurfaceHit> path;
  unclipped.trace_forward(aimed.ray, &path);
  REQUIRE(path.size() >= static_cast<std::size_t>(stop));
  const Eigen::Vector3d& on_stop = path[static_cast<std::size_t>(stop) - 1].point_mm;
  CHECK_THAT(on_stop.x(), WithinAbs(pupil.px * stop_radius_of(aimer), AimOptions{}.tolerance_mm));
  CHECK_THAT(on_stop.y(), WithinAbs(pupil.py * stop_radius_of(aimer), AimOptions{}.tolerance_mm));
  path.resize(static_cast<std::size_t>(stop));
  CHECK(physical_path(unclipped, path, aimed.ray.wavelength_nm));
}

// Brute force, independent of the aimer: every ray through one point of the stop, traced backward over a dense set
// of stop-space directions through the surfaces in front of the stop. What survives along a physical path gives
// the object-space directions (or, for a finite object, the points) that can send a ray through that stop point.
class StopPointScan {
 public:
  StopPointScan(const Prescription& lens, const RayAimer& aimer, const PupilCoordinate& pupil)
      : lens_(lens), stop_(aimer.paraxial().stop_surface()) {
    // The stop point is put on the vertex plane, and the first backward crossing is not checked against it.
    REQUIRE(lens.surfaces[static_cast<std::size_t>(stop_) - 1].is_plane());
    Prescription front = lens;
    front.surfaces.resize(static_cast<std::size_t>(stop_) - 1);
    front.image_at_paraxial_focus = false;
    front.aperture = ApertureSpec{ApertureSpec::Kind::EntrancePupilDiameter, 1.0};  // the stop is not in it
    TracerOptions options;
    options.clip_apertures = false;
    options.image_distance_mm = 0.0;
    front_.emplace(front, options);
    unclipped_.emplace(lens, options);
    point_ = Eigen::Vector3d(pupil.px * stop_radius_of(aimer), pupil.py * stop_radius_of(aimer),
                             unclipped_->vertex_z_mm(stop_));  // the shipped stops are flat
  }

  // Meridional stop point (px = 0): the object-space ray of each stop-space angle -85..85 degrees in the y-z
  // plane, empty where no physical ray leaves surface 1 toward the object.
  void scan_meridional() {
    rays_.clear();
    for (int i = 0; i <= kMeridionalSamples; ++i) {
      const double angle = rad_from_deg(-kScanMaxAngleDeg + 2.0 * kScanMaxAngleDeg * i / kMeridionalSamples);
      rays_.push_back(backward(Eigen::Vector3d(0.0, std::sin(angle), std::cos(angle))));
    }
  }
  // Any stop point: a grid of arriving directions with transverse components (a, b) in [-0.95, 0.95]^2.
  void scan_grid() {
    rays_.clear();
    for (int i = 0; i <= kSkewCells; ++i) {
      for (int j = 0; j <= kSkewCells; ++j) {
        const double a = -0.95 + 1.9 * i / kSkewCells;
        const double b = -0.95 + 1.9 * j / kSkewCells;
        rays_.push_back(a * a + b * b < 1.0 ? backward(Eigen::Vector3d(a, b, std::sqrt(1.0 - a * a - b * b)))
                                            : std::nullopt);
      }
    }
  }

  // After scan_meridional: does a ray leave toward the object at `field_deg` (in the y-z plane)? Yes when two
  // neighbouring samples bracket it (the intermediate value theorem; neighbours are 0.0085 degrees apart).
  bool meridional_reaches(double field_deg) const {
    return meridional_brackets([&](const Ray& r) { return std::atan2(r.direction.y(), r.direction.z()); },
                               rad_from_deg(field_deg));
  }
  // After scan_meridional: does a ray come from the point at height y_mm on the plane z = z_mm?
  bool meridional_reaches_point(double y_mm, double z_mm) const {
    return meridional_brackets(
        [&](const Ray& r) { return r.position_mm.y() + (z_mm - r.position_mm.z()) * r.direction.y() / r.direction.z(); },
        y_mm);
  }
  // After scan_meridional: the largest field angle (degrees) any physical ray reaches.
  double meridional_max_field_deg() const {
    double largest = -90.0;
    for (const auto& r : rays_) {
      if (r) largest = std::max(largest, deg_from_rad(std::atan2(r->direction.y(), r->direction.z())));
    }
    return largest;
  }
  // After scan_grid: does the image of a grid triangle with three physical corners contain the direction? Then a
  // ray exists (the map from stop-space to object-space directions is smooth across a cell).
  bool grid_reaches(const Eigen::Vector3d& direction) const {
    const Eigen::Vector2d target(direction.x(), direction.y());
    const int n = kSkewCells + 1;
    for (int i = 0; i + 1 < n; ++i) {
      for (int j = 0; j + 1 < n; ++j) {
        const int corners[4] = {i * n + j, (i + 1) * n + j, (i + 1) * n + j + 1, i * n + j + 1};
        for (int half = 0; half < 2; ++half) {
          const auto& a = rays_[static_cast<std::size_t>(corners[0])];
          const auto& b = rays_[static_cast<std::size_t>(corners[1 + half])];
          const auto& c = rays_[static_cast<std::size_t>(corners[2 + half])];
          if (!a || !b || !c) continue;
          const Eigen::Vector2d pa(a->direction.x(), a->direction.y());
          const Eigen::Vector2d e1 = Eigen::Vector2d(b->direction.x(), b->direction.y()) - pa;
          const Eigen::Vector2d e2 = Eigen::Vector2d(c->direction.x(), c->direction.y()) - pa;
          const Eigen::Vector2d q = target - pa;
          const double det = e1.x() * e2.y() - e1.y() * e2.x();
          if (det == 0.0) continue;
          const double u = (q.x() * e2.y() - q.y() * e2.x()) / det;
          const double v = (e1.x() * q.y() - e1.y() * q.x()) / det;
          if (u >= 0.0 && v >= 0.0 && u + v <= 1.0) return true;
        }
      }
    }
    return false;
  }

 private:
  // The ray arriving at the stop point along `arriving`, traced backward: in object space (forward direction,
  // position on surface 1) when its path is physical and it leaves toward the object.
  std::optional<Ray> backward(const Eigen::Vector3d& arriving) {
    Ray ray;
    ray.position_mm = point_;
    ray.direction = -arriving;
    ray.wavelength_nm = lens_.primary_wavelength_nm();
    const TraceResult r = front_->trace_backward(ray, &path_);
    // The stop is a plane in air, so the first crossing may lie on either side of it (only refracting ones count).
    if (!r.ok() || !physical_path(*front_, path_, ray.wavelength_nm)) return std::nullopt;
    Ray out = r.ray;
    out.direction = -out.direction;
    if (!(out.direction.z() > 0.0)) return std::nullopt;
    return out;
  }
  template <typename Value>
  bool meridional_brackets(Value value, double wanted) const {
    for (std::size_t i = 0; i + 1 < rays_.size(); ++i) {
      if (rays_[i] && rays_[i + 1] && (value(*rays_[i]) - wanted) * (value(*rays_[i + 1]) - wanted) <= 0.0) return true;
    }
    return false;
  }

  Prescription lens_;
  int stop_ = 0;
  std::optional<SequentialTracer> front_;
  std::optional<SequentialTracer> unclipped_;
  Eigen::Vector3d point_{0.0, 0.0, 0.0};
  std::vector<std::optional<Ray>> rays_;
  std::vector<SurfaceHit> path_;
};

// Hexapolar pupil pattern with `rings` rings: the centre, then 6 k points on ring k (radius k / rings), the first at
// the top of the pupil (px = 0, py > 0).
std::vector<PupilCoordinate> hexapolar(int rings) {
  std::vector<PupilCoordinate> points = {{0.0, 0.0}};
  for (int k = 1; k <= rings; ++k) {
    for (int j = 0; j < 6 * k; ++j) {
      const double angle = 2.0 * kPi * j / (6 * k);
      const double radius = static_cast<double>(k) / rings;
      // Exact zeros on the meridian, so those points use the meridional scan.
      const double px = (j == 0 || 2 * j == 6 * k) ? 0.0 : radius * std::sin(angle);
      points.push_back({px, radius * std::cos(angle)});
    }
  }
  return points;
}

// The singlet with a stop behind it that the analysis engineer reported: R1 = 50, t = 5, n_d 1.5168 / V_d 64.17,
// R2 = -50, 20 mm of air to a flat stop of semi-diameter 5 mm, 40 mm to the image.
Prescription rear_stop_singlet() {
  Prescription lens;
  lens.name = "rear-stop singlet";
  lens.surfaces = {make_surface(50.0, 5.0, MaterialSpec::model(1.5168, 64.17)),
                   make_surface(-50.0, 20.0, MaterialSpec::air()),
                   make_surface(kInfinity, 40.0, MaterialSpec::air(), 5.0)};
  lens.surfaces[2].is_stop = true;
  lens.aperture = ApertureSpec{ApertureSpec::Kind::FloatByStop, 0.0};
  lens.field = FieldSpec{FieldSpec::Kind::AngleDeg, {25.0}};
  return lens;
}

}  // namespace

TEST_CASE("real-stop aiming puts the real ray on the stop at (px, py) x stop radius within the tolerance, or shows that no ray gets there",
          "[aiming]") {
  int aimed_count = 0;
  int absent_count = 0;
  for (const char* id : {"smith-cooke-triplet", "sasian-triplet", "angenieux-double-gauss-1953", "aspherical-fisheye",
                         "pbrt-fisheye-10mm", "nikon-retrofocus-1971"}) {
    const Prescription lens = LensLibrary::load(id).prescription;
    TracerOptions unclipped;
    unclipped.clip_apertures = false;  // to see where the aimed ray crosses the stop even if a rim cuts it later
    const SequentialTracer tracer(lens, unclipped);
    const RayAimer aimer(tracer, real_stop());
    // Pupil coordinate 1 is the beam edge the aperture specification defines: for an EPD, where the real
    // axial ray through the paraxial pupil's edge crosses the stop (Smith's triplet: 10.477 mm, beyond its
    // 10.3-mm stop rim, which these unclipped traces ignore).
    const std::vector<double> fields = lens.field ? std::vector<double>{0.0, 0.5, 1.0} : std::vector<double>{0.0};
    std::vector<SurfaceHit> path;
    for (double relative : fields) {
      const FieldPoint field = lens.field ? aimer.field_at(relative) : FieldPoint::angle_deg(0.0);
      for (const PupilCoordinate& pupil : kPupils) {
        for (double wavelength : lens.wavelengths_nm) {
          INFO(id << ", " << field.to_string() << ", pupil (" << pupil.px << ", " << pupil.py << "), " << wavelength
                  << " nm");
          const AimedRay aimed = aimer.make_ray(field, pupil, wavelength);
          INFO(to_string(aimed.status) << " at surface " << aimed.surface);
          if (!aimed.ok()) {
            // Only where no physical ray exists: the edge of Smith's triplet at full field and of the Nikon
            // retrofocus at 37.5 degrees, whose only rays would cross the first elements where their two faces
            // overlap (far outside the clear apertures).
            StopPointScan scan(lens, aimer, pupil);
            const Eigen::Vector3d d = Eigen::Vector3d(0.0, std::tan(rad_from_deg(field.y)), 1.0).normalized();
            if (pupil.px == 0.0) {
              scan.scan_meridional();
              CHECK_FALSE(scan.meridional_reaches(field.y));
            } else {
              scan.scan_grid();
              CHECK_FALSE(scan.grid_reaches(d));
            }
            ++absent_count;
            continue;
          }
          check_on_stop(tracer, aimer, aimed, pupil);
          tracer.trace_forward(aimed.ray, &path);
          // An angle field's rays start in object space, in front of surface 1.
          CHECK(aimed.ray.position_mm.z() < path.front().point_mm.z());
          ++aimed_count;
        }
      }
    }
  }
  CHECK(aimed_count == 324);
  CHECK(absent_count == 12);
}

TEST_CASE("with the stop in front of the lens both aimings give the same ray", "[aiming]") {
  // A flat stop of radius 5 mm as surface 1, then a biconvex singlet: the entrance pupil is the stop itself,
  // so the ray through (px, py) x 5 mm on the pupil plane is the ray through the same point of the stop.
  Prescription lens;
  lens.name = "stop in front of a singlet";
  lens.surfaces = {make_surface(kInfinity, 3.0, MaterialSpec::air(), 5.0),
                   make_surface(30.0, 4.0, MaterialSpec::model(1.5168, 64.17), 8.0),
                   make_surface(-30.0, 27.0, MaterialSpec::air(), 8.0)};
  lens.surfaces[0].is_stop = true;
  lens.aperture = ApertureSpec{ApertureSpec::Kind::FloatByStop, 0.0};
  lens.field = FieldSpec{FieldSpec::Kind::AngleDeg, {15.0}};
  const SequentialTracer tracer(lens);
  const RayAimer paraxial(tracer);
  const RayAimer real(tracer, real_stop());
  REQUIRE(paraxial.paraxial().entrance_pupil().z_mm == 0.0);
  for (double relative : {0.0, 0.6, 1.0}) {
    for (const PupilCoordinate& pupil : kPupils) {
      INFO("field " << relative << ", pupil (" << pupil.px << ", " << pupil.py << ")");
      const AimedRay a = paraxial.make_ray(paraxial.field_at(relative), pupil, kWavelengthD_nm);
      const AimedRay b = real.make_ray(real.field_at(relative), pupil, kWavelengthD_nm);
      REQUIRE(a.ok());
      REQUIRE(b.ok());
      // Both start on the same wavefront; they differ only by the Newton tolerance on the stop.
      CHECK_THAT((a.ray.position_mm - b.ray.position_mm).norm(), WithinAbs(0.0, AimOptions{}.tolerance_mm));
      CHECK(a.ray.direction == b.ray.direction);
      const TraceResult ta = tracer.trace_forward(a.ray);
      const TraceResult tb = tracer.trace_forward(b.ray);
      CHECK(ta.status == tb.status);
      CHECK_THAT((ta.ray.position_mm - tb.ray.position_mm).norm(), WithinAbs(0.0, 1e-9));
    }
  }
}

TEST_CASE("real aiming that cannot converge says so: one iteration, or a stop point no ray reaches", "[aiming][status]") {
  const Prescription lens = smith_cooke_triplet();
  const SequentialTracer tracer(lens);
  AimOptions one_step = real_stop();
  one_step.max_iterations = 1;
  const RayAimer hasty(tracer, one_step);
  // Full field, top of the pupil: the paraxial guess misses the stop point by ~0.2 mm; one Newton step with a
  // finite-difference Jacobian leaves ~1e-5 mm, far above 1e-10.
  const AimedRay once = hasty.make_ray(hasty.field_at(1.0), {0.0, 1.0}, kWavelengthD_nm);
  CHECK(once.status == RayStatus::NotConverged);
  CHECK(once.surface == 5);
  CHECK(to_string(once.status) == "not_converged");
  // On axis at the pupil centre the paraxial guess is exact, so even one iteration is enough.
  CHECK(hasty.make_ray(hasty.field_at(0.0), {0.0, 0.0}, kWavelengthD_nm).ok());

  // Three stop radii (31 mm on the stop) would need heights beyond surface 1's 37.4-mm radius: every ray that
  // could get there misses a surface, and the aimer reports how its trace died.
  const RayAimer aimer(tracer, real_stop());
  const AimedRay unreachable = aimer.make_ray(aimer.field_at(0.0), {0.0, 3.0}, kWavelengthD_nm);
  CHECK_FALSE(unreachable.ok());
  CHECK(unreachable.surface >= 1);
  CHECK(unreachable.surface <= 5);
}

TEST_CASE("paraxial-pupil aiming: each ray crosses the pupil plane at (px, py) x EP radius, and an angle field's rays start on one plane wavefront in front of surface 1",
          "[aiming]") {
  // A singlet whose first surface is concave to the object: its rim (semi-diameter 8 mm) lies 1.67 mm in
  // front of the vertex, so rays must start before z = -1.67.
  Prescription lens;
  lens.surfaces = {make_surface(-20.0, 3.0, MaterialSpec::model(1.6, 40.0), 8.0),
                   make_surface(-10.0, 40.0, MaterialSpec::air(), 9.0)};
  lens.aperture = ApertureSpec{ApertureSpec::Kind::EntrancePupilDiameter, 8.0};
  lens.field = FieldSpec{FieldSpec::Kind::AngleDeg, {25.0}};
  const double rim_sag = (-1.0 / 20.0) * 64.0 / (1.0 + std::sqrt(1.0 - 64.0 / 400.0));
  const std::vector<Prescription> lenses = {lens, smith_cooke_triplet(), sasian_triplet()};
  for (std::size_t which = 0; which < lenses.size(); ++which) {
    const Prescription& p = lenses[which];
    const SequentialTracer tracer(p);
    const RayAimer aimer(tracer);
    const Pupil& ep = aimer.paraxial().entrance_pupil();
    const double front_z = which == 0 ? rim_sag : 0.0;  // the triplets are convex to the object
    for (double relative : {0.0, 0.5, 1.0}) {
      const FieldPoint field = aimer.field_at(relative);
      const Eigen::Vector3d d = Eigen::Vector3d(0.0, std::tan(rad_from_deg(field.y)), 1.0).normalized();
      std::vector<double> wavefront_offsets;
      for (const PupilCoordinate& pupil : kPupils) {
        INFO(p.name << ", " << field.to_string() << ", pupil (" << pupil.px << ", " << pupil.py << ")");
        const AimedRay aimed = aimer.make_ray(field, pupil, kWavelengthD_nm);
        REQUIRE(aimed.ok());
        CHECK(aimed.ray.direction == d);
        CHECK(aimed.ray.position_mm.z() < front_z);
        const double to_pupil = (ep.z_mm - aimed.ray.position_mm.z()) / d.z();
        const Eigen::Vector3d at_pupil = aimed.ray.position_mm + to_pupil * d;
        CHECK_THAT(at_pupil.x(), WithinAbs(pupil.px * 0.5 * ep.diameter_mm, kArithmetic_mm));
        CHECK_THAT(at_pupil.y(), WithinAbs(pupil.py * 0.5 * ep.diameter_mm, kArithmetic_mm));
        wavefront_offsets.push_back((aimed.ray.position_mm - Eigen::Vector3d(0.0, 0.0, ep.z_mm)).dot(d));
      }
      for (double offset : wavefront_offsets) CHECK_THAT(offset, WithinAbs(wavefront_offsets.front(), kArithmetic_mm));
    }
  }
}

TEST_CASE("a finite object: object-height rays start at y = +h on the object plane (as in Zemax) and reproduce the paraxial rays in the small limit",
          "[aiming]") {
  // Smith's triplet focused on an object 1 m in front, with an object-height field of 100 mm. The paraxial
  // chief-ray table follows conventions.h (a rising chief ray: object point at y = -100, image at y > 0);
  // FieldPoint::object_height_mm(h) puts the object point at y = +h as Zemax does, so the paraxial table is
  // reproduced by the height -h.
  Prescription lens = smith_cooke_triplet();
  lens.object_distance_mm = 1000.0;
  lens.field = FieldSpec{FieldSpec::Kind::ObjectHeightMm, {100.0}};
  const SequentialTracer tracer(lens);  // image plane at the paraxial image of the object (image_at_paraxial_focus)
  const RayAimer aimer(tracer);
  const ParaxialSystem& paraxial = aimer.paraxial();
  REQUIRE(paraxial.chief_ray().has_value());
  CHECK(paraxial.chief_ray()->image_height_mm > 0.0);

  const AimedRay full = aimer.make_ray(aimer.field_at(1.0), {0.0, 0.0}, kWavelengthD_nm);
  REQUIRE(full.ok());
  CHECK(full.ray.position_mm == Eigen::Vector3d(0.0, 100.0, -1000.0));

  std::vector<SurfaceHit> path;
  for (double s : {1e-4, 1e-5}) {
    const double height_tolerance = kThirdOrderHeight_mm * s * s + kDividedRounding;
    const double slope_tolerance = kThirdOrderSlope * s * s + kDividedRounding;
    const ParaxialRayTable* tables[] = {&*paraxial.chief_ray(), &paraxial.marginal_ray()};
    const AimedRay rays[] = {aimer.make_ray(FieldPoint::object_height_mm(-s * 100.0), {0.0, 0.0}, kWavelengthD_nm),
                             aimer.make_ray(FieldPoint::object_height_mm(0.0), {0.0, s}, kWavelengthD_nm)};
    for (int which = 0; which < 2; ++which) {
      INFO((which == 0 ? "chief" : "marginal") << " ray, s = " << s);
      REQUIRE(rays[which].ok());
      const TraceResult r = tracer.trace_forward(rays[which].ray, &path);
      REQUIRE(r.ok());
      const ParaxialRayTable& table = *tables[which];
      CHECK_THAT(slope_y(rays[which].ray.direction) / s, WithinAbs(table.object_slope, slope_tolerance));
      for (std::size_t k = 0; k < path.size(); ++k) {
        INFO("surface " << k + 1);
        CHECK_THAT(path[k].point_mm.y() / s, WithinAbs(table.rows[k].y_mm, height_tolerance));
        CHECK_THAT(slope_y(path[k].direction_after) / s, WithinAbs(table.rows[k].u_after, slope_tolerance));
      }
      CHECK_THAT(r.ray.position_mm.y() / s, WithinAbs(table.image_height_mm, height_tolerance));
    }
  }
}

TEST_CASE("field_at scales the prescription's maximum field, and angle fields of a finite object start on the object plane",
          "[aiming]") {
  const Prescription sasian = sasian_triplet();  // fields 0, 14, 20 degrees
  const SequentialTracer tracer(sasian);
  const RayAimer aimer(tracer);
  const FieldPoint half = aimer.field_at(0.5);
  CHECK(half.kind == FieldPoint::Kind::AngleDeg);
  CHECK(half.y == 10.0);
  CHECK(half.x == 0.0);
  CHECK(half.to_string() == "field angle (x 0, y 10) deg");
  CHECK(half.point_mm == Eigen::Vector3d::Zero());  // not left uninitialised by the factory
  CHECK(FieldPoint::object_height_mm(2.0).point_mm == Eigen::Vector3d::Zero());

  // An image-height field: the maximum field is the angle whose paraxial chief ray lands at that height.
  Prescription by_image = sasian;
  by_image.field = FieldSpec{FieldSpec::Kind::ImageHeightMm, {18.0}};
  const SequentialTracer image_tracer(by_image);
  const RayAimer image_aimer(image_tracer);
  const FieldPoint edge = image_aimer.field_at(1.0);
  CHECK(edge.kind == FieldPoint::Kind::AngleDeg);
  // Paraxial chief rays are linear in their slope: the 20-degree chief ray of the Sasian triplet lands at
  // h20 on the paraxial image plane, so 18 mm needs tan(angle) = tan(20 deg) x 18 / h20.
  const ParaxialSystem& p = aimer.paraxial();
  const ParaxialRayRow& last = p.chief_ray()->rows.back();
  const double h20 = last.y_mm + p.image_distance_mm() * last.u_after;
  CHECK_THAT(std::tan(rad_from_deg(edge.y)), WithinRel(std::tan(rad_from_deg(20.0)) * 18.0 / h20, 1e-12));
  // Half the image height is half the slope (not half the angle).
  CHECK_THAT(std::tan(rad_from_deg(image_aimer.field_at(0.5).y)), WithinRel(0.5 * std::tan(rad_from_deg(edge.y)), 1e-12));

  // An angle field with the object 500 mm away: the rays come from the object-plane point on the chief ray.
  Prescription near = sasian;
  near.object_distance_mm = 500.0;
  const SequentialTracer near_tracer(near);
  const RayAimer near_aimer(near_tracer);
  const AimedRay chief = near_aimer.make_ray(FieldPoint::angle_deg(10.0), {0.0, 0.0}, kWavelengthD_nm);
  REQUIRE(chief.ok());
  CHECK_THAT(chief.ray.position_mm.z(), WithinAbs(-500.0, kArithmetic_mm));
  CHECK_THAT(slope_y(chief.ray.direction), WithinAbs(std::tan(rad_from_deg(10.0)), kArithmetic_mm));
  const AimedRay rim = near_aimer.make_ray(FieldPoint::angle_deg(10.0), {0.0, 1.0}, kWavelengthD_nm);
  CHECK(rim.ray.position_mm == chief.ray.position_mm);
}

TEST_CASE("aim options validate themselves and bad inputs are InvalidInput or a typed error", "[aiming][status]") {
  AimOptions options;
  options.tolerance_mm = 0.0;
  CHECK_THROWS_WITH(options.validate(), Catch::Contains("AimOptions::tolerance_mm") && Catch::Contains("> 0"));
  options = AimOptions{};
  options.max_iterations = 0;
  CHECK_THROWS_WITH(options.validate(), Catch::Contains("AimOptions::max_iterations = 0"));
  const SequentialTracer tracer(sasian_triplet());
  CHECK_THROWS_AS(RayAimer(tracer, options), OptionsError);

  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const AimOptions& mode : {AimOptions{}, real_stop()}) {
    const RayAimer aimer(tracer, mode);
    CHECK(aimer.make_ray(FieldPoint::angle_deg(5.0), {nan, 0.0}, kWavelengthD_nm).status == RayStatus::InvalidInput);
    CHECK(aimer.make_ray(FieldPoint::angle_deg(nan), {0.0, 0.0}, kWavelengthD_nm).status == RayStatus::InvalidInput);
    CHECK(aimer.make_ray(FieldPoint::angle_deg(90.0), {0.0, 0.0}, kWavelengthD_nm).status == RayStatus::InvalidInput);
    CHECK(aimer.make_ray(FieldPoint::angle_deg(5.0), {0.0, 0.0}, -1.0).status == RayStatus::InvalidInput);
    // An object height needs a finite object; the Sasian triplet's object is at infinity.
    CHECK_THROWS_AS(aimer.make_ray(FieldPoint::object_height_mm(3.0), {0.0, 0.0}, kWavelengthD_nm), OptionsError);
  }
  // An explicit object point on the pupil plane at the aimed point leaves no direction.
  const RayAimer aimer(tracer);
  const double z_ep = aimer.paraxial().entrance_pupil().z_mm;
  const AimedRay degenerate = aimer.make_ray(FieldPoint::object_point_mm({0.0, 0.0, z_ep}), {0.0, 0.0}, kWavelengthD_nm);
  CHECK(degenerate.status == RayStatus::InvalidInput);
}

TEST_CASE("rear-stop singlet: real-stop aiming finds every ray that exists from 0 to 25 degrees over a hexapolar pupil, and only those",
          "[aiming][robust]") {
  // The bending that pupil aberration needs is not there: beyond a certain field the lens cannot send a ray through
  // a given stop point at all. The meridional scans put the ends at 12.10 degrees for the stop centre, 19.93 for the
  // top of the stop (py = 1) and 3.81 for its bottom (py = -1); the same numbers follow from a hand trace in the
  // meridional plane (two spheres, Snell's law). Beyond 19.93 degrees no ray passes the 5-mm stop.
  const Prescription lens = rear_stop_singlet();
  TracerOptions no_clipping;
  no_clipping.clip_apertures = false;
  const SequentialTracer tracer(lens, no_clipping);
  const RayAimer aimer(tracer, real_stop());
  REQUIRE_THAT(stop_radius_of(aimer), WithinAbs(5.0, kArithmetic_mm));
  int aimed = 0;
  int absent = 0;
  for (const PupilCoordinate& pupil : hexapolar(3)) {
    StopPointScan scan(lens, aimer, pupil);
    const bool meridional = pupil.px == 0.0;
    if (meridional) {
      scan.scan_meridional();
    } else {
      scan.scan_grid();
    }
    for (int degrees = 0; degrees <= 25; ++degrees) {
      INFO("field " << degrees << " deg, pupil (" << pupil.px << ", " << pupil.py << ")");
      const FieldPoint field = FieldPoint::angle_deg(degrees);
      const AimedRay ray = aimer.make_ray(field, pupil, kWavelengthD_nm);
      INFO(to_string(ray.status) << " at surface " << ray.surface);
      const Eigen::Vector3d d = Eigen::Vector3d(0.0, std::tan(rad_from_deg(degrees)), 1.0).normalized();
      // Meridional scans decide both ways; a grid triangle that contains the direction proves a ray exists.
      const bool exists = meridional ? scan.meridional_reaches(degrees) : scan.grid_reaches(d);
      if (ray.ok()) {
        check_on_stop(tracer, aimer, ray, pupil);
        CHECK(ray.ray.direction == d);
        if (meridional) CHECK(exists);
        ++aimed;
      } else {
        CHECK_FALSE(exists);
        CHECK((ray.status == RayStatus::NotConverged || ray.status == RayStatus::Missed ||
               ray.status == RayStatus::TotalInternalReflection));
        CHECK(ray.surface >= 1);
        CHECK(ray.surface <= 3);
        ++absent;
      }
      if (pupil.px == 0.0 && pupil.py == 0.0) CHECK(ray.ok() == (degrees <= 12));
      if (degrees >= 20) CHECK_FALSE(ray.ok());
    }
  }
  // 425 of the 962 requests have a ray; the rest fail, as the scans show they must.
  CHECK(aimed == 425);
  CHECK(absent == 37 * 26 - 425);
}

TEST_CASE("pbrt-fisheye-10mm: the chief ray and the 0.9 pupil rays aim at every field up to its stated 77.95 degrees",
          "[aiming][robust][fisheye]") {
  // The front group bends the 77.95-degree chief ray to 31.6 degrees at the stop; the entrance pupil moves
  // forward and grows off axis (pupil aberration), so the paraxial pupil is far from where the real rays pass.
  const Prescription lens = LensLibrary::load("pbrt-fisheye-10mm").prescription;
  TracerOptions no_clipping;
  no_clipping.clip_apertures = false;
  const SequentialTracer tracer(lens, no_clipping);
  const RayAimer aimer(tracer, real_stop());
  REQUIRE(lens.field->max_value() == 77.95);
  const std::vector<PupilCoordinate> pupils = {{0.0, 0.0}, {0.0, 0.9}, {0.0, -0.9}, {0.9, 0.0}, {-0.9, 0.0}};
  const double z_ep = aimer.paraxial().entrance_pupil().z_mm;
  std::vector<double> fields;
  for (int i = 0; i <= 155; ++i) fields.push_back(0.5 * i);
  fields.push_back(77.95);
  for (double degrees : fields) {
    const Eigen::Vector3d d = Eigen::Vector3d(0.0, std::tan(rad_from_deg(degrees)), 1.0).normalized();
    for (double wavelength : lens.wavelengths_nm) {
      std::vector<double> wavefront_offsets;
      for (const PupilCoordinate& pupil : pupils) {
        INFO("field " << degrees << " deg, pupil (" << pupil.px << ", " << pupil.py << "), " << wavelength << " nm");
        const AimedRay ray = aimer.make_ray(FieldPoint::angle_deg(degrees), pupil, wavelength);
        INFO(to_string(ray.status) << " at surface " << ray.surface);
        check_on_stop(tracer, aimer, ray, pupil);
        CHECK(ray.ray.direction == d);
        // Every ray of the field starts on one plane wavefront, so their optical paths compare directly.
        wavefront_offsets.push_back((ray.ray.position_mm - Eigen::Vector3d(0.0, 0.0, z_ep)).dot(d));
      }
      for (double offset : wavefront_offsets) CHECK_THAT(offset, WithinAbs(wavefront_offsets.front(), kArithmetic_mm));
    }
  }
}

TEST_CASE("beyond what a fisheye passes the aimer fails cleanly: pbrt-fisheye-10mm's stop at py = -0.9 takes no ray from 84 degrees",
          "[aiming][robust][fisheye]") {
  // The lower part of the stop is the first to become unreachable at the extreme field: the rays it would need
  // cross the first two elements where their faces overlap (outside the clear apertures). The dense scan puts the
  // last ray through (0, -0.9) at 82.5 degrees; the upper rim and the centre take rays to within 0.02 degrees of 90.
  const Prescription lens = LensLibrary::load("pbrt-fisheye-10mm").prescription;
  TracerOptions no_clipping;
  no_clipping.clip_apertures = false;
  const SequentialTracer tracer(lens, no_clipping);
  const RayAimer aimer(tracer, real_stop());
  const PupilCoordinate low{0.0, -0.9};
  StopPointScan scan(lens, aimer, low);
  scan.scan_meridional();
  CHECK_THAT(scan.meridional_max_field_deg(), WithinAbs(82.5, 0.05));
  CHECK(scan.meridional_reaches(82.0));
  check_on_stop(tracer, aimer, aimer.make_ray(FieldPoint::angle_deg(82.0), low, kWavelengthD_nm), low);
  for (double degrees : {84.0, 86.0, 89.0}) {
    INFO("field " << degrees << " deg");
    CHECK_FALSE(scan.meridional_reaches(degrees));
    const AimedRay ray = aimer.make_ray(FieldPoint::angle_deg(degrees), low, kWavelengthD_nm);
    CHECK_FALSE(ray.ok());
    CHECK(ray.surface >= 1);
    CHECK(ray.surface <= aimer.paraxial().stop_surface());
  }
}

TEST_CASE("the real chief ray of each fisheye exists to 89 degrees and its image height grows monotonically with the field",
          "[aiming][robust][fisheye]") {
  // A fisheye maps the hemisphere onto a finite image (equidistant or equisolid-like), so the chief-ray height on
  // the image plane must rise with the field all the way out.
  for (const char* id : {"pbrt-fisheye-10mm", "aspherical-fisheye", "minolta-fisheye-1978"}) {
    const Prescription lens = LensLibrary::load(id).prescription;
    TracerOptions no_clipping;
    no_clipping.clip_apertures = false;
    const SequentialTracer tracer(lens, no_clipping);
    const RayAimer aimer(tracer, real_stop());
    double previous_height = -1.0;
    for (int degrees = 0; degrees <= 89; ++degrees) {
      INFO(id << ", field " << degrees << " deg");
      const AimedRay chief = aimer.make_ray(FieldPoint::angle_deg(degrees), {0.0, 0.0}, kWavelengthD_nm);
      INFO(to_string(chief.status) << " at surface " << chief.surface);
      check_on_stop(tracer, aimer, chief, {0.0, 0.0});
      const TraceResult image = tracer.trace_forward(chief.ray);
      REQUIRE(image.ok());
      CHECK(image.ray.position_mm.y() > previous_height);
      CHECK(std::abs(image.ray.position_mm.x()) < kArithmetic_mm);
      previous_height = image.ray.position_mm.y();
    }
  }
}

TEST_CASE("real-stop aiming from a near object point: a fisheye 100 mm away, object heights to 500 mm (79 degrees)",
          "[aiming][robust][fisheye]") {
  Prescription lens = LensLibrary::load("pbrt-fisheye-10mm").prescription;
  lens.object_distance_mm = 100.0;
  TracerOptions no_clipping;
  no_clipping.clip_apertures = false;
  const SequentialTracer tracer(lens, no_clipping);
  const RayAimer aimer(tracer, real_stop());
  const std::vector<PupilCoordinate> pupils = {{0.0, 0.0}, {0.0, 0.9}, {0.0, -0.9}, {0.9, 0.0}};
  for (double height : {0.0, 10.0, 50.0, 100.0, 200.0, 350.0, 500.0}) {
    for (const PupilCoordinate& pupil : pupils) {
      INFO("object height " << height << " mm, pupil (" << pupil.px << ", " << pupil.py << ")");
      const AimedRay ray = aimer.make_ray(FieldPoint::object_height_mm(height), pupil, kWavelengthD_nm);
      INFO(to_string(ray.status) << " at surface " << ray.surface);
      check_on_stop(tracer, aimer, ray, pupil);
      CHECK(ray.ray.position_mm == Eigen::Vector3d(0.0, height, -100.0));  // from the object point (+h, as in Zemax)
    }
  }
}

TEST_CASE("a field along x gives the mirror image (x <-> y) of the same field along y", "[aiming][robust]") {
  // Any plane through the axis is a mirror plane of a rotationally symmetric lens, the diagonal x = y included.
  const Prescription lens = LensLibrary::load("minolta-fisheye-1978").prescription;
  const SequentialTracer tracer(lens);
  const RayAimer aimer(tracer, real_stop());
  // The two aims run the same arithmetic on swapped coordinates, up to rounding in different orders.
  constexpr double kMirrorRounding = 1e-9;
  for (double degrees : {30.0, 70.0, 88.0}) {
    for (const PupilCoordinate& pupil : {PupilCoordinate{0.3, 0.8}, PupilCoordinate{-0.6, 0.1}}) {
      INFO("field " << degrees << " deg, pupil (" << pupil.px << ", " << pupil.py << ")");
      const AimedRay along_y = aimer.make_ray(FieldPoint::angle_deg(degrees, 0.0), pupil, kWavelengthD_nm);
      const AimedRay along_x = aimer.make_ray(FieldPoint::angle_deg(0.0, degrees), {pupil.py, pupil.px}, kWavelengthD_nm);
      REQUIRE(along_y.ok());
      REQUIRE(along_x.ok());
      CHECK_THAT(along_x.ray.position_mm.x(), WithinAbs(along_y.ray.position_mm.y(), kMirrorRounding));
      CHECK_THAT(along_x.ray.position_mm.y(), WithinAbs(along_y.ray.position_mm.x(), kMirrorRounding));
      CHECK_THAT(along_x.ray.position_mm.z(), WithinAbs(along_y.ray.position_mm.z(), kMirrorRounding));
      CHECK_THAT(along_x.ray.direction.x(), WithinAbs(along_y.ray.direction.y(), kMirrorRounding));
    }
  }
}

TEST_CASE("a flat stop at the vertex of a surface that bulges through it still aims: the stop plane is no refracting surface",
          "[aiming][robust]") {
  // A meniscus whose rear face (R = +40) curves toward the image, and the stop plane at its vertex: off axis the
  // ray meets the rear face behind the stop plane, then the stop plane "behind" it. Nothing refracts at the plane,
  // so the ray is real (Zemax files often place a stop this way).
  Prescription lens;
  lens.name = "meniscus with the stop at its rear vertex";
  lens.surfaces = {make_surface(20.0, 4.0, MaterialSpec::model(1.6, 40.0), 9.0),
                   make_surface(40.0, 0.0, MaterialSpec::air(), 9.0),
                   make_surface(kInfinity, 40.0, MaterialSpec::air(), 4.0)};
  lens.surfaces[2].is_stop = true;
  lens.aperture = ApertureSpec{ApertureSpec::Kind::FloatByStop, 0.0};
  lens.field = FieldSpec{FieldSpec::Kind::AngleDeg, {20.0}};
  TracerOptions no_clipping;
  no_clipping.clip_apertures = false;
  const SequentialTracer tracer(lens, no_clipping);
  const RayAimer aimer(tracer, real_stop());
  int behind_the_plane = 0;
  for (double relative : {0.0, 0.5, 1.0}) {
    for (const PupilCoordinate& pupil : kPupils) {
      INFO("field " << relative << ", pupil (" << pupil.px << ", " << pupil.py << ")");
      const AimedRay ray = aimer.make_ray(aimer.field_at(relative), pupil, kWavelengthD_nm);
      INFO(to_string(ray.status) << " at surface " << ray.surface);
      check_on_stop(tracer, aimer, ray, pupil);
      std::vector<SurfaceHit> path;
      tracer.trace_forward(ray.ray, &path);
      if (path[2].point_mm.z() < path[1].point_mm.z()) ++behind_the_plane;
    }
  }
  CHECK(behind_the_plane >= 20);  // most rays do meet the stop plane behind the rear face
}

TEST_CASE("a stop point whose ray passes outside an earlier surface's clear aperture: the aimed ray is exact and the clipped trace says vignetted there",
          "[aiming][status]") {
  // Smith's triplet at full field (11.86 degrees): the ray through (0, -0.6) of the stop crosses surface 1 below its
  // 14.7-mm rim. Aiming ignores clear apertures (Zemax's ray aiming does too), so the ray is the true one; the
  // caller's clipped trace reports where it is cut, never a ray through the wrong stop point.
  const Prescription lens = smith_cooke_triplet();
  const SequentialTracer clipped(lens);
  TracerOptions no_clipping;
  no_clipping.clip_apertures = false;
  const SequentialTracer unclipped(lens, no_clipping);
  const RayAimer aimer(clipped, real_stop());
  const PupilCoordinate low{0.0, -0.6};
  const AimedRay ray = aimer.make_ray(aimer.field_at(1.0), low, kWavelengthD_nm);
  check_on_stop(unclipped, aimer, ray, low);
  const TraceResult traced = clipped.trace_forward(ray.ray);
  CHECK(traced.status == RayStatus::Vignetted);
  CHECK(traced.surface == 1);
  // The full stop radius below the axis has no ray at all: its ray would cross element 1 where its faces overlap.
  const AimedRay rim = aimer.make_ray(aimer.field_at(1.0), {0.0, -1.0}, kWavelengthD_nm);
  CHECK_FALSE(rim.ok());
  CHECK(rim.surface >= 1);
  CHECK(rim.surface <= 5);
}

TEST_CASE("the Sasian triplet's paraxially aimed rim ray passes its stop, which its file gives to 5 digits", "[aiming][vignetting]") {
  // The stop's semi-diameter is 4.7919 mm; the real rim ray aimed at the paraxial entrance pupil
  // crosses it at 4.791917 mm (pupil aberration), 3.5e-6 beyond: within the tracer's stated
  // clipping tolerance (1e-5 of the semi-diameter, the rounding of a 5-digit value), so the on-axis
  // spot keeps its outer ring at the primary wavelength, as the unvignetted pupil says it should.
  const Prescription lens = LensLibrary::load("sasian-triplet").prescription;
  const SequentialTracer tracer(lens);
  const RayAimer aimer(tracer);
  for (const PupilCoordinate pupil : {PupilCoordinate{0.0, 1.0}, PupilCoordinate{1.0, 0.0}, PupilCoordinate{0.0, -1.0}}) {
    const AimedRay aimed = aimer.make_ray(aimer.field_at(0.0), pupil, kWavelengthD_nm);
    REQUIRE(aimed.ok());
    const TraceResult r = tracer.trace_forward(aimed.ray);
    INFO("pupil (" << pupil.px << ", " << pupil.py << "): " << to_string(r.status));
    CHECK(r.ok());
  }
  // A ray clearly beyond the rim is still stopped there.
  const AimedRay beyond = aimer.make_ray(aimer.field_at(0.0), PupilCoordinate{0.0, 1.01}, kWavelengthD_nm);
  REQUIRE(beyond.ok());
  CHECK(tracer.trace_forward(beyond.ray).status == RayStatus::Vignetted);
}

TEST_CASE("a real-image-height field resolves to the object angles whose real chief rays land at those heights",
          "[trace][aiming][field]") {
  // Outside truth: an independent trace of the resolved field's chief ray, and the paraxial limit.
  for (const RayAiming aiming : {RayAiming::ParaxialEntrancePupil, RayAiming::RealStop}) {
    Prescription lens = smith_cooke_triplet();
    lens.ray_aiming = aiming;
    lens.field = FieldSpec{FieldSpec::Kind::RealImageHeightMm, {0.0, 0.01, 12.0, 21.0}};
    const Prescription resolved = resolve_real_image_height_field(lens);
    REQUIRE(resolved.field->kind == FieldSpec::Kind::AngleDeg);
    TracerOptions free;
    free.clip_apertures = false;
    const SequentialTracer tracer(resolved, free);
    AimOptions options;
    options.aiming = aiming;
    const RayAimer aimer(tracer, options);
    CHECK(resolved.field->values[0] == 0.0);
    for (std::size_t i = 1; i < lens.field->values.size(); ++i) {
      const AimedRay chief = aimer.make_ray(FieldPoint::angle_deg(resolved.field->values[i]), {0.0, 0.0}, lens.primary_wavelength_nm());
      REQUIRE(chief.ok());
      const TraceResult r = tracer.trace_forward(chief.ray);
      REQUIRE(r.ok());
      CHECK_THAT(std::abs(r.ray.position_mm.y()), WithinAbs(lens.field->values[i], 1e-8));
    }
    // 0.01 mm is a paraxial height: its angle is the paraxial one, atan(h / EFL) for this object at infinity.
    const ParaxialSystem paraxial(smith_cooke_triplet());
    CHECK_THAT(resolved.field->values[1], WithinRel(deg_from_rad(std::atan(0.01 / paraxial.efl_mm())), 1e-4));
  }
}

TEST_CASE("a real image height beyond the lens's reach is a ComputationError naming the height", "[trace][aiming][field]") {
  Prescription lens = smith_cooke_triplet();
  lens.field = FieldSpec{FieldSpec::Kind::RealImageHeightMm, {0.0, 5000.0}};
  CHECK_THROWS_AS(resolve_real_image_height_field(lens), ComputationError);
  CHECK_THROWS_WITH(resolve_real_image_height_field(lens), Catch::Matchers::Contains("5000"));
}

TEST_CASE("object-space telecentric: the aimed chief ray leaves the object parallel to the axis, the marginal ray at the NA's angle",
          "[trace][aiming][telecentric]") {
  Prescription lens = smith_cooke_triplet();
  lens.object_distance_mm = 300.0;
  lens.image_at_paraxial_focus = true;
  lens.object_space_telecentric = true;
  lens.aperture = ApertureSpec{ApertureSpec::Kind::ObjectSpaceNA, 0.05};
  lens.field = FieldSpec{FieldSpec::Kind::ObjectHeightMm, {10.0}};
  TracerOptions free;
  free.clip_apertures = false;
  const SequentialTracer tracer(lens, free);
  const RayAimer aimer(tracer);
  const AimedRay chief = aimer.make_ray(aimer.field_at(1.0), {0.0, 0.0}, lens.primary_wavelength_nm());
  REQUIRE(chief.ok());
  CHECK(std::abs(chief.ray.direction.y()) < 1e-10);
  const AimedRay marginal = aimer.make_ray(aimer.field_at(0.0), {0.0, 1.0}, lens.primary_wavelength_nm());
  REQUIRE(marginal.ok());
  // n sin(theta) = NA in air for the ray to the pupil's edge.
  CHECK_THAT(marginal.ray.direction.y(), WithinRel(0.05, 1e-9));
}

TEST_CASE("vignetting factors: pupil coordinates sample the field's vignetted pupil, interpolated between field points",
          "[trace][aiming][vignetting]") {
  // OpticStudio's definition (Px' = VDX + Px (1 - VCX), Py' = VDY + Py (1 - VCY)) checked against the
  // same lens without factors aimed at the transformed coordinate: an independent route to the same ray.
  Prescription lens = smith_cooke_triplet();
  lens.field = FieldSpec{FieldSpec::Kind::AngleDeg, {0.0, 10.0, 20.0}};
  lens.field->vignetting = {VignettingFactors{}, VignettingFactors{0.0, 0.05, 0.0, 0.1, 0.0},
                            VignettingFactors{0.01, 0.1, 0.02, 0.3, 0.0}};
  Prescription plain = lens;
  plain.field->vignetting.clear();
  const SequentialTracer tracer(lens), plain_tracer(plain);
  const RayAimer aimer(tracer), plain_aimer(plain_tracer);
  const double nm = lens.primary_wavelength_nm();
  struct Case {
    double angle_deg, px, py, expect_px, expect_py;
  };
  for (const Case& c : {Case{20.0, 0.0, 1.0, 0.01, 0.1 + 0.7}, Case{20.0, 0.5, -1.0, 0.01 + 0.5 * 0.98, 0.1 - 0.7},
                        Case{15.0, 0.0, 1.0, 0.005, 0.075 + 0.8}, Case{0.0, 0.3, 0.4, 0.3, 0.4}}) {
    INFO(c.angle_deg << " deg, pupil " << c.px << ", " << c.py);
    const FieldPoint field = FieldPoint::angle_deg(c.angle_deg);
    const PupilCoordinate v = aimer.vignetted_pupil(field, {c.px, c.py});
    CHECK_THAT(v.px, WithinAbs(c.expect_px, 1e-12));
    CHECK_THAT(v.py, WithinAbs(c.expect_py, 1e-12));
    const AimedRay a = aimer.make_ray(field, {c.px, c.py}, nm);
    const AimedRay b = plain_aimer.make_ray(field, {c.expect_px, c.expect_py}, nm);
    REQUIRE(a.ok());
    REQUIRE(b.ok());
    CHECK((a.ray.position_mm - b.ray.position_mm).norm() < 1e-9);
    CHECK((a.ray.direction - b.ray.direction).norm() < 1e-12);
  }
  // A field below the axis mirrors the decentre.
  const PupilCoordinate below = aimer.vignetted_pupil(FieldPoint::angle_deg(-20.0), {0.0, 1.0});
  CHECK_THAT(below.py, WithinAbs(-0.1 + 0.7, 1e-12));
  // Switched off, the whole pupil.
  AimOptions off;
  off.use_vignetting_factors = false;
  const PupilCoordinate whole = RayAimer(tracer, off).vignetted_pupil(FieldPoint::angle_deg(20.0), {0.0, 1.0});
  CHECK(whole.py == 1.0);
}

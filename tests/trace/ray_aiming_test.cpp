// RayAimer: rays aimed at the paraxial entrance pupil (Welford, Aberrations of Optical Systems, sec. 4.6) and
// real-stop aiming by Newton iteration, checked against the stop they aim at, against each other where they
// must agree (a stop in front of the lens), and against the paraxial chief and marginal rays of a finite
// object (W. J. Smith's Cooke triplet, Modern Optical Engineering, 4th ed., ch. 6).
#include "lensmith/trace/ray_aiming.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
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

}  // namespace

TEST_CASE("real-stop aiming puts the real ray on the stop at (px, py) x stop radius within the tolerance",
          "[aiming]") {
  for (const char* id : {"smith-cooke-triplet", "sasian-triplet", "angenieux-double-gauss-1953", "aspherical-fisheye",
                         "pbrt-fisheye-10mm", "nikon-retrofocus-1971"}) {
    const Prescription lens = LensLibrary::load(id).prescription;
    TracerOptions unclipped;
    unclipped.clip_apertures = false;  // to see where the aimed ray crosses the stop even if a rim cuts it later
    const SequentialTracer tracer(lens, unclipped);
    const RayAimer aimer(tracer, real_stop());
    const int stop = aimer.paraxial().stop_surface();
    // Pupil coordinate 1 is the beam edge the aperture specification defines: the paraxial marginal
    // height at the stop (Smith's triplet: 10.298 mm inside its 10.3 mm stop rim).
    const double stop_radius = std::abs(aimer.paraxial().marginal_ray().rows[static_cast<std::size_t>(stop) - 1].y_mm);
    const std::vector<double> fields = lens.field ? std::vector<double>{0.0, 0.5, 1.0} : std::vector<double>{0.0};
    int aimed_count = 0;
    std::vector<SurfaceHit> path;
    for (double relative : fields) {
      const FieldPoint field = lens.field ? aimer.field_at(relative) : FieldPoint::angle_deg(0.0);
      for (const PupilCoordinate& pupil : kPupils) {
        for (double wavelength : lens.wavelengths_nm) {
          INFO(id << ", " << field.to_string() << ", pupil (" << pupil.px << ", " << pupil.py << "), " << wavelength
                  << " nm");
          const AimedRay aimed = aimer.make_ray(field, pupil, wavelength);
          INFO(to_string(aimed.status) << " at surface " << aimed.surface);
          REQUIRE(aimed.ok());
          tracer.trace_forward(aimed.ray, &path);
          REQUIRE(path.size() >= static_cast<std::size_t>(stop));
          const Eigen::Vector3d& on_stop = path[static_cast<std::size_t>(stop) - 1].point_mm;
          CHECK_THAT(on_stop.x(), WithinAbs(pupil.px * stop_radius, AimOptions{}.tolerance_mm));
          CHECK_THAT(on_stop.y(), WithinAbs(pupil.py * stop_radius, AimOptions{}.tolerance_mm));
          // An angle field's rays start in object space, in front of surface 1.
          CHECK(aimed.ray.position_mm.z() < path.front().point_mm.z());
          ++aimed_count;
        }
      }
    }
    CHECK(aimed_count > 0);
  }
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

TEST_CASE("a finite object: object-height rays start at y = -h on the object plane and reproduce the paraxial rays in the small limit",
          "[aiming]") {
  // Smith's triplet focused on an object 1 m in front, with an object-height field of 100 mm: conventions.h
  // puts the object point at y = -100 so the chief ray rises in object space and the image lands at y > 0.
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
  CHECK(full.ray.position_mm == Eigen::Vector3d(0.0, -100.0, -1000.0));

  std::vector<SurfaceHit> path;
  for (double s : {1e-4, 1e-5}) {
    const double height_tolerance = kThirdOrderHeight_mm * s * s + kDividedRounding;
    const double slope_tolerance = kThirdOrderSlope * s * s + kDividedRounding;
    const ParaxialRayTable* tables[] = {&*paraxial.chief_ray(), &paraxial.marginal_ray()};
    const AimedRay rays[] = {aimer.make_ray(FieldPoint::object_height_mm(s * 100.0), {0.0, 0.0}, kWavelengthD_nm),
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

// SequentialTracer against outside truth: the paraxial ray tables of Smith's Cooke triplet (W. J. Smith,
// Modern Optical Engineering, 4th ed., ch. 6) and the Sasian triplet (ray-optics documentation) in the limit
// of vanishing aperture and field; Smith's third-, fifth- and seventh-order spherical aberration; closed-form
// optics (plane-parallel plate, ball lens, the Cartesian ellipsoid that focuses a parallel beam perfectly);
// reversibility; and every way a ray can die. Numbers: ../shared/lens-data/REFERENCE-VALUES.md.
#include "lensmith/trace/sequential_tracer.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Dense>
#if __has_include(<omp.h>)
#include <omp.h>
#endif

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "lensmith/prescription/lens_library.h"
#include "lensmith/trace/ray_aiming.h"
#include "reference_lenses.h"

using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using namespace lensmith;
using lensmith::testing::angenieux_double_gauss;
using lensmith::testing::make_surface;
using lensmith::testing::sasian_triplet;
using lensmith::testing::smith_cooke_triplet;

namespace {

// Pure double arithmetic over a few surfaces of ~100 mm: a few ulps of the coordinates.
constexpr double kArithmetic_mm = 1e-12;
// Directions are unit vectors computed with a handful of roundings per surface.
constexpr double kDirectionRounding = 1e-14;
// A real ray of relative aperture/field s departs from the paraxial ray by third-order terms, relative
// size (s y / R)^2 for heights y ~ 15 mm and radii R ~ 40 mm: heights (divided by s) within 1 mm x s^2,
// slopes within 0.1 x s^2 (measured: 0.43 s^2 and 0.05 s^2 for both triplets), plus the rounding of the
// divided coordinates (1e-12).
constexpr double kThirdOrderHeight_mm = 1.0;
constexpr double kThirdOrderSlope = 0.1;
constexpr double kDividedRounding = 1e-12;
// Smith's third-order sums add seven per-surface terms of up to 2 mm, each printed with 6 decimals and
// computed from his 6-decimal ray table (1e-6 relative): a few 1e-6 on the sum.
constexpr double kSmithSumRounding_mm = 1e-5;
// The fifth- and seventh-order coefficients come from a five-term fit of real rays at s = 0.05..0.25; the
// omitted higher orders make the fit depend on the range (fitting 0.1..0.5 instead moves SA5 by 3e-7 and SA7
// by 1e-5), and Smith prints 6 decimals: ten times those.
constexpr double kSmithFifthOrder_mm = 1e-5;
constexpr double kSmithSeventhOrder_mm = 1e-4;
// Reversibility: forward then backward through up to 21 surfaces; each surface adds a few ulps of
// 100-mm coordinates (measured: 1e-13 mm, 1e-14 in direction, 7e-13 mm in optical path).
constexpr double kRoundTrip_mm = 1e-11;
constexpr double kRoundTripDirection = 1e-12;
constexpr double kRoundTripPath_mm = 1e-10;

Prescription lens_in_air(std::vector<Surface> surfaces, double epd_mm) {
  Prescription p;
  p.name = "test lens";
  p.surfaces = std::move(surfaces);
  p.surfaces.front().is_stop = true;
  p.aperture = ApertureSpec{ApertureSpec::Kind::EntrancePupilDiameter, epd_mm};
  return p;
}

MaterialSpec constant_glass(double n) { return MaterialSpec::model(n, std::nullopt); }

Ray make_ray(const Eigen::Vector3d& position, const Eigen::Vector3d& direction, double wavelength_nm = kWavelengthD_nm) {
  Ray r;
  r.position_mm = position;
  r.direction = direction.normalized();
  r.wavelength_nm = wavelength_nm;
  return r;
}

double slope_y(const Eigen::Vector3d& direction) { return direction.y() / direction.z(); }

// The shipped lenses with the field points used for whole-lens checks: the prescription's field at 0, 0.5
// and 1, or 0, 5 and 10 degrees when it gives none.
std::vector<FieldPoint> fields_for(const RayAimer& aimer) {
  if (aimer.tracer().lens().field) return {aimer.field_at(0.0), aimer.field_at(0.5), aimer.field_at(1.0)};
  return {FieldPoint::angle_deg(0.0), FieldPoint::angle_deg(5.0), FieldPoint::angle_deg(10.0)};
}

// Pupil points inside the unit disc, off both axes so that every coordinate is exercised.
const std::vector<PupilCoordinate> kPupilSamples = {{0.0, 0.0},  {0.0, 0.95},  {0.0, -0.95}, {0.6, 0.3},
                                                    {-0.5, 0.5}, {0.7, -0.6},  {0.95, 0.0},  {-0.3, -0.8}};

// Paraxial-limit check of one ray against one table; returns nothing, records CHECKs.
void check_against_table(const std::vector<SurfaceHit>& path, const TraceResult& result, const ParaxialRayTable& table,
                         double s) {
  REQUIRE(result.ok());
  REQUIRE(path.size() == table.rows.size());
  const double height_tolerance = kThirdOrderHeight_mm * s * s + kDividedRounding;
  const double slope_tolerance = kThirdOrderSlope * s * s + kDividedRounding;
  for (std::size_t k = 0; k < path.size(); ++k) {
    INFO("surface " << k + 1 << ", s = " << s);
    CHECK_THAT(path[k].point_mm.y() / s, WithinAbs(table.rows[k].y_mm, height_tolerance));
    CHECK_THAT(slope_y(path[k].direction_after) / s, WithinAbs(table.rows[k].u_after, slope_tolerance));
    CHECK(path[k].point_mm.x() == 0.0);  // a meridional ray stays in the y-z plane exactly
  }
  CHECK_THAT(result.ray.position_mm.y() / s, WithinAbs(table.image_height_mm, height_tolerance));
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Axis and paraxial limit

TEST_CASE("a ray along the axis stays on the axis and reaches the image plane at (0, 0, z_image)", "[trace]") {
  std::vector<Prescription> lenses = {smith_cooke_triplet(), sasian_triplet(), angenieux_double_gauss(),
                                      LensLibrary::load("aspherical-fisheye").prescription};
  for (const Prescription& lens : lenses) {
    const SequentialTracer tracer(lens);
    for (double wavelength : lens.wavelengths_nm) {
      INFO(lens.name << " at " << wavelength << " nm");
      constexpr double kStart_mm = -10.0;
      std::vector<SurfaceHit> path;
      const TraceResult r = tracer.trace_forward(make_ray({0, 0, kStart_mm}, {0, 0, 1}, wavelength), &path);
      REQUIRE(r.ok());
      REQUIRE(path.size() == lens.surfaces.size());
      // Along the axis the optical path is the sum of n x thickness (the sag is 0 at the vertex).
      double axial_path_mm = -kStart_mm * lens.object_medium.index(wavelength);
      for (std::size_t k = 0; k < path.size(); ++k) {
        CHECK(path[k].surface == static_cast<int>(k) + 1);
        CHECK(path[k].point_mm.x() == 0.0);
        CHECK(path[k].point_mm.y() == 0.0);
        CHECK_THAT(path[k].point_mm.z(), WithinAbs(tracer.vertex_z_mm(static_cast<int>(k) + 1), kArithmetic_mm));
        CHECK(path[k].direction_after.x() == 0.0);
        CHECK(path[k].direction_after.y() == 0.0);
        CHECK_THAT(path[k].direction_after.z(), WithinAbs(1.0, kDirectionRounding));
        CHECK_THAT(path[k].optical_path_mm, WithinRel(axial_path_mm, 1e-14));
        const double gap = k + 1 < path.size() ? tracer.vertex_z_mm(static_cast<int>(k) + 2) - tracer.vertex_z_mm(static_cast<int>(k) + 1)
                                               : tracer.image_plane_z_mm() - tracer.vertex_z_mm(static_cast<int>(k) + 1);
        axial_path_mm += gap * lens.surfaces[k].medium.index(wavelength);
      }
      CHECK(r.ray.position_mm == Eigen::Vector3d(0, 0, tracer.image_plane_z_mm()));
      CHECK_THAT((r.ray.direction - Eigen::Vector3d(0, 0, 1)).norm(), WithinAbs(0.0, kDirectionRounding));
      CHECK_THAT(r.optical_path_mm, WithinRel(axial_path_mm, 1e-14));
    }
  }
}

TEST_CASE("rays of vanishing aperture and field reproduce the paraxial marginal and chief ray tables",
          "[trace][published]") {
  // The paraxial tables are themselves checked against Smith's book and ray-optics' printout
  // (tests/paraxial): this ties the exact tracer to those published numbers.
  std::vector<Prescription> lenses = {smith_cooke_triplet(), sasian_triplet()};
  for (const Prescription& lens : lenses) {
    const SequentialTracer tracer(lens);
    const RayAimer aimer(tracer);
    for (double wavelength : lens.wavelengths_nm) {
      // The tables at this wavelength; the stop, EPD and image plane are those of the primary wavelength
      // in both models.
      ParaxialOptions at_wavelength;
      at_wavelength.wavelength_nm = wavelength;
      const ParaxialSystem paraxial(lens, at_wavelength);
      REQUIRE(paraxial.chief_ray().has_value());
      for (double s : {1e-4, 1e-5, 1e-6}) {
        INFO(lens.name << " at " << wavelength << " nm");
        std::vector<SurfaceHit> path;
        INFO("marginal ray");
        const AimedRay marginal = aimer.make_ray(FieldPoint::angle_deg(0.0), {0.0, s}, wavelength);
        REQUIRE(marginal.ok());
        const TraceResult rm = tracer.trace_forward(marginal.ray, &path);
        check_against_table(path, rm, paraxial.marginal_ray(), s);

        INFO("chief ray");
        // The aimer uses the entrance pupil of the primary wavelength; at another wavelength the paraxial
        // chief ray passes through that wavelength's pupil centre (the stop's image moves with colour).
        const double slope = s * paraxial.chief_ray()->object_slope;
        Ray chief;
        if (wavelength == lens.primary_wavelength_nm()) {
          const AimedRay aimed = aimer.make_ray(FieldPoint::angle_deg(deg_from_rad(std::atan(slope))), {0.0, 0.0}, wavelength);
          REQUIRE(aimed.ok());
          chief = aimed.ray;
        } else {
          constexpr double kStart_mm = -5.0;  // in front of both triplets' convex first surfaces
          chief = make_ray({0.0, slope * (kStart_mm - paraxial.entrance_pupil().z_mm), kStart_mm}, {0.0, slope, 1.0}, wavelength);
        }
        const TraceResult rc = tracer.trace_forward(chief, &path);
        check_against_table(path, rc, *paraxial.chief_ray(), s);
      }
    }
  }
}

TEST_CASE("Smith triplet: real spherical aberration tends to Smith's third-order sum, with his fifth and seventh orders",
          "[trace][published]") {
  // Smith, Modern Optical Engineering, 4th ed., ch. 6: sum SA3 = -0.186575 mm, SA5 = 0.125426, SA7 = 0.048670
  // (transverse, at full aperture, negative = undercorrected). A marginal ray at relative aperture s from
  // +y lands at TA(s) = SA3 s^3 + SA5 s^5 + SA7 s^7 + ... on the paraxial image plane: an undercorrected lens
  // brings it across the axis early, so it lands at y < 0 as Smith's sign says. TA(s) / s^3 is fitted by a
  // polynomial in s^2 whose coefficients are SA3, SA5, SA7, ...
  const Prescription lens = smith_cooke_triplet();
  TracerOptions unclipped;
  unclipped.clip_apertures = false;  // the full-aperture ray below passes the stop outside its 10.3 mm rim
  const SequentialTracer tracer(lens, unclipped);
  const RayAimer aimer(tracer);
  auto ta_over_s3 = [&](double s) {
    const TraceResult r = tracer.trace_forward(aimer.make_ray(FieldPoint::angle_deg(0.0), {0.0, s}, kWavelengthD_nm).ray);
    REQUIRE(r.ok());
    return r.ray.position_mm.y() / (s * s * s);
  };
  const std::vector<double> apertures = {0.05, 0.10, 0.15, 0.20, 0.25};
  const auto count = static_cast<Eigen::Index>(apertures.size());
  Eigen::MatrixXd vandermonde(count, count);
  Eigen::VectorXd values(count);
  for (Eigen::Index i = 0; i < count; ++i) {
    const double s = apertures[static_cast<std::size_t>(i)];
    for (Eigen::Index j = 0; j < count; ++j) vandermonde(i, j) = std::pow(s, 2.0 * static_cast<double>(j));
    values(i) = ta_over_s3(s);
  }
  const Eigen::VectorXd series = vandermonde.colPivHouseholderQr().solve(values);

  // Third order, independently: Welford's S_I from lensmith's paraxial marginal ray, SA3 = S_I / (2 n' u'_k)
  // (REFERENCE-VALUES.md section 1), with S_I = -sum A^2 y delta(u / n), A = n i.
  const ParaxialSystem& paraxial = aimer.paraxial();
  double s_one = 0.0;
  double u_before = paraxial.marginal_ray().object_slope;
  double n_before = 1.0;
  for (const ParaxialRayRow& row : paraxial.marginal_ray().rows) {
    const double a = n_before * row.i;
    s_one -= a * a * row.y_mm * (row.u_after / row.n_after - u_before / n_before);
    u_before = row.u_after;
    n_before = row.n_after;
  }
  const double sa3_from_table = s_one / (2.0 * n_before * u_before);

  // The fit's truncation (ninth order and up, at s <= 0.25) is ~1e-9 on the constant term.
  CHECK_THAT(series(0), WithinAbs(sa3_from_table, 1e-8));
  CHECK_THAT(series(0), WithinAbs(-0.186575, kSmithSumRounding_mm));
  CHECK_THAT(series(1), WithinAbs(0.125426, kSmithFifthOrder_mm));
  CHECK_THAT(series(2), WithinAbs(0.048670, kSmithSeventhOrder_mm));
  // The small-aperture limit directly, without the fit: at s = 0.001 the fifth order adds 0.125 x 1e-6.
  CHECK_THAT(ta_over_s3(0.001), WithinAbs(-0.186575, kSmithSumRounding_mm));

  // At full aperture the orders above the third nearly cancel SA3 (Smith's sum SA3 + SA5 + SA7 = -0.0125):
  // the real transverse aberration is an order of magnitude below |SA3| and the longitudinal one
  // LA = -TA / tan U' below 0.2 mm (Smith's design is corrected for the margin).
  const TraceResult full = tracer.trace_forward(aimer.make_ray(FieldPoint::angle_deg(0.0), {0.0, 1.0}, kWavelengthD_nm).ray);
  REQUIRE(full.ok());
  const double ta_full = full.ray.position_mm.y();
  const double la_full = -ta_full / slope_y(full.ray.direction);
  CHECK(std::abs(ta_full) < 0.1 * 0.186575);
  CHECK(std::abs(la_full) < 0.2);
}

// ---------------------------------------------------------------------------------------------
// Closed-form optics

TEST_CASE("plane-parallel plate: the ray leaves parallel to itself, shifted by t sin(theta) (1 - cos(theta) / sqrt(n^2 - sin^2(theta)))",
          "[trace][analytic]") {
  // Derivation: inside the plate the ray runs t / cos(theta') with sin(theta) = n sin(theta'), and leaves
  // parallel to itself, displaced by that length times sin(theta - theta'), which expands to the formula.
  constexpr double kIndex = 1.5;
  constexpr double kThickness_mm = 10.0;
  const Prescription plate = lens_in_air(
      {make_surface(kInfinity, kThickness_mm, constant_glass(kIndex)), make_surface(kInfinity, 5.0, MaterialSpec::air())},
      10.0);
  const SequentialTracer tracer(plate);
  for (double theta_deg : {5.0, 30.0, 60.0, 80.0}) {
    INFO("incidence " << theta_deg << " deg");
    const double theta = rad_from_deg(theta_deg);
    const Eigen::Vector3d d_in(0.0, std::sin(theta), std::cos(theta));
    const Eigen::Vector3d p_in(0.3, -2.0, -1.0);
    std::vector<SurfaceHit> path;
    const TraceResult r = tracer.trace_forward(make_ray(p_in, d_in), &path);
    REQUIRE(r.ok());
    CHECK_THAT((r.ray.direction - d_in).norm(), WithinAbs(0.0, kDirectionRounding));
    const Eigen::Vector3d offset = r.ray.position_mm - p_in;
    const double shift = (offset - offset.dot(d_in) * d_in).norm();
    const double sin_t = std::sin(theta);
    const double expected = kThickness_mm * sin_t * (1.0 - std::cos(theta) / std::sqrt(kIndex * kIndex - sin_t * sin_t));
    CHECK_THAT(shift, WithinAbs(expected, kArithmetic_mm));
    // Inside the plate: geometric length t / cos(theta') at index n.
    const double cos_inside = std::sqrt(1.0 - sin_t * sin_t / (kIndex * kIndex));
    CHECK_THAT(path[1].optical_path_mm - path[0].optical_path_mm,
               WithinAbs(kIndex * kThickness_mm / cos_inside, kArithmetic_mm));
  }
}

TEST_CASE("ball lens: paraxial focus at n R / (2 (n - 1)) from the centre, and a marginal ray refracted twice by hand",
          "[trace][analytic]") {
  // The thick-lens formula (Hecht, Optics, 5th ed., ch. 6) with R1 = -R2 = R and thickness 2R gives
  // f = n R / (2 (n - 1)), measured from the centre (both principal planes pass through it). The marginal ray:
  // incidence i1 = asin(h / R), refraction r1 = asin(sin i1 / n); by symmetry it leaves at incidence r1 and
  // refraction i1, deviated by 2 (i1 - r1), from the point at polar angle 2 r1 - i1 about the centre.
  constexpr double kIndex = 1.5;
  constexpr double kRadius_mm = 5.0;
  const Prescription ball =
      lens_in_air({make_surface(kRadius_mm, 2.0 * kRadius_mm, constant_glass(kIndex)),
                   make_surface(-kRadius_mm, 10.0, MaterialSpec::air())},
                  2.0);
  const SequentialTracer tracer(ball);
  const double centre_z = kRadius_mm;
  auto axis_crossing_z = [](const TraceResult& r) {
    return r.ray.position_mm.z() - r.ray.position_mm.y() / slope_y(r.ray.direction);
  };

  // Paraxial: a height of 1e-4 mm departs from the paraxial focus by (h / R)^2 relative, 4e-10 x 7.5 mm.
  constexpr double kParaxialHeight_mm = 1e-4;
  const TraceResult paraxial = tracer.trace_forward(make_ray({0, kParaxialHeight_mm, -1.0}, {0, 0, 1}));
  INFO(paraxial.to_string());
  REQUIRE(paraxial.ok());
  const double focal_from_centre = kIndex * kRadius_mm / (2.0 * (kIndex - 1.0));
  CHECK_THAT(axis_crossing_z(paraxial), WithinAbs(centre_z + focal_from_centre, 1e-8));

  // Marginal: h = 3 mm (sin i1 = 0.6).
  constexpr double kHeight_mm = 3.0;
  std::vector<SurfaceHit> path;
  const TraceResult marginal = tracer.trace_forward(make_ray({0, kHeight_mm, -1.0}, {0, 0, 1}), &path);
  REQUIRE(marginal.ok());
  const double i1 = std::asin(kHeight_mm / kRadius_mm);
  const double r1 = std::asin(std::sin(i1) / kIndex);
  const double exit_polar = 2.0 * r1 - i1;
  const double deviation = 2.0 * (i1 - r1);
  CHECK_THAT(path[0].point_mm.z(), WithinAbs(kRadius_mm - kRadius_mm * std::cos(i1), kArithmetic_mm));
  CHECK_THAT(path[1].point_mm.z(), WithinAbs(centre_z + kRadius_mm * std::cos(exit_polar), kArithmetic_mm));
  CHECK_THAT(path[1].point_mm.y(), WithinAbs(kRadius_mm * std::sin(exit_polar), kArithmetic_mm));
  CHECK_THAT(std::atan2(-marginal.ray.direction.y(), marginal.ray.direction.z()), WithinAbs(deviation, kDirectionRounding));
  const double expected_crossing = centre_z + kRadius_mm * std::cos(exit_polar) + kRadius_mm * std::sin(exit_polar) / std::tan(deviation);
  CHECK_THAT(axis_crossing_z(marginal), WithinAbs(expected_crossing, kArithmetic_mm));
  // Spherical aberration of a ball: the marginal ray crosses well before the paraxial focus.
  CHECK(axis_crossing_z(marginal) < centre_z + focal_from_centre - 0.5);
}

TEST_CASE("an ellipsoid with k = -1/n^2 focuses a parallel beam perfectly at n R / (n - 1) with equal optical paths",
          "[trace][analytic]") {
  // Derivation (the Cartesian surface for an object at infinity; Hecht, Optics, 5th ed., sec. 5.2): on an
  // ellipse of eccentricity e the distance to a focus is e times the distance to that focus's directrix. With
  // e = 1/n, n |P F'| = z_D - z_P, so a ray parallel to the axis from the plane z0 has optical path
  // (z_P - z0) + n |P F'| = z_D - z0 for every P: all rays meet at F' in phase. The conic is k = -e^2; with
  // vertex radius R = a (1 - e^2) the far focus lies a (1 + e) = R / (1 - e) = n R / (n - 1) from the vertex.
  constexpr double kIndex = 1.5;
  constexpr double kRadius_mm = 10.0;
  const double focus_mm = kIndex * kRadius_mm / (kIndex - 1.0);
  Surface ellipsoid = make_surface(kRadius_mm, focus_mm, constant_glass(kIndex));
  ellipsoid.conic = -1.0 / (kIndex * kIndex);
  const SequentialTracer tracer(lens_in_air({ellipsoid}, 16.0));
  REQUIRE(tracer.image_plane_z_mm() == focus_mm);

  constexpr double kStart_mm = -5.0;  // the plane wavefront where every ray starts
  const double axial_path_mm = -kStart_mm + kIndex * focus_mm;
  double worst_transverse = 0.0;
  double worst_path = 0.0;
  int traced = 0;
  for (double x = -8.0; x <= 8.0; x += 2.0) {
    for (double y = -8.0; y <= 8.0; y += 1.0) {
      if (x * x + y * y > 64.0) continue;
      const TraceResult r = tracer.trace_forward(make_ray({x, y, kStart_mm}, {0, 0, 1}));
      INFO("ray at (" << x << ", " << y << ")");
      REQUIRE(r.ok());
      worst_transverse = std::max(worst_transverse, r.ray.position_mm.head<2>().norm());
      worst_path = std::max(worst_path, std::abs(r.optical_path_mm / axial_path_mm - 1.0));
      ++traced;
    }
  }
  CHECK(traced > 90);
  CHECK_THAT(worst_transverse, WithinAbs(0.0, kArithmetic_mm));
  CHECK_THAT(worst_path, WithinAbs(0.0, 1e-9));  // brief's bound; measured ~1e-15
}

// ---------------------------------------------------------------------------------------------
// Reversibility and aspheres

TEST_CASE("forward then backward returns the same ray on surface 1 for every shipped lens, off axis and aspheric",
          "[trace][lenses]") {
  for (const ShippedLens& shipped : LensLibrary::list()) {
    const Prescription lens = LensLibrary::load(shipped.id).prescription;
    const SequentialTracer tracer(lens);
    const RayAimer aimer(tracer);
    int compared = 0;
    int attempted = 0;
    std::vector<SurfaceHit> forward_path;
    std::vector<SurfaceHit> backward_path;
    for (const FieldPoint& field : fields_for(aimer)) {
      for (const PupilCoordinate& pupil : kPupilSamples) {
        for (double wavelength : lens.wavelengths_nm) {
          INFO(shipped.id << ", " << field.to_string() << ", pupil (" << pupil.px << ", " << pupil.py << "), "
                          << wavelength << " nm");
          ++attempted;
          const AimedRay aimed = aimer.make_ray(field, pupil, wavelength);
          REQUIRE(aimed.ok());
          const TraceResult forward = tracer.trace_forward(aimed.ray, &forward_path);
          if (!forward.ok()) continue;  // vignetted rays have no way back
          Ray reversed = forward.ray;
          reversed.direction = -reversed.direction;
          const TraceResult backward = tracer.trace_backward(reversed, &backward_path);
          REQUIRE(backward.ok());
          REQUIRE(backward_path.size() == lens.surfaces.size());
          CHECK(backward_path.front().surface == static_cast<int>(lens.surfaces.size()));
          CHECK(backward_path.back().surface == 1);
          CHECK_THAT((backward.ray.position_mm - forward_path.front().point_mm).norm(), WithinAbs(0.0, kRoundTrip_mm));
          CHECK_THAT((backward.ray.direction + aimed.ray.direction).norm(), WithinAbs(0.0, kRoundTripDirection));
          CHECK_THAT(backward.optical_path_mm,
                     WithinAbs(forward.optical_path_mm - forward_path.front().optical_path_mm, kRoundTripPath_mm));
          ++compared;
        }
      }
    }
    INFO(shipped.id << ": " << compared << " of " << attempted << " rays reached the image");
    // Edge-of-field, edge-of-pupil rays are vignetted in most lenses; at least a third get through.
    CHECK(3 * compared >= attempted);
  }
}

TEST_CASE("a trace through the surfaces up to any one and on from there lands where the whole trace lands, for every shipped lens",
          "[trace][lenses]") {
  // The exact ray model aims through the surfaces up to the stop and traces the rest once
  // (exact_model.cpp). Split after surface k, the second part starts from the first part's hit on k
  // and recomputes the next intersection's first coefficient that the whole trace carries over: a
  // few roundings, within kArithmetic_mm on the image plane.
  int splits = 0;
  std::vector<SurfaceHit> front;
  std::vector<SurfaceHit> rear;
  std::vector<SurfaceHit> whole_path;
  for (const ShippedLens& shipped : LensLibrary::list()) {
    const Prescription lens = LensLibrary::load(shipped.id).prescription;
    const SequentialTracer tracer(lens);
    const RayAimer aimer(tracer);
    const int count = static_cast<int>(lens.surfaces.size());
    for (const FieldPoint& field : fields_for(aimer)) {
      const AimedRay aimed = aimer.make_ray(field, PupilCoordinate{0.3, -0.5}, lens.wavelengths_nm.front());
      REQUIRE(aimed.ok());
      const TraceResult whole = tracer.trace_forward(aimed.ray, &whole_path);
      if (!whole.ok()) continue;
      // Through every surface: the whole trace, bit for bit.
      const TraceResult all = tracer.trace_forward_through(aimed.ray, 1, count);
      CHECK(all.ok());
      CHECK(all.ray.position_mm == whole.ray.position_mm);
      CHECK(all.ray.direction == whole.ray.direction);
      for (int k = 1; k < count; ++k) {
        INFO(shipped.id << ", " << field.to_string() << ", split after surface " << k);
        const TraceResult first = tracer.trace_forward_through(aimed.ray, 1, k, &front);
        REQUIRE(first.ok());
        REQUIRE(front.size() == static_cast<std::size_t>(k));
        // The first part ends on surface k, leaving it as the whole trace does.
        CHECK_THAT((first.ray.position_mm - whole_path[static_cast<std::size_t>(k - 1)].point_mm).norm(), WithinAbs(0.0, kArithmetic_mm));
        CHECK_THAT((first.ray.direction - whole_path[static_cast<std::size_t>(k - 1)].direction_after).norm(),
                   WithinAbs(0.0, kDirectionRounding));
        const TraceResult second = tracer.trace_forward_through(Ray{first.ray.position_mm, first.ray.direction, aimed.ray.wavelength_nm},
                                                                k + 1, count, &rear);
        REQUIRE(second.ok());
        REQUIRE(rear.size() == static_cast<std::size_t>(count - k));
        CHECK(rear.front().surface == k + 1);
        CHECK_THAT((second.ray.position_mm - whole.ray.position_mm).norm(), WithinAbs(0.0, kArithmetic_mm));
        ++splits;
      }
    }
  }
  CHECK(splits > 100);
  const SequentialTracer tracer(sasian_triplet());
  const Ray ray;
  CHECK_THROWS_AS(tracer.trace_forward_through(ray, 0, 3), OptionsError);
  CHECK_THROWS_AS(tracer.trace_forward_through(ray, 4, 3), OptionsError);
  CHECK_THROWS_AS(tracer.trace_forward_through(ray, 1, 7), OptionsError);
}

TEST_CASE("aspheric intersections lie on the sag z(r) with the normal of its gradient", "[trace][asphere]") {
  // Surfaces 7, 8, 10 and 11 of the aspherical fisheye (lentil 0014) are even aspheres (a4..a10).
  const Prescription lens = LensLibrary::load("aspherical-fisheye").prescription;
  TracerOptions unclipped;
  unclipped.clip_apertures = false;
  const SequentialTracer tracer(lens, unclipped);
  const RayAimer aimer(tracer);
  auto sag = [](const Surface& s, double r) {
    const double c = s.curvature_per_mm;
    const double u = r * r;
    double z = c * u / (1.0 + std::sqrt(1.0 - (1.0 + s.conic) * c * c * u));
    for (std::size_t j = 0; j < s.even_asphere.size(); ++j) z += s.even_asphere[j] * std::pow(u, static_cast<double>(j + 1));
    return z;
  };
  int aspheric_hits = 0;
  std::vector<SurfaceHit> path;
  for (double field_deg : {0.0, 20.0, 40.0}) {
    for (const PupilCoordinate& pupil : kPupilSamples) {
      const TraceResult r = tracer.trace_forward(aimer.make_ray(FieldPoint::angle_deg(field_deg), pupil, kWavelengthD_nm).ray, &path);
      for (const SurfaceHit& hit : path) {
        const Surface& s = lens.surfaces[static_cast<std::size_t>(hit.surface) - 1];
        if (!s.has_asphere()) continue;
        INFO("surface " << hit.surface << ", field " << field_deg << " deg, " << r.to_string());
        const double radius = hit.point_mm.head<2>().norm();
        const double z_local = hit.point_mm.z() - tracer.vertex_z_mm(hit.surface);
        CHECK_THAT(z_local, WithinAbs(sag(s, radius), kArithmetic_mm));
        // Normal from a central difference of the sag: (-dz/dr cos(phi), -dz/dr sin(phi), 1) normalised.
        if (radius > 1e-3) {
          constexpr double kStep_mm = 1e-5;  // central difference error ~ step^2 z''' ~ 1e-10
          const double dzdr = (sag(s, radius + kStep_mm) - sag(s, radius - kStep_mm)) / (2.0 * kStep_mm);
          const Eigen::Vector3d expected =
              Eigen::Vector3d(-dzdr * hit.point_mm.x() / radius, -dzdr * hit.point_mm.y() / radius, 1.0).normalized();
          CHECK_THAT((hit.normal - expected).norm(), WithinAbs(0.0, 1e-9));
        }
        ++aspheric_hits;
      }
    }
  }
  CHECK(aspheric_hits > 50);
}

TEST_CASE("a strongly aspheric surface: every hit lies on the sag and no crossing is missed, by a dense scan along each ray",
          "[trace][asphere]") {
  // Base sphere R = 8 mm (domain r < 8) with a4 = -3e-3 and a6 = 2e-5: the sag rises, falls below the vertex
  // plane and turns up again near the rim, where the slope grows without bound. Newton from the base sphere
  // fails for many rays here, so the bracketed fallback is exercised. Independent check: sample
  // G(t) = z(t) - sag(r(t)) every kScanStep_mm along the ray and find the first front-to-back sign change.
  constexpr double kRadius_mm = 8.0;
  Surface surface = make_surface(kRadius_mm, 20.0, constant_glass(1.5));
  surface.even_asphere[1] = -3e-3;
  surface.even_asphere[2] = 2e-5;
  const SequentialTracer tracer(lens_in_air({surface}, 4.0));
  auto sag = [&](double u, bool& inside) {
    const double c = 1.0 / kRadius_mm;
    const double d = 1.0 - c * c * u;
    inside = d > 0.0;
    return inside ? c * u / (1.0 + std::sqrt(d)) - 3e-3 * u * u + 2e-5 * u * u * u : 0.0;
  };
  constexpr double kStart_mm = -3.0;
  constexpr double kScanStep_mm = 2e-3;  // the scan's resolution; crossings closer than this may pair up
  int hits = 0;
  int misses = 0;
  std::vector<SurfaceHit> path;
  for (double y = -10.0; y <= 10.0; y += 0.05) {
    for (double angle : {-0.6, -0.3, 0.0, 0.3, 0.6}) {
      const Ray ray = make_ray({0.0, y, kStart_mm}, {0.0, std::sin(angle), std::cos(angle)});
      const TraceResult r = tracer.trace_forward(ray, &path);
      double first_crossing = std::numeric_limits<double>::quiet_NaN();
      bool previous_inside = false;
      double previous_g = 0.0;
      for (double t = 0.0; t <= 40.0 && std::isnan(first_crossing); t += kScanStep_mm) {
        const double yy = y + t * ray.direction.y();
        bool inside = false;
        const double g = kStart_mm + t * ray.direction.z() - sag(yy * yy, inside);
        if (inside && previous_inside && previous_g < 0.0 && g >= 0.0) first_crossing = t;
        previous_inside = inside;
        previous_g = g;
      }
      INFO("ray from y = " << y << " at " << angle << " rad: " << r.to_string());
      if (r.status == RayStatus::Missed) {
        CHECK(std::isnan(first_crossing));
        ++misses;
        continue;
      }
      REQUIRE(!path.empty());
      const SurfaceHit& hit = path.front();
      bool inside = false;
      // Distance from the surface along its normal: the vertical miss times n_z.
      CHECK_THAT((hit.point_mm.z() - sag(hit.point_mm.y() * hit.point_mm.y(), inside)) * hit.normal.z(),
                 WithinAbs(0.0, kArithmetic_mm));
      CHECK(inside);
      CHECK(hit.normal.dot(ray.direction) > 0.0);  // crossed from the front, in the direction of travel
      if (!std::isnan(first_crossing)) {
        CHECK_THAT((hit.point_mm.z() - kStart_mm) / ray.direction.z(), WithinAbs(first_crossing, kScanStep_mm));
      }
      ++hits;
    }
  }
  CHECK(hits > 1000);
  CHECK(misses > 300);  // rays that pass outside the 8-mm domain (388 of 2005)
}

// ---------------------------------------------------------------------------------------------
// How rays die

TEST_CASE("a ray outside a strongly curved surface is Missed at that surface", "[trace][status]") {
  // Smith's surface 1 has R = 37.40 mm: a ray parallel to the axis at 40 mm never meets the sphere.
  const SequentialTracer tracer(smith_cooke_triplet());
  const Ray ray = make_ray({0, 40.0, -5.0}, {0, 0, 1});
  const TraceResult r = tracer.trace_forward(ray);
  CHECK(r.status == RayStatus::Missed);
  CHECK(r.surface == 1);
  CHECK(r.ray.position_mm == ray.position_mm);  // it died before moving
  CHECK(tracer.trace_backward(make_ray({0, 40.0, 200.0}, {0, 0, -1})).surface == 7);
}

TEST_CASE("a ray that meets a sphere only on its far hemisphere is Missed: the surface is the sheet through the vertex",
          "[trace][status]") {
  // R = 10 mm, centre at z = 10: the surface is the hemisphere z <= 10. A ray coming in from the side at
  // z ~ 19 enters the full sphere, from outside, on its rear half only.
  const Prescription lens = lens_in_air({make_surface(10.0, 30.0, constant_glass(1.5))}, 4.0);
  const SequentialTracer tracer(lens);
  const TraceResult r = tracer.trace_forward(make_ray({0, 30.0, 18.0}, {0, -1.0, 0.05}));
  CHECK(r.status == RayStatus::Missed);
  CHECK(r.surface == 1);
  // The same ray lowered into the front half (z ~ 4) is fine.
  CHECK(tracer.trace_forward(make_ray({0, 30.0, 3.0}, {0, -1.0, 0.05})).ok());
}

TEST_CASE("a ray travelling parallel to a plane surface is Missed there", "[trace][status]") {
  const Prescription plate = lens_in_air(
      {make_surface(kInfinity, 10.0, constant_glass(1.5)), make_surface(kInfinity, 5.0, MaterialSpec::air())}, 10.0);
  const SequentialTracer tracer(plate);
  const TraceResult sideways = tracer.trace_forward(make_ray({0, 0, -1.0}, {0, 1, 0}));
  CHECK(sideways.status == RayStatus::Missed);
  CHECK(sideways.surface == 1);
  CHECK(to_string(sideways.status) == "missed");
}

TEST_CASE("clipping at a clear semi-diameter and at the stop gives Vignetted with the surface number", "[trace][status]") {
  const Prescription lens = smith_cooke_triplet();
  const SequentialTracer tracer(lens);
  TracerOptions unclipped_options;
  unclipped_options.clip_apertures = false;
  const SequentialTracer unclipped(lens, unclipped_options);
  // 14.8 mm > the 14.7 mm semi-diameter of surface 1.
  const Ray outside_front = make_ray({0, 14.8, -5.0}, {0, 0, 1});
  const TraceResult front = tracer.trace_forward(outside_front);
  CHECK(front.status == RayStatus::Vignetted);
  CHECK(front.surface == 1);
  CHECK_THAT(front.ray.position_mm.y(), WithinAbs(14.8, kArithmetic_mm));  // on surface 1, where it died
  CHECK(unclipped.trace_forward(outside_front).ok());
  // The full-aperture ray at 14.6 mm clears surfaces 1-4 (10.76 mm at surface 3, rim 10.8) but passes the
  // stop (surface 5, rim 10.3 mm) at 10.48 mm: the real ray's pupil aberration, 1.7 % over the paraxial 10.298.
  std::vector<SurfaceHit> path;
  const TraceResult at_stop = tracer.trace_forward(make_ray({0, 14.6, -5.0}, {0, 0, 1}), &path);
  CHECK(at_stop.status == RayStatus::Vignetted);
  CHECK(at_stop.surface == 5);
  REQUIRE(path.size() == 5);
  CHECK(path.back().point_mm.y() > 10.3);
  CHECK(to_string(at_stop.status) == "vignetted");
  CHECK(at_stop.to_string().find("vignetted at surface 5") != std::string::npos);
}

TEST_CASE("a semi-diameter that is not a clear aperture (a Zemax DIAM) clips no ray", "[trace][status]") {
  Prescription lens = smith_cooke_triplet();
  lens.surfaces[0].clips_rays = false;  // 14.7 mm
  const SequentialTracer tracer(lens);
  const TraceResult r = tracer.trace_forward(make_ray({0, 14.75, -5.0}, {0, 0, 1}));
  CHECK(r.surface != 1);  // it may still die at a later clear aperture, never at surface 1
}

TEST_CASE("a clear aperture passes a ray on its rim within the rim tolerance", "[trace][status]") {
  // The rim tolerance is 1e-5 relative (sequential_tracer.cpp): a file's semi-diameter printed to 6 digits.
  const Prescription lens = smith_cooke_triplet();
  const SequentialTracer tracer(lens);
  CHECK(tracer.trace_forward(make_ray({0, 14.7 * (1.0 + 0.5e-5), -5.0}, {0, 0, 1})).surface != 1);
  CHECK(tracer.trace_forward(make_ray({0, 14.7 * (1.0 + 2e-5), -5.0}, {0, 0, 1})).surface == 1);
}

TEST_CASE("explicit apertures clip by their shape: annulus, decentred rectangle, ellipse, obscurations", "[trace][status]") {
  using Shape = SurfaceAperture::Shape;
  struct Case {
    SurfaceAperture aperture;
    double x, y;
    bool passes;
  };
  const Case cases[] = {
      {{Shape::Circular, false, 2.0, 6.0, 6.0, 0.0, 0.0}, 0.0, 1.0, false},    // inside the annulus's hole
      {{Shape::Circular, false, 2.0, 6.0, 6.0, 0.0, 0.0}, 3.0, 3.0, true},     // in the ring (r 4.24)
      {{Shape::Circular, false, 2.0, 6.0, 6.0, 0.0, 0.0}, 4.5, 4.5, false},    // beyond it (r 6.36)
      {{Shape::Rectangular, false, 0.0, 3.0, 2.0, 1.0, 0.0}, 3.9, 1.9, true},  // the box is shifted +1 in x
      {{Shape::Rectangular, false, 0.0, 3.0, 2.0, 1.0, 0.0}, -2.5, 0.0, false},
      {{Shape::Rectangular, false, 0.0, 3.0, 2.0, 1.0, 0.0}, 0.0, 2.1, false},
      {{Shape::Elliptical, false, 0.0, 3.0, 2.0, 0.0, 0.0}, 2.9, 0.0, true},
      {{Shape::Elliptical, false, 0.0, 3.0, 2.0, 0.0, 0.0}, 2.0, 1.6, false},  // (2/3)^2 + 0.8^2 = 1.084
      {{Shape::Circular, true, 0.0, 2.5, 2.5, 0.0, 0.0}, 1.0, 1.0, false},     // a central obscuration
      {{Shape::Circular, true, 0.0, 2.5, 2.5, 0.0, 0.0}, 3.0, 0.0, true},
      {{Shape::Elliptical, true, 0.0, 1.0, 0.5, 0.0, 0.0}, 0.0, 0.6, true},
  };
  for (const Case& c : cases) {
    INFO(c.aperture.to_string() << " at (" << c.x << ", " << c.y << ")");
    Prescription lens = smith_cooke_triplet();
    lens.surfaces[0].aperture = c.aperture;
    const SequentialTracer tracer(lens);
    const TraceResult r = tracer.trace_forward(make_ray({c.x, c.y, -5.0}, {0, 0, 1}));
    CHECK((r.surface != 1) == c.passes);
    CHECK(c.aperture.passes(c.x, c.y, 0.0) == c.passes);
    TracerOptions unclipped_options;
    unclipped_options.clip_apertures = false;
    CHECK(SequentialTracer(lens, unclipped_options).trace_forward(make_ray({c.x, c.y, -5.0}, {0, 0, 1})).surface != 1);
  }
}

TEST_CASE("a steep ray inside glass is totally internally reflected at the surface where it would leave", "[trace][status]") {
  // Plano-convex, n = 1.5, rear radius -10 mm: a ray parallel to the axis at h meets the rear sphere at
  // incidence asin(h / 10), beyond the critical angle asin(1 / 1.5) when h > 6.67 mm.
  const Prescription lens = lens_in_air(
      {make_surface(kInfinity, 12.0, constant_glass(1.5)), make_surface(-10.0, 20.0, MaterialSpec::air())}, 4.0);
  const SequentialTracer tracer(lens);
  CHECK(tracer.trace_forward(make_ray({0, 6.5, -1.0}, {0, 0, 1})).ok());
  const TraceResult r = tracer.trace_forward(make_ray({0, 7.0, -1.0}, {0, 0, 1}));
  CHECK(r.status == RayStatus::TotalInternalReflection);
  CHECK(r.surface == 2);
  CHECK(to_string(r.status) == "tir");
}

TEST_CASE("NaN, infinite or zero directions and positions, and bad wavelengths, are InvalidInput", "[trace][status]") {
  const SequentialTracer tracer(sasian_triplet());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<Ray> bad(5, make_ray({0, 1, -5}, {0, 0, 1}));
  bad[0].direction = Eigen::Vector3d(nan, 0, 1);
  bad[1].direction = Eigen::Vector3d::Zero();
  bad[2].position_mm.x() = kInfinity;
  bad[3].wavelength_nm = nan;
  bad[4].wavelength_nm = 0.0;
  for (const Ray& ray : bad) {
    INFO(ray.to_string());
    for (TraceDirection direction : {TraceDirection::Forward, TraceDirection::Backward}) {
      const TraceResult r = tracer.trace(ray, direction);
      CHECK(r.status == RayStatus::InvalidInput);
      CHECK(r.surface == 0);
    }
  }
  CHECK(to_string(RayStatus::InvalidInput) == "invalid_input");
  CHECK(to_string(RayStatus::NotConverged) == "not_converged");
  CHECK(to_string(RayStatus::Missed) == "missed");
  CHECK(to_string(RayStatus::Ok) == "ok");
}

TEST_CASE("a direction that is not unit length is normalised", "[trace]") {
  const SequentialTracer tracer(sasian_triplet());
  Ray unit = make_ray({0.5, 1.0, -5.0}, {0.01, 0.05, 1.0});
  Ray longer = unit;
  longer.direction *= 3.0;
  const TraceResult a = tracer.trace_forward(unit);
  const TraceResult b = tracer.trace_forward(longer);
  REQUIRE(a.ok());
  CHECK_THAT((a.ray.position_mm - b.ray.position_mm).norm(), WithinAbs(0.0, kArithmetic_mm));
  CHECK_THAT(b.ray.direction.norm(), WithinAbs(1.0, kDirectionRounding));
}

// ---------------------------------------------------------------------------------------------
// Image plane, indices, batch

TEST_CASE("the image plane is the last thickness, the paraxial focus, or the override", "[trace]") {
  const Prescription lens = sasian_triplet();  // last thickness 41.2365, paraxial BFL 41.2376
  const double z_last = lens.last_vertex_z_mm();
  CHECK_THAT(SequentialTracer(lens).image_plane_z_mm(), WithinAbs(z_last + 41.2365, kArithmetic_mm));
  TracerOptions focus;
  focus.image_plane = TracerOptions::ImagePlane::ParaxialFocus;
  CHECK_THAT(SequentialTracer(lens, focus).image_plane_z_mm(),
             WithinAbs(z_last + ParaxialSystem(lens).image_distance_mm(), kArithmetic_mm));
  TracerOptions fixed;
  fixed.image_distance_mm = 40.0;
  fixed.image_plane = TracerOptions::ImagePlane::ParaxialFocus;  // the override wins
  CHECK_THAT(SequentialTracer(lens, fixed).image_plane_z_mm(), WithinAbs(z_last + 40.0, kArithmetic_mm));
  // Smith's triplet asks for the paraxial focus in the prescription itself.
  const Prescription smith = smith_cooke_triplet();
  CHECK_THAT(SequentialTracer(smith).image_plane_z_mm(), WithinAbs(ParaxialSystem(smith).z_image_mm(), kArithmetic_mm));
  CHECK(SequentialTracer(smith).vertex_z_mm(7) == smith.last_vertex_z_mm());
  CHECK_THROWS_AS(SequentialTracer(smith).vertex_z_mm(8), std::out_of_range);

  TracerOptions bad;
  bad.image_distance_mm = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(bad.validate(), Catch::Contains("TracerOptions::image_distance_mm") && Catch::Contains("finite"));
  CHECK_THROWS_AS(SequentialTracer(lens, bad), OptionsError);
}

TEST_CASE("indices come from each medium's glass at the ray's wavelength, cached or not", "[trace]") {
  const Prescription lens = sasian_triplet();
  const SequentialTracer tracer(lens);
  CHECK(tracer.index_after(0, 500.0) == 1.0);
  CHECK(tracer.index_after(1, 500.0) == lens.surfaces[0].medium.index(500.0));
  CHECK(tracer.index_after(3, 700.0) == lens.surfaces[2].medium.index(700.0));
  CHECK_THROWS_AS(tracer.index_after(7, 500.0), std::out_of_range);
  // More distinct wavelengths than the cache holds: a ray at each, traced by the shared tracer (cached
  // or, once the table is full, evaluated per surface) and by a fresh tracer, lands at the same place.
  const RayAimer aimer(tracer);
  for (int i = 0; i < 400; ++i) {
    const double wavelength = 400.0 + 0.75 * i;
    const Ray ray = aimer.make_ray(FieldPoint::angle_deg(14.0), {0.3, 0.7}, wavelength).ray;
    const TraceResult shared = tracer.trace_forward(ray);
    const TraceResult fresh = SequentialTracer(lens).trace_forward(ray);
    INFO(wavelength << " nm");
    REQUIRE(shared.ok());
    CHECK(shared.ray.position_mm == fresh.ray.position_mm);
    CHECK(shared.ray.direction == fresh.ray.direction);
  }
}

TEST_CASE("the batch path gives the same bits as the single-ray path, on many rays and threads", "[trace][batch]") {
#if __has_include(<omp.h>)
  omp_set_num_threads(4);  // several threads even on a 1- or 2-core machine
#endif
  for (const char* id : {"angenieux-double-gauss-1953", "aspherical-fisheye", "smith-cooke-triplet"}) {
    const Prescription lens = LensLibrary::load(id).prescription;
    const SequentialTracer tracer(lens);
    const RayAimer aimer(tracer);
    // Rays over the field and an oversized pupil, so the batch holds vignetted and missed rays too, at the
    // lens's wavelengths and at many others (some past the index cache's capacity).
    std::vector<Ray> rays;
    for (int i = 0; i < 6000; ++i) {
      const double field = (i % 7) / 6.0;
      const double px = 1.4 * std::cos(0.37 * i) * std::sqrt((i % 13) / 12.0);
      const double py = 1.4 * std::sin(0.37 * i) * std::sqrt((i % 13) / 12.0);
      const double wavelength = i % 3 == 0 ? lens.wavelengths_nm[static_cast<std::size_t>(i) % lens.wavelengths_nm.size()]
                                           : 420.0 + 0.05 * i;
      const FieldPoint fp = lens.field ? aimer.field_at(field) : FieldPoint::angle_deg(10.0 * field);
      rays.push_back(aimer.make_ray(fp, {px, py}, wavelength).ray);
    }
    for (TraceDirection direction : {TraceDirection::Forward, TraceDirection::Backward}) {
      RayBatch batch;
      batch.resize(rays.size());
      std::vector<Ray> inputs = rays;
      if (direction == TraceDirection::Backward) {
        // Start from where the forward rays land, reversed (dead ones are simply other rays).
        for (Ray& r : inputs) {
          const TraceResult f = tracer.trace_forward(r);
          r.position_mm = f.ray.position_mm;
          r.direction = -f.ray.direction;
        }
      }
      for (std::size_t i = 0; i < inputs.size(); ++i) batch.set(i, inputs[i]);
      tracer.trace_batch(batch, direction);
      int ok = 0;
      int dead = 0;
      for (std::size_t i = 0; i < inputs.size(); ++i) {
        const TraceResult single = tracer.trace(inputs[i], direction);
        INFO(id << ", ray " << i << ": " << single.to_string());
        REQUIRE(batch.status[i] == single.status);
        REQUIRE(batch.surface[i] == single.surface);
        const Ray out = batch.get(i);
        REQUIRE(out.position_mm == single.ray.position_mm);
        REQUIRE(out.direction == single.ray.direction);
        REQUIRE(out.wavelength_nm == inputs[i].wavelength_nm);
        (single.ok() ? ok : dead) += 1;
      }
      INFO(id << ": " << ok << " ok, " << dead << " dead");
      CHECK(ok > 1000);
      CHECK(dead > 100);
    }
  }
  RayBatch uneven;
  uneven.resize(3);
  uneven.l.resize(2);
  CHECK_THROWS_AS(SequentialTracer(sasian_triplet()).trace_batch(uneven, TraceDirection::Forward), OptionsError);
}

TEST_CASE("a batch in rows of the caller's arrays traces to the same bits as a RayBatch, without touching the inputs",
          "[trace][batch]") {
  // The Python module's layout: (N, 3) row-major positions and directions, outputs in other arrays,
  // one wavelength for all rays (stride 0) or one per ray.
  const Prescription lens = LensLibrary::load("zeiss-biotar-1927").prescription;
  const SequentialTracer tracer(lens);
  const RayAimer aimer(tracer);
  constexpr std::size_t kRays = 3000;
  std::vector<double> origins(3 * kRays), directions(3 * kRays), wavelengths(kRays);
  RayBatch batch;
  batch.resize(kRays);
  for (std::size_t i = 0; i < kRays; ++i) {
    const double r = 1.3 * std::sqrt(static_cast<double>(i % 17) / 16.0), a = 0.61 * static_cast<double>(i);
    wavelengths[i] = i % 2 ? 486.1327 : 656.2725;
    Ray ray = aimer.make_ray(FieldPoint::angle_deg(4.0 * static_cast<double>(i % 5)), {r * std::cos(a), r * std::sin(a)}, wavelengths[i]).ray;
    if (i == 7) ray.direction = {0.0, 0.0, 0.0};  // invalid: kept as given
    for (int c = 0; c < 3; ++c) {
      origins[3 * i + static_cast<std::size_t>(c)] = ray.position_mm[c];
      directions[3 * i + static_cast<std::size_t>(c)] = ray.direction[c];
    }
    batch.set(i, ray);
  }
  const std::vector<double> origins_before = origins, directions_before = directions;
  tracer.trace_batch(batch, TraceDirection::Forward);

  std::vector<double> positions(3 * kRays), out_directions(3 * kRays);
  std::vector<RayStatus> status(kRays);
  std::vector<int> surface(kRays);
  RayBatchView view;
  view.count = kRays;
  view.x_mm = origins.data();
  view.y_mm = origins.data() + 1;
  view.z_mm = origins.data() + 2;
  view.l = directions.data();
  view.m = directions.data() + 1;
  view.n = directions.data() + 2;
  view.stride = 3;
  view.wavelength_nm = wavelengths.data();
  view.x_out_mm = positions.data();
  view.y_out_mm = positions.data() + 1;
  view.z_out_mm = positions.data() + 2;
  view.l_out = out_directions.data();
  view.m_out = out_directions.data() + 1;
  view.n_out = out_directions.data() + 2;
  view.out_stride = 3;
  view.status = status.data();
  view.surface = surface.data();
  tracer.trace_batch(view, TraceDirection::Forward);
  CHECK(origins == origins_before);
  CHECK(directions == directions_before);
  for (std::size_t i = 0; i < kRays; ++i) {
    INFO("ray " << i);
    REQUIRE(status[i] == batch.status[i]);
    REQUIRE(surface[i] == batch.surface[i]);
    REQUIRE(positions[3 * i] == batch.x_mm[i]);
    REQUIRE(positions[3 * i + 2] == batch.z_mm[i]);
    REQUIRE(out_directions[3 * i + 1] == batch.m[i]);
  }
  CHECK(status[7] == RayStatus::InvalidInput);
  CHECK(out_directions[3 * 7 + 2] == 0.0);

  // One wavelength for every ray: stride 0.
  const double blue = 486.1327;
  view.wavelength_nm = &blue;
  view.wavelength_stride = 0;
  tracer.trace_batch(view, TraceDirection::Forward);
  CHECK(status[1] == batch.status[1]);
  CHECK(positions[3 * 1] == batch.x_mm[1]);  // ray 1 is blue in both
  view.stride = 0;
  CHECK_THROWS_AS(tracer.trace_batch(view, TraceDirection::Forward), OptionsError);
}

// Third-order theory against the exact tracer: as aperture and field shrink by s, the real transverse
// aberration on the Gaussian image plane approaches the Seidel prediction (their ratio -> 1) and the
// residual, the fifth- and higher-order part, falls like s^5: halving s divides it by about 32.
// Every shipped lens (aspheric ones included), three wavelengths and two object distances.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "lensmith/core/units.h"
#include "lensmith/prescription/lens_library.h"
#include "lensmith/seidel/aberration_vector.h"
#include "lensmith/trace/sequential_tracer.h"

using namespace lensmith;

namespace {

struct Residual {
  bool ok = false;
  double exact_mm = 0.0;      // real ray minus Gaussian image point, y component
  double predicted_mm = 0.0;  // third-order prediction
  double exact_x_mm = 0.0;    // the same, x component (skew rays)
  double predicted_x_mm = 0.0;
};

// Real and predicted y displacement for the ray at pupil (0, s*rho) and field s*h (fractions of the
// lens's aperture and maximum field), on the Gaussian image plane of this wavelength and distance.
Residual residual(const Prescription& lens, double wavelength_nm, double object_distance_mm, double s, double rho, double h,
                  double theta = 0.0) {
  SeidelOptions so;
  so.wavelength_nm = wavelength_nm;
  so.object_distance_mm = object_distance_mm;
  const SeidelAnalysis seidel(lens, so);
  const AberrationCoefficients c = AberrationCoefficients::from(seidel);
  const ParaxialSystem& p = seidel.paraxial();

  Prescription at_distance = lens;
  at_distance.object_distance_mm = object_distance_mm;
  TracerOptions to;
  to.image_distance_mm = p.image_distance_mm();
  to.clip_apertures = false;  // third-order theory knows no vignetting
  const SequentialTracer tracer(at_distance, to);

  // The ray through the paraxial entrance pupil of this wavelength at height s*rho*r (Seidel theory's
  // pupil coordinate), from the chief ray's object point, or along its direction at infinity, scaled
  // by s*h (the paraxial field variable is linear in tan(angle) and in object height).
  const ParaxialRayTable& chief = *p.chief_ray();
  const double pupil_radius = s * rho * 0.5 * p.entrance_pupil().diameter_mm;
  const Eigen::Vector3d pupil_point(pupil_radius * std::sin(theta), pupil_radius * std::cos(theta), p.entrance_pupil().z_mm);
  Ray ray;
  ray.wavelength_nm = wavelength_nm;
  if (std::isinf(object_distance_mm)) {
    ray.direction = Eigen::Vector3d(0.0, s * h * chief.object_slope, 1.0).normalized();
    const double z_start = std::min(0.0, pupil_point.z()) - 10.0;  // in object space, before surface 1
    ray.position_mm = pupil_point + ray.direction * ((z_start - pupil_point.z()) / ray.direction.z());
  } else {
    ray.position_mm = Eigen::Vector3d(0.0, s * h * chief.object_height_mm, -object_distance_mm);
    ray.direction = (pupil_point - ray.position_mm).normalized();
  }
  Residual r;
  const TraceResult traced = tracer.trace_forward(ray);
  if (!traced.ok()) return r;
  // Gaussian image point: the paraxial chief ray carried to the paraxial image plane of this
  // wavelength and distance (the table's image_height_mm is at the prescription's image plane).
  const ParaxialRayRow& last = chief.rows.back();
  const double gaussian_y = s * h * (last.y_mm + last.u_after * p.image_distance_mm());
  r.ok = true;
  r.exact_mm = traced.ray.position_mm.y() - gaussian_y;
  r.predicted_mm = c.displacement(s * rho, theta, s * h).y_mm;
  r.exact_x_mm = traced.ray.position_mm.x();
  r.predicted_x_mm = c.displacement(s * rho, theta, s * h).x_mm;
  return r;
}

}  // namespace

TEST_CASE("Seidel vs exact tracer: the third-order prediction converges, residual ~ s^5, for every shipped lens",
          "[seidel][trace][convergence]") {
  // s = 0.02 and 0.01: small enough that fifth order dominates the residual, large enough that the
  // residual (~ s^5 of millimetres) stays far above double rounding of the image position.
  constexpr double kLarge = 0.02;
  constexpr double kSmall = 0.01;
  // Ratio of residuals for halved s: 2^5 = 32 for a pure fifth-order residual; seventh order and the
  // pupil mapping shift it a little.
  constexpr double kMinRatio = 28.0;
  constexpr double kMaxRatio = 36.0;
  // At s = 0.01 the fifth-order part is ~1e-4 of the third-order one; measured worst 6.4e-4.
  constexpr double kThirdOrderShare = 2e-3;
  int checked = 0;
  for (const ShippedLens& shipped : LensLibrary::list()) {
    Prescription lens = LensLibrary::load(shipped.id).prescription;
    // Lenses whose source states no field get a 10-degree one: the test shrinks it by s anyway.
    if (!lens.field) lens.field = FieldSpec{FieldSpec::Kind::AngleDeg, {10.0}};
    for (double wavelength_nm : {486.1327, 587.5618, 656.2725}) {
      for (double distance_mm : {kInfinity, 2000.0}) {
        // A general ray: 70 % of the aperture, 70 % of the field, both aberration types mixed.
        const Residual big = residual(lens, wavelength_nm, distance_mm, kLarge, 0.7, 0.7);
        const Residual small = residual(lens, wavelength_nm, distance_mm, kSmall, 0.7, 0.7);
        INFO(shipped.id << " at " << wavelength_nm << " nm, object " << distance_mm << " mm: exact " << small.exact_mm << " mm, third order "
                        << small.predicted_mm << " mm");
        REQUIRE(big.ok);
        REQUIRE(small.ok);
        const double residual_big = big.exact_mm - big.predicted_mm;
        const double residual_small = small.exact_mm - small.predicted_mm;
        // The prediction carries the exact value.
        CHECK(std::abs(small.exact_mm / small.predicted_mm - 1.0) < kThirdOrderShare);
        const double ratio = residual_big / residual_small;
        INFO("residual ratio for halved s: " << ratio);
        CHECK(ratio > kMinRatio);
        CHECK(ratio < kMaxRatio);
        // A skew ray (pupil angle 60 degrees from the meridian): both components converge.
        const Residual skew_big = residual(lens, wavelength_nm, distance_mm, kLarge, 0.8, 0.6, rad_from_deg(60.0));
        const Residual skew = residual(lens, wavelength_nm, distance_mm, kSmall, 0.8, 0.6, rad_from_deg(60.0));
        REQUIRE(skew.ok);
        REQUIRE(skew_big.ok);
        CHECK(std::abs(skew.exact_x_mm / skew.predicted_x_mm - 1.0) < kThirdOrderShare);
        CHECK(std::abs(skew.exact_mm / skew.predicted_mm - 1.0) < kThirdOrderShare);
        const double skew_ratio = (skew_big.exact_x_mm - skew_big.predicted_x_mm) / (skew.exact_x_mm - skew.predicted_x_mm);
        INFO("skew x residual ratio for halved s: " << skew_ratio);
        CHECK(skew_ratio > kMinRatio);
        CHECK(skew_ratio < kMaxRatio);
        ++checked;
      }
    }
  }
  CHECK(checked == 6 * static_cast<int>(LensLibrary::list().size()));  // every lens, three wavelengths, two distances
}

// Primary rays for path tracers (lens_camera.h) against the exact tracer run the other way, the
// definition of the weight's normalisation, and the fit against the tracer.
#include "lensmith/camera/lens_camera.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <memory>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "lensmith/prescription/lens_library.h"

#include "camera_options.h"

using namespace lensmith;

namespace {

CameraOptions options(double focus_m, double f_number) { return testing::camera_options(focus_m, f_number); }

// The camera-frame ray (metres) back in the lens frame (mm; z = 0 at surface 1), travelling into
// the lens (+z): lens_camera.h's frames, undone.
Ray into_lens(const Camera& camera, const CameraRay& r, double wavelength_nm) {
  Ray ray;
  ray.position_mm = Eigen::Vector3d(mm_from_m(r.origin_m.x()), mm_from_m(r.origin_m.y()), camera.z_perspective_mm() - mm_from_m(r.origin_m.z()));
  ray.direction = Eigen::Vector3d(-r.direction.x(), -r.direction.y(), r.direction.z());
  ray.wavelength_nm = wavelength_nm;
  return ray;
}

}  // namespace

TEST_CASE("A lens camera's ray, traced forward through the lens, lands on the film point it came from", "[camera][lens_camera]") {
  // Outside truth: the sequential tracer's forward trace, the inverse of the backward trace that
  // made the ray; it checks the frames and the direction convention of the public ray.
  // A unit vector along the axis: its z is 1 to an ulp or two (2.2e-16 each).
  constexpr double kUlps = 1e-15;
  // The origin's z from the perspective centre's: a mm-to-m conversion and a frame change, a few ulps.
  constexpr double kFrameChange = 1e-12;
  const Camera camera = Camera::from_lens(LensLibrary::load("pbrt-dgauss-50mm").prescription, options(2.0, 2.8), 640, 480);
  const LensCamera lc(camera, std::vector<double>{450.0, 587.56, 650.0});
  TracerOptions to;
  to.image_distance_mm = camera.z_sensor_mm() - camera.lens()->last_vertex_z_mm();
  const SequentialTracer tracer(*camera.lens(), to);
  int passed = 0;
  for (const auto& [fx, fy] : {std::pair{0.0, 0.0}, std::pair{6.0, -3.0}, std::pair{-10.0, 7.5}}) {
    for (double u : {0.05, 0.4, 0.8}) {
      for (double v : {0.0, 0.3, 0.7}) {
        const auto ray = lc.generate_ray(fx, fy, u, v, 587.56);
        if (!ray) continue;
        ++passed;
        CHECK(ray->weight > 0.0);
        CHECK(std::abs(ray->direction.norm() - 1.0) < 1e-12);
        CHECK(ray->direction.z() > 0.0);  // into the scene
        const TraceResult back = tracer.trace_forward(into_lens(camera, *ray, 587.56));
        REQUIRE(back.ok());
        INFO("film (" << fx << ", " << fy << "), pupil (" << u << ", " << v << ")");
        CHECK(std::abs(back.ray.position_mm.x() - fx) < 1e-8);
        CHECK(std::abs(back.ray.position_mm.y() - fy) < 1e-8);
      }
    }
  }
  CHECK(passed > 20);
  // The chief ray of the film's centre runs along the axis from the vertex of the front surface.
  const auto chief = lc.generate_ray(0.0, 0.0, 0.0, 0.0, 587.56);
  REQUIRE(chief);
  CHECK(std::abs(chief->origin_m.x()) < 1e-15);
  CHECK(chief->direction.z() == Approx(1.0).epsilon(kUlps));
  CHECK(chief->origin_m.z() == Approx(m_from_mm(camera.z_perspective_mm())).epsilon(kFrameChange));
}

TEST_CASE("At the film's centre the weights average to 1 over uniform pupil samples: a uniform surface gives its radiance",
          "[camera][lens_camera]") {
  // The normalisation's definition (lens_camera.h), checked with another quadrature (a uniform
  // u, v grid, not the constructor's polar grid): the beam's edge in a 256 x 256 grid costs < 0.5 %.
  // The uniform grid resolves the beam's edge to under 0.5 % (above).
  constexpr double kGridEdge = 5e-3;
  const Camera camera = Camera::from_lens(LensLibrary::load("sasian-triplet").prescription, options(3.0, 4.0), 640, 480);
  const LensCamera lc(camera, std::vector<double>{550.0});
  constexpr int kGrid = 256;
  double sum = 0.0;
  for (int i = 0; i < kGrid; ++i) {
    for (int j = 0; j < kGrid; ++j) {
      if (const auto r = lc.generate_ray(0.0, 0.0, (i + 0.5) / kGrid, (j + 0.5) / kGrid, 550.0)) sum += r->weight;
    }
  }
  CHECK(sum / (kGrid * kGrid) == Approx(1.0).margin(kGridEdge));
  // Off axis the mean falls (cos^4, vignetting): the frame's corner gets less.
  double corner = 0.0;
  const auto film = lc.film_point_mm(0.5, 0.5);
  for (int i = 0; i < kGrid; ++i) {
    for (int j = 0; j < kGrid; ++j) {
      if (const auto r = lc.generate_ray(film[0], film[1], (i + 0.5) / kGrid, (j + 0.5) / kGrid, 550.0)) corner += r->weight;
    }
  }
  CHECK(corner / (kGrid * kGrid) < 0.95);
  CHECK(corner > 0.0);
}

TEST_CASE("A lens camera on a polynomial fit sends the rays the exact tracer sends, to the fit's held-out error", "[camera][lens_camera]") {
  // The same cos^4 / D^2 in both; their normalisations differ by the fit's clipping.
  constexpr double kFitClipping = 0.02;
  const Camera camera = Camera::from_lens(LensLibrary::load("sasian-triplet").prescription, options(3.0, 5.6), 640, 480);
  LensFitOptions fo;
  fo.training_rays = 6000;
  fo.test_rays = 2000;
  const auto fit = std::make_shared<const LensFit>(LensFit::fit(*camera.lens(), fo));
  const LensCamera exact(camera, std::vector<double>{550.0});
  const LensCamera poly(camera, fit, std::vector<double>{550.0});
  CHECK(poly.uses_fit());
  // Position on the front surface: the fit's held-out error (um), with room for the sensor shift.
  const double position_tolerance_m = m_from_mm(5e-3 * fit->errors().position_rms_um + 2e-3);
  const double direction_tolerance = 5e-3 * fit->errors().direction_rms_mrad + 2e-4;
  int compared = 0;
  for (double fy : {0.0, 4.0, 9.0}) {
    for (double u : {0.1, 0.5, 0.85}) {
      for (double v : {0.1, 0.6}) {
        const auto a = exact.generate_ray(0.0, fy, u, v, 550.0);
        const auto b = poly.generate_ray(0.0, fy, u, v, 550.0);
        if (!(a && b)) continue;
        ++compared;
        INFO("film y " << fy << ", pupil (" << u << ", " << v << ")");
        CHECK((a->origin_m - b->origin_m).norm() < position_tolerance_m);
        CHECK((a->direction - b->direction).norm() < direction_tolerance);
        CHECK(a->weight == Approx(b->weight).epsilon(kFitClipping));
      }
    }
  }
  CHECK(compared > 10);
}

TEST_CASE("A lens camera refuses a thin-lens camera, and a fit of another lens", "[camera][lens_camera]") {
  const Camera thin = Camera::thin_lens(50.0, options(2.0, 2.0), 64, 48);
  CHECK_THROWS_AS(LensCamera(thin), OptionsError);
  const Camera camera = Camera::from_lens(LensLibrary::load("sasian-triplet").prescription, options(3.0, 5.6), 64, 48);
  LensFitOptions fo;
  fo.training_rays = 1000;
  fo.test_rays = 300;
  fo.degree = 3;
  const auto other = std::make_shared<const LensFit>(LensFit::fit(LensLibrary::load("zeiss-biotar-1927").prescription, fo));
  CHECK_THROWS_AS(LensCamera(camera, other), OptionsError);
}

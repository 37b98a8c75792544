// The component form of a lens fit (component_map.h), for lenses symmetric only under their two section
// mirrors: its pools keep exactly the monomials those mirrors allow, a map of that form is recovered
// exactly from its own values, its Jacobian is the derivative of its values, and its batch path agrees
// with the point path. Then whole fits of lentil's Schneider anamorphic against the exact tracer.
#include "lensmith/polyfit/component_map.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include "lensmith/core/errors.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "lensmith/polyfit/lens_fit.h"
#include "lensmith/polyfit/term_pool.h"
#include "lensmith/prescription/lens_file.h"
#include "lensmith/prescription/lens_library.h"
#include "lensmith/trace/sequential_tracer.h"

using namespace lensmith;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;

namespace {

// Parity of a monomial under x -> -x (in x and dx) and y -> -y (in y and dy).
bool odd_in_x(const Monomial& m) { return (m.exponents[0] + m.exponents[2]) % 2 == 1; }
bool odd_in_y(const Monomial& m) { return (m.exponents[1] + m.exponents[3]) % 2 == 1; }

std::vector<PolyPoint> random_points(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<PolyPoint> points(n);
  for (PolyPoint& p : points) {
    for (double& v : p) v = u(rng);
  }
  return points;
}

// A two-output map of the section-mirror form with a few known terms of each component.
ComponentMap known_map() {
  std::vector<ComponentTerm> terms;
  std::vector<double> coefficients;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  const std::vector<ComponentTerm> pool = vector_component_terms(5);
  for (std::size_t i = 0; i < pool.size(); i += 9) {
    terms.push_back(pool[i]);
    coefficients.push_back(u(rng));
    coefficients.push_back(u(rng));
  }
  return ComponentMap(terms, 2, coefficients);
}

// A smaller fit than the default (30000 rays) of the anamorphic, shared by the tests that only read it.
const LensFit& anamorphic_fit() {
  static const LensFit fit = [] {
    LensFitOptions o;
    o.training_rays = 12000;
    o.test_rays = 2000;
    return LensFit::fit(read_lens_file(std::string(LENSMITH_TEST_DATA_DIR) + "/lentil/lenses.json#2004").prescription, o);
  }();
  return fit;
}

}  // namespace

TEST_CASE("Component pools hold exactly the monomials the two section mirrors allow") {
  // x components change sign under x -> -x and keep it under y -> -y; y components the reverse; scalars
  // keep it under both (term_pool.h). Every such monomial is a candidate, once.
  const std::vector<ComponentTerm> vector_pool = vector_component_terms(7);
  std::size_t x_terms = 0, y_terms = 0;
  for (const ComponentTerm& t : vector_pool) {
    INFO(t);
    REQUIRE(t.component != MapComponent::kScalar);
    if (t.component == MapComponent::kX) {
      ++x_terms;
      CHECK((odd_in_x(t.monomial) && !odd_in_y(t.monomial)));
    } else {
      ++y_terms;
      CHECK((!odd_in_x(t.monomial) && odd_in_y(t.monomial)));
    }
  }
  CHECK(x_terms == symmetric_monomials(7, OutputParity::kOddInX).size());
  CHECK(y_terms == symmetric_monomials(7, OutputParity::kOddInY).size());
  for (const ComponentTerm& t : scalar_component_terms(6)) {
    CHECK(t.component == MapComponent::kScalar);
    CHECK((!odd_in_x(t.monomial) && !odd_in_y(t.monomial)));
  }
  CHECK(scalar_component_terms(6).size() == symmetric_monomials(6, OutputParity::kEven).size());
  CHECK_THROWS_AS(vector_component_terms(12), OptionsError);
}

TEST_CASE("A map of the section-mirror form is recovered from its own values to rounding") {
  const ComponentMap truth = known_map();
  const std::vector<PolyPoint> inputs = random_points(3000, 3);
  std::vector<std::vector<std::array<double, 2>>> targets(2);
  std::array<double, 4> out;
  for (const PolyPoint& p : inputs) {
    truth.evaluate(p, out);
    targets[0].push_back({out[0], out[1]});
    targets[1].push_back({out[2], out[3]});
  }
  FitOptions o;
  o.max_degree = 5;
  o.max_terms = static_cast<int>(truth.size()) + 10;
  const ComponentFitResult fit = fit_component_map(inputs, targets, vector_component_terms(5), o);
  // Exact data of the pool's own form: selection finds the true terms and least squares their values,
  // to the rounding of a dense QR on values of order 10.
  constexpr double kRounding = 1e-9;
  CHECK(fit.train_rms[0] < kRounding);
  CHECK(fit.train_rms[1] < kRounding);
  for (const PolyPoint& p : random_points(50, 4)) {
    std::array<double, 4> a, b;
    truth.evaluate(p, a);
    fit.map.evaluate(p, b);
    for (int k = 0; k < 4; ++k) CHECK_THAT(b[static_cast<std::size_t>(k)], WithinAbs(a[static_cast<std::size_t>(k)], kRounding));
  }
}

TEST_CASE("A component map's Jacobian is the derivative of its values, and its batch path agrees with its point path") {
  const ComponentMap map = known_map();
  // Central differences of a degree-5 polynomial: error h^2 / 6 |f'''| ~ 1e-10 at h = 1e-5, far above rounding.
  constexpr double kStep = 1e-5, kDifferenceError = 1e-7;
  for (const PolyPoint& p : random_points(20, 5)) {
    std::array<double, 2> value;
    std::array<double, 8> jacobian;
    map.evaluate_with_jacobian(p, 1, value, jacobian);
    const std::array<double, 2> direct = map.evaluate_output(p, 1);
    CHECK(value[0] == direct[0]);
    CHECK(value[1] == direct[1]);
    for (std::size_t i = 0; i < 4; ++i) {
      PolyPoint plus = p, minus = p;
      plus[i] += kStep;
      minus[i] -= kStep;
      const std::array<double, 2> a = map.evaluate_output(plus, 1), b = map.evaluate_output(minus, 1);
      CHECK_THAT(jacobian[i], WithinAbs((a[0] - b[0]) / (2.0 * kStep), kDifferenceError));
      CHECK_THAT(jacobian[4 + i], WithinAbs((a[1] - b[1]) / (2.0 * kStep), kDifferenceError));
    }
  }
  // The batch path normalises on the fly: v = in * scale + offset.
  const std::vector<PolyPoint> points = random_points(70, 6);
  std::array<std::vector<double>, kPolyVariables> in;
  const std::array<double, kPolyVariables> scale{0.5, 0.25, 2.0, 4.0, 0.01}, offset{0.0, 0.0, 0.0, 0.0, -5.8};
  for (const PolyPoint& p : points) {
    for (std::size_t i = 0; i < kPolyVariables; ++i) in[i].push_back((p[i] - offset[i]) / scale[i]);
  }
  std::array<std::vector<double>, 4> out;
  for (auto& o : out) o.resize(points.size());
  const std::array<double*, 4> out_ptr{out[0].data(), out[1].data(), out[2].data(), out[3].data()};
  map.evaluate_batch({in[0].data(), in[1].data(), in[2].data(), in[3].data(), in[4].data()}, out_ptr, points.size(), scale, offset);
  for (std::size_t r = 0; r < points.size(); ++r) {
    std::array<double, 4> v;
    map.evaluate(points[r], v);
    for (std::size_t k = 0; k < 4; ++k) CHECK_THAT(out[k][r], WithinAbs(v[k], 1e-12));
  }
}

TEST_CASE("A component map refuses repeated terms, mixed kinds and mismatched coefficients") {
  const ComponentTerm x{Monomial{{1, 0, 0, 0, 0}}, MapComponent::kX};
  const ComponentTerm s{Monomial{{0, 0, 0, 0, 0}}, MapComponent::kScalar};
  CHECK_THROWS_WITH(ComponentMap({x, x}, 1, {1.0, 2.0}), Contains("listed twice"));
  CHECK_THROWS_WITH(ComponentMap({x, s}, 1, {1.0, 2.0}), Contains("cannot share a map"));
  CHECK_THROWS_WITH(ComponentMap({x}, 2, {1.0}), Contains("coefficients"));
  CHECK(x.to_string() == "x->x");
  CHECK(ComponentTerm{Monomial{{0, 2, 0, 1, 1}}, MapComponent::kY}.to_string() == "y^2*dy*lambda->y");
}

TEST_CASE("lentil's Schneider anamorphic is fitted in the component form, and its rays agree with the exact tracer") {
  const Prescription lens = read_lens_file(std::string(LENSMITH_TEST_DATA_DIR) + "/lentil/lenses.json#2004").prescription;
  const LensFit& fit = anamorphic_fit();
  CHECK(fit.symmetry() == LensSymmetry::kSectionMirrors);
  CHECK_FALSE(fit.sensor_to_outer().is_rotational());
  // Its x section's entrance pupil lies far in front of the y section's (an anamorphic front group).
  ParaxialOptions xs;
  xs.section = Section::X;
  CHECK_THAT(fit.pupils_x().z_entrance_pupil_mm, WithinAbs(ParaxialSystem(lens, xs).entrance_pupil().z_mm, 1e-9));
  CHECK(std::abs(fit.pupils_x().z_entrance_pupil_mm - fit.pupils().z_entrance_pupil_mm) > 50.0);
  // Held-out rays through the exact tracer: the sensor-side error is a fraction of a pixel of a 36-mm-wide
  // frame 640 px wide (56 um), measured 31-35 um RMS with 12000 training rays; the stop error the
  // same order (aiming depends on it).
  constexpr double kPixelUm = 36000.0 / 640.0;
  INFO(fit.errors());
  CHECK(fit.errors().sensor_position_rms_um < kPixelUm);
  CHECK(fit.errors().stop_rms_um < kPixelUm);
  CHECK(fit.errors().vignetting_mismatch < 0.01);

  // Aimed from an object point off axis in x and in y, the exact ray through the fitted outer point
  // crosses the stop where the fit says: within 5 x the fit's held-out stop RMS.
  TracerOptions free;
  free.image_plane = TracerOptions::ImagePlane::ParaxialFocus;
  free.clip_apertures = false;
  const SequentialTracer tracer(lens, free);
  const std::size_t stop = static_cast<std::size_t>(fit.stop_surface() - 1);
  const double tolerance_mm = 5e-3 * fit.errors().stop_rms_um;
  const double r = 0.7 * fit.stop_radius_mm();
  std::vector<SurfaceHit> path;
  for (const auto& [tx, ty] : {std::pair{0.0, 0.0}, std::pair{0.3, 0.0}, std::pair{0.0, 0.15}, std::pair{-0.2, 0.1}}) {
    const ObjectPoint object{tx, ty, 1.0 / 3000.0, fit.pupils().z_entrance_pupil_mm};
    for (const auto& [sx, sy] : {std::pair{0.0, 0.0}, std::pair{r, 0.0}, std::pair{0.0, -r}}) {
      const FitAim aim = fit.aim_from_object(object, sx, sy, 587.6);
      INFO("object tangents (" << tx << ", " << ty << "), stop (" << sx << ", " << sy << "): " << aim);
      REQUIRE(aim.converged);
      Ray ray;
      const double dz = std::sqrt(1.0 - aim.ray.dx * aim.ray.dx - aim.ray.dy * aim.ray.dy);
      ray.direction = Eigen::Vector3d(aim.ray.dx, aim.ray.dy, dz);
      double sag = 0.0, zx = 0.0, zy = 0.0;
      REQUIRE(lens.surfaces[0].sag_and_slope(aim.ray.x_mm, aim.ray.y_mm, sag, zx, zy));
      ray.position_mm = Eigen::Vector3d(aim.ray.x_mm, aim.ray.y_mm, sag) - 20.0 * ray.direction;
      ray.wavelength_nm = 587.6;
      REQUIRE(tracer.trace_forward(ray, &path).ok());
      CHECK(std::hypot(path[stop].point_mm.x() - sx, path[stop].point_mm.y() - sy) < tolerance_mm);
    }
  }
}

TEST_CASE("An anamorphic fit is written as version 2 and read back evaluating bit for bit the same, and a round lens's stays version 1") {
  const LensFit& fit = anamorphic_fit();
  const std::string text = fit.to_json();
  CHECK_THAT(text, Contains("\"version\": 2"));
  CHECK_THAT(text, Contains("\"section mirrors\""));
  const LensFit back = LensFit::parse(text, "fit.json");
  CHECK(back.to_json() == text);
  CHECK(back.symmetry() == LensSymmetry::kSectionMirrors);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 100; ++i) {
    const PlaneRay ray{8.0 * u(rng), 8.0 * u(rng), 0.1 * u(rng), 0.1 * u(rng)};
    const FitTrace a = fit.from_outer(ray, 550.0), b = back.from_outer(ray, 550.0);
    CHECK(a.ray.x_mm == b.ray.x_mm);
    CHECK(a.stop_y_mm == b.stop_y_mm);
    double zx_a = 0.0, zy_a = 0.0, zx_b = 0.0, zy_b = 0.0;
    CHECK(fit.front_sag(ray.x_mm, ray.y_mm, zx_a, zy_a) == back.front_sag(ray.x_mm, ray.y_mm, zx_b, zy_b));
    CHECK(zx_a == zx_b);
  }
  // A version-1 file cannot carry component terms.
  std::string as_v1 = text;
  as_v1.replace(as_v1.find("\"version\": 2"), 12, "\"version\": 1");
  CHECK_THROWS_AS(LensFit::parse(as_v1, "fit.json"), FileError);

  LensFitOptions small;
  small.training_rays = 2000;
  small.test_rays = 500;
  const LensFit round = LensFit::fit(LensLibrary::load("sasian-triplet").prescription, small);
  CHECK(round.symmetry() == LensSymmetry::kRotational);
  CHECK_THAT(round.to_json(), Contains("\"version\": 1"));
  CHECK_THAT(round.to_json(), !Contains("symmetry"));
}

TEST_CASE("A fit of an anamorphic lens refuses the lens with another x section") {
  // The hash covers the x curvature of toroids and biconics: a fit must not serve a lens whose cylinders differ.
  Prescription lens = read_lens_file(std::string(LENSMITH_TEST_DATA_DIR) + "/lentil/lenses.json#2004").prescription;
  const std::string hash = LensFit::prescription_hash(lens);
  REQUIRE(lens.surfaces[0].kind != SurfaceKind::Standard);
  lens.surfaces[0].curvature_x_per_mm *= 1.01;
  CHECK(LensFit::prescription_hash(lens) != hash);
  CHECK_THROWS_WITH(anamorphic_fit().check_matches(lens), Contains("not for"));
}

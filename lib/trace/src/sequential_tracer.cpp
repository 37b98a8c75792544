// Exact sequential ray tracing. Intersection with a conic in closed form on the sheet that contains the
// vertex (the general ray-trace formulation of Spencer & Murty, JOSA 52, 672 (1962), written in the
// cancellation-free "C / (B + sqrt)" form; Welford, Aberrations of Optical Systems, ch. 4); even aspheres by
// Newton's method on the sag along the ray with a bracketed regula-falsi fallback; vector Snell refraction;
// optical path n x length. Per-wavelength refractive indices come from a lock-free cache so that the per-ray
// loop allocates nothing and throws nothing. docs/trace.md explains the choices made here.
#include "lensmith/core/number_parsing.h"
#include "lensmith/trace/sequential_tracer.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "lensmith/prescription/conic_profile.h"
#include "lensmith/trace/surface_frames.h"

namespace lensmith {

namespace {

// A conic's vertex sheet is where 1 - (1 + k) c z >= 0 (the z-component of the unnormalised normal);
// at the rim of a hemisphere it is 0 and rounding leaves a few 1e-16 either side.
constexpr double kSheetTolerance = 1e-12;
// A ray that lands on a clear aperture's rim to within the rounding of the semi-diameter itself is
// kept: lens files give semi-diameters to 5 or 6 significant digits (the Sasian triplet's stop,
// 4.7919 mm, passes the paraxially aimed rim ray at 4.791917 mm, 3.5e-6 relative beyond it). 1e-5
// relative is 50 nm on a 5-mm stop, far below anything a clear aperture is made to.
constexpr double kClipRelativeTolerance = 1e-5;
// Newton on the aspheric sag stops when its step falls below this (mm). Steps are taken from a point
// within microns of the surface, so 1e-12 mm is a few ulps of the coordinates and far below any optical
// effect (1e-6 of a wavelength).
constexpr double kAsphereStepTolerance_mm = 1e-12;
// Newton converges quadratically from the base-conic intersection in 2-4 steps; 30 only ends a cycle.
constexpr int kMaxNewtonIterations = 30;
// Factor on Newton's predicted remaining error before it is trusted (see intersect_asphere).
constexpr double kNewtonSafety = 100.0;
// Fallback bracket search: samples at +/- kBracketFirstStep_mm x 2^j, j < kBracketDoublings, around the
// Newton start (up to 1.8e10 mm), then regula falsi (Illinois) for at most kMaxFalsiIterations steps.
constexpr double kBracketFirstStep_mm = 1e-3;
constexpr int kBracketDoublings = 45;
constexpr int kMaxFalsiIterations = 200;
// ... plus this many evenly spaced samples across the stretch of the ray inside a finite sag domain.
constexpr int kBracketUniformSamples = 256;
// ... and this many on each side approaching the domain's rim geometrically (down to 2^-38 of the stretch).
constexpr int kBracketRimSamples = 30;
// An input direction whose squared length is further than this from 1 is normalised (a unit vector
// made by Eigen's normalized() is within a few 1e-16).
constexpr double kUnitTolerance = 1e-14;
// Below this many rays a batch is traced on the calling thread: starting a thread team costs about
// as much as tracing a few hundred rays.
constexpr std::ptrdiff_t kParallelBatchThreshold = 256;

// General: a toroid or biconic, intersected through Surface::sag_and_slope (the general path only).
// Cylinder: a conic section in x-z or y-z extruded along the other axis (a biconic or toroid with one flat
// section: lentil's and most anamorphics' cylinders), a quadric intersected in closed form.
enum class Shape : std::uint8_t { Plane, Sphere, Conic, Asphere, General, Cylinder };

// What the inner loop needs of a surface, precomputed once.
struct SurfaceGeometry {
  Shape shape = Shape::Plane;
  double z_vertex_mm = 0.0;
  double curvature_per_mm = 0.0;
  double one_plus_conic = 1.0;               // 1 + k
  std::array<double, 8> asphere{};           // a2, a4, ..., a16 (r^2 ... r^16)
  int asphere_terms = 0;                     // highest non-zero coefficient + 1
  double clip_radius2_mm2 = std::numeric_limits<double>::infinity();  // (semi-diameter)^2 with tolerance
  bool has_aperture = false;                 // an explicit (non-circular, annular, obscuring or decentred) aperture
  SurfaceAperture aperture;                  // used when has_aperture
  double aperture_tolerance_mm = 0.0;        // its rim tolerance
  bool cylinder_in_x = false;                // Cylinder: curved in x (else in y), curvature_per_mm and one_plus_conic of that section
  bool is_break = false;                     // a coordinate break: no interaction (general path)
  bool mirror = false;                       // reflects (general path)
};

// A ray in the inner loop: position (global frame), unit direction, optical path so far.
struct State {
  double x, y, z;
  double l, m, n;
  double opl;
};

// An intersection: parameter along the ray (mm, may be negative), the unit normal (n_z >= 0), and the
// cosine of the angle of incidence against it, cos I = d.N (signed), with its square.
struct Hit {
  double t;
  double nx, ny, nz;
  double cos_i;
  double cos_i_squared;
};

// Intersection with the conic c (x^2 + y^2) + (1 + k) c z^2 - 2 z = 0, vertex at the origin of the local
// frame. With p = p0 + t d, |d| = 1, this is A t^2 - 2 B t + C = 0 with
//   A = c (1 + k d_z^2),  B = d.W,  C = c (x0^2 + y0^2 + (1 + k) z0^2) - 2 z0,
//   W = (-c x0, -c y0, 1 - (1 + k) c z0)
// (W is the unnormalised normal N = (-c x, -c y, 1 - (1 + k) c z), minus half the gradient, at p0).
// At the two roots N.d = -/+ sqrt(B^2 - AC), so the root crossing from the -z side (the front medium) to the
// +z side is t = C / (B + sqrt(B^2 - AC)) and the one crossing back is t = C / (B - sqrt(...)): `sense` = +1 /
// -1 picks the crossing in the direction of travel. Of the two algebraic forms of that root, the one without
// cancellation is used (C / (B + sense sqrt) when sense B >= 0, which also holds for A = 0, a paraboloid hit
// parallel to its axis). The point must lie on the vertex sheet, where N_z = 1 - (1 + k) c z >= 0.
inline double conic_b(double c, double one_plus_conic, double x0, double y0, double z0, double l, double m,
                      double n) {
  return n - c * (x0 * l + y0 * m + one_plus_conic * z0 * n);
}

// `b` is B for this ray and position (conic_b(), or the cheaper form the loop carries over a refraction).
inline bool intersect_conic(double c, double one_plus_conic, double x0, double y0, double z0, double l, double m,
                            double n, double b, double sense, Hit& hit) {
  const double a = c * (1.0 + (one_plus_conic - 1.0) * n * n);
  const double cc = c * (x0 * x0 + y0 * y0 + one_plus_conic * z0 * z0) - 2.0 * z0;
  const double discriminant = b * b - a * cc;
  if (!(discriminant >= 0.0)) return false;
  const double root = std::sqrt(discriminant);
  // The same root two ways: C / (B + sense sqrt) cancels when B has the sign opposite to `sense` (the ray
  // starts beyond the centre of curvature, e.g. on the far side of a ball), where (B - sense sqrt) / A does not.
  const double t = sense * b >= 0.0 ? cc / (b + sense * root) : (b - sense * root) / a;
  if (!std::isfinite(t)) return false;
  const double x = x0 + t * l;
  const double y = y0 + t * m;
  const double z = z0 + t * n;
  const double nz = 1.0 - one_plus_conic * c * z;
  if (nz < -kSheetTolerance) return false;
  hit.t = t;
  hit.nx = -c * x;
  hit.ny = -c * y;
  hit.nz = nz;
  if (one_plus_conic == 1.0) {
    // On a sphere |N| = 1 (|N|^2 = 1 + c F(p) and F(p) = 0), so cos I = N.d = sense sqrt(B^2 - AC) and
    // cos^2 I = B^2 - AC: the refraction starts from the discriminant while the square root, the division
    // and the point are still in flight, which shortens the latency chain of a surface by about a third.
    hit.cos_i = sense * root;
    hit.cos_i_squared = discriminant;
  } else {
    const double inverse_length = 1.0 / std::sqrt(hit.nx * hit.nx + hit.ny * hit.ny + nz * nz);
    hit.nx *= inverse_length;
    hit.ny *= inverse_length;
    hit.nz *= inverse_length;
    hit.cos_i = hit.nx * l + hit.ny * m + hit.nz * n;
    hit.cos_i_squared = hit.cos_i * hit.cos_i;
  }
  return true;
}

// Sag of an even asphere z(u), u = r^2, and dz/du (conic_profile.h, the one home of the shape); false
// outside the domain (D <= 0).
inline bool asphere_sag(const SurfaceGeometry& g, double u, double& sag, double& slope) {
  return conic_profile(g.curvature_per_mm, g.one_plus_conic, g.asphere.data(), g.asphere_terms, u, sag, slope);
}

// The asphere crossing at parameter t along the ray from (x0, y0, z0): checks the domain and, when
// `check_sense`, that the ray crosses in the direction of travel; fills the unit normal
// N = (-2 x z', -2 y z', 1) / |.| (z' = dz/du), which is the gradient of z - sag(u).
inline bool finish_asphere(const SurfaceGeometry& g, double x0, double y0, double l, double m, double n, double sense,
                           double t, bool check_sense, Hit& hit) {
  const double x = x0 + t * l;
  const double y = y0 + t * m;
  double sag = 0.0;
  double slope = 0.0;
  if (!asphere_sag(g, x * x + y * y, sag, slope)) return false;
  const double nx = -2.0 * x * slope;
  const double ny = -2.0 * y * slope;
  if (check_sense && !(sense * (nx * l + ny * m + n) > 0.0)) return false;
  const double inverse_length = 1.0 / std::sqrt(nx * nx + ny * ny + 1.0);
  if (!std::isfinite(inverse_length) || !std::isfinite(t)) return false;
  hit.t = t;
  hit.nx = nx * inverse_length;
  hit.ny = ny * inverse_length;
  hit.nz = inverse_length;
  hit.cos_i = hit.nx * l + hit.ny * m + hit.nz * n;
  hit.cos_i_squared = hit.cos_i * hit.cos_i;
  return true;
}

// Signed distance-like function along the ray: G(t) = sense (z - sag), negative on the side the ray
// comes from. False outside the sag's domain.
inline bool asphere_side(const SurfaceGeometry& g, double x0, double y0, double z0, double l, double m, double n,
                         double sense, double t, double& value) {
  const double x = x0 + t * l;
  const double y = y0 + t * m;
  double sag = 0.0;
  double slope = 0.0;
  if (!asphere_sag(g, x * x + y * y, sag, slope)) return false;
  value = sense * (z0 + t * n - sag);
  return std::isfinite(value);
}

// Fallback when Newton fails: sample G at parameters spaced geometrically on both sides of the start (fine
// near it, reaching far) and, when the sag's domain is a cylinder r^2 < 1 / ((1 + k) c^2), uniformly across
// the stretch of the ray inside it (so a crossing next to the domain's rim is not stepped over); take the sign
// change (front -> back) nearest to the start and refine it by regula falsi with the Illinois modification
// (Dowell & Jarratt, BIT 11, 168 (1971)). Missed when no sample lies in the domain or no sign change is found;
// NotConverged when the refinement does not reach the tolerance.
RayStatus bracket_asphere(const SurfaceGeometry& g, double x0, double y0, double z0, double l, double m, double n,
                          double sense, Hit& hit) {
  constexpr int kGeometric = 2 * kBracketDoublings + 1;
  constexpr int kSamples = kGeometric + kBracketUniformSamples + 2 * kBracketRimSamples;
  std::array<double, kSamples> ts{};
  std::array<double, kSamples> values{};
  std::array<bool, kSamples> valid{};
  int used = 0;
  for (int j = 0; j < kBracketDoublings; ++j) {
    const double step = std::ldexp(kBracketFirstStep_mm, j);
    ts[static_cast<std::size_t>(used++)] = -step;
    ts[static_cast<std::size_t>(used++)] = step;
  }
  ts[static_cast<std::size_t>(used++)] = 0.0;
  const double c = g.curvature_per_mm;
  const double domain = g.one_plus_conic * c * c;  // r^2 < 1 / domain when > 0
  const double transverse2 = l * l + m * m;
  if (domain > 0.0 && transverse2 > 0.0) {
    // r^2(t) = transverse2 t^2 + 2 p t + q = 1 / domain: the stretch of the ray inside the cylinder.
    const double p = x0 * l + y0 * m;
    const double q = x0 * x0 + y0 * y0 - 1.0 / domain;
    const double discriminant = p * p - transverse2 * q;
    if (discriminant > 0.0) {
      const double root = std::sqrt(discriminant);
      const double t_in = (-p - root) / transverse2;
      const double t_out = (-p + root) / transverse2;
      for (int i = 0; i < kBracketUniformSamples; ++i) {
        // Interior points only: the rim itself has an infinite slope.
        const double fraction = (i + 0.5) / kBracketUniformSamples;
        ts[static_cast<std::size_t>(used++)] = t_in + fraction * (t_out - t_in);
      }
      // Toward both ends, where the slope grows without bound and a crossing can hide next to the rim.
      for (int j = 1; j <= kBracketRimSamples; ++j) {
        const double offset = std::ldexp(t_out - t_in, -j - 8);
        ts[static_cast<std::size_t>(used++)] = t_in + offset;
        ts[static_cast<std::size_t>(used++)] = t_out - offset;
      }
    }
  }
  std::sort(ts.begin(), ts.begin() + used);
  bool any_valid = false;
  for (int i = 0; i < used; ++i) {
    const auto k = static_cast<std::size_t>(i);
    valid[k] = asphere_side(g, x0, y0, z0, l, m, n, sense, ts[k], values[k]);
    any_valid = any_valid || valid[k];
  }
  if (!any_valid) return RayStatus::Missed;
  int best = -1;
  double best_distance = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 1 < static_cast<std::size_t>(used); ++i) {
    if (valid[i] && valid[i + 1] && values[i] < 0.0 && values[i + 1] >= 0.0) {
      const double distance = std::min(std::abs(ts[i]), std::abs(ts[i + 1]));
      if (distance < best_distance) {
        best_distance = distance;
        best = static_cast<int>(i);
      }
    }
  }
  if (best < 0) return RayStatus::Missed;
  double a = ts[static_cast<std::size_t>(best)];
  double b = ts[static_cast<std::size_t>(best) + 1];
  double ga = values[static_cast<std::size_t>(best)];
  double gb = values[static_cast<std::size_t>(best) + 1];
  int retained = 0;  // -1: a kept twice in a row, +1: b kept twice
  for (int iteration = 0; iteration < kMaxFalsiIterations; ++iteration) {
    if (gb == 0.0) {
      a = b;
      break;
    }
    if (b - a <= kAsphereStepTolerance_mm) break;
    double t = (a * gb - b * ga) / (gb - ga);
    if (!(t > a && t < b)) t = 0.5 * (a + b);
    double gt = 0.0;
    if (!asphere_side(g, x0, y0, z0, l, m, n, sense, t, gt)) {
      // A hole in the domain inside the bracket: bisect instead.
      t = 0.5 * (a + b);
      if (!asphere_side(g, x0, y0, z0, l, m, n, sense, t, gt)) return RayStatus::NotConverged;
    }
    if (gt < 0.0) {
      a = t;
      ga = gt;
      if (retained == 1) gb *= 0.5;
      retained = 1;
    } else {
      b = t;
      gb = gt;
      if (retained == -1) ga *= 0.5;
      retained = -1;
    }
  }
  if (!(b - a <= kAsphereStepTolerance_mm) && gb != 0.0) return RayStatus::NotConverged;
  const double t = gb == 0.0 ? b : 0.5 * (a + b);
  return finish_asphere(g, x0, y0, l, m, n, sense, t, false, hit) ? RayStatus::Ok : RayStatus::NotConverged;
}

// Even asphere: Newton on G(t) = z(t) - sag(r^2(t)), G'(t) = N.d with N = (-2 x z', -2 y z', 1), started
// from the base conic's intersection (or the vertex plane). The ray is first moved to that start point
// so the iteration works on small parameters and converges to a few ulps of the coordinates.
RayStatus intersect_asphere(const SurfaceGeometry& g, const State& r, double sense, Hit& hit) {
  double x0 = r.x;
  double y0 = r.y;
  double z0 = r.z - g.z_vertex_mm;
  double t_start = 0.0;
  Hit base{};
  if (g.curvature_per_mm != 0.0 &&
      intersect_conic(g.curvature_per_mm, g.one_plus_conic, x0, y0, z0, r.l, r.m, r.n,
                      conic_b(g.curvature_per_mm, g.one_plus_conic, x0, y0, z0, r.l, r.m, r.n), sense, base)) {
    t_start = base.t;
  } else if (sense * r.n > 0.0) {
    t_start = -z0 / r.n;
  }
  x0 += t_start * r.l;
  y0 += t_start * r.m;
  z0 += t_start * r.n;

  double t = 0.0;
  bool converged = false;
  double previous_step = 0.0;  // none yet
  for (int iteration = 0; iteration < kMaxNewtonIterations; ++iteration) {
    const double x = x0 + t * r.l;
    const double y = y0 + t * r.m;
    double sag = 0.0;
    double slope = 0.0;
    if (!asphere_sag(g, x * x + y * y, sag, slope)) break;
    const double value = z0 + t * r.n - sag;
    const double derivative = r.n - 2.0 * slope * (x * r.l + y * r.m);
    const double step = value / derivative;
    if (!std::isfinite(step)) break;
    t -= step;
    // Newton's error after a step e_k is about K e_k^2 with K = |step_k| / step_(k-1)^2 once convergence is
    // quadratic: stop when that predicted error, with a safety factor for an estimate taken before the
    // asymptotic regime, is below the tolerance. This saves the last, confirming iteration (a quarter of the
    // cost of an aspheric surface).
    const double size = std::abs(step);
    const bool quadratic = previous_step != 0.0 && size < 1e-3 * std::abs(previous_step);
    if (size <= kAsphereStepTolerance_mm ||
        (quadratic && kNewtonSafety * size / (previous_step * previous_step) * size * size <= kAsphereStepTolerance_mm)) {
      converged = true;
      break;
    }
    previous_step = step;
  }
  RayStatus status = RayStatus::Ok;
  if (!(converged && finish_asphere(g, x0, y0, r.l, r.m, r.n, sense, t, true, hit))) {
    status = bracket_asphere(g, x0, y0, z0, r.l, r.m, r.n, sense, hit);
  }
  hit.t += t_start;
  return status;
}

inline RayStatus intersect(const SurfaceGeometry& g, const State& r, double sense, Hit& hit) {
  switch (g.shape) {
    case Shape::Plane: {
      // The vertex plane: crossing it in the direction of travel needs sense * n > 0.
      if (!(sense * r.n > 0.0)) return RayStatus::Missed;
      hit.t = (g.z_vertex_mm - r.z) / r.n;
      hit.nx = 0.0;
      hit.ny = 0.0;
      hit.nz = 1.0;
      hit.cos_i = r.n;
      hit.cos_i_squared = r.n * r.n;
      return RayStatus::Ok;
    }
    case Shape::Sphere:
    case Shape::Conic: {
      const double z0 = r.z - g.z_vertex_mm;
      const double b = conic_b(g.curvature_per_mm, g.one_plus_conic, r.x, r.y, z0, r.l, r.m, r.n);
      return intersect_conic(g.curvature_per_mm, g.one_plus_conic, r.x, r.y, z0, r.l, r.m, r.n, b, sense, hit)
                 ? RayStatus::Ok
                 : RayStatus::Missed;
    }
    case Shape::Asphere:
      return intersect_asphere(g, r, sense, hit);
    case Shape::General:
      return RayStatus::Missed;  // intersect_general (needs the Surface)
    case Shape::Cylinder:
      return RayStatus::Missed;  // intersect_cylinder (general path)
  }
  return RayStatus::Missed;
}

// A cylinder c u^2 + (1 + k) c z^2 - 2 z = 0 (u = x or y, the other coordinate free), vertex at the origin: with
// p = p0 + t d, A t^2 + 2 B t + C = 0, A = c (du^2 + (1 + k) n^2), B = c (u0 du + (1 + k) z0 n) - n,
// C = c (u0^2 + (1 + k) z0^2) - 2 z0. Of the two roots the one on the vertex sheet (N_z = 1 - (1 + k) c z >= 0)
// that the ray crosses in its direction of travel (sense N.d > 0), as for the conics above.
RayStatus intersect_cylinder(const SurfaceGeometry& g, const State& r, double sense, Hit& hit) {
  const double c = g.curvature_per_mm, q = g.one_plus_conic;
  const double u0 = g.cylinder_in_x ? r.x : r.y, du = g.cylinder_in_x ? r.l : r.m;
  const double a = c * (du * du + q * r.n * r.n);
  const double b = c * (u0 * du + q * r.z * r.n) - r.n;
  const double cc = c * (u0 * u0 + q * r.z * r.z) - 2.0 * r.z;
  std::array<double, 2> roots{};
  int count = 0;
  if (a == 0.0) {
    if (b == 0.0) return RayStatus::Missed;
    roots[count++] = -cc / (2.0 * b);
  } else {
    const double discriminant = b * b - a * cc;
    if (!(discriminant >= 0.0)) return RayStatus::Missed;
    const double root = std::sqrt(discriminant);
    // Cancellation-free: q = -(b + sign(b) root), roots q / a and cc / q.
    const double qq = -(b + (b >= 0.0 ? root : -root));
    roots[count++] = qq / a;
    if (qq != 0.0) roots[count++] = cc / qq;
  }
  for (int i = 0; i < count; ++i) {
    const double t = roots[static_cast<std::size_t>(i)];
    if (!std::isfinite(t)) continue;
    const double u = u0 + t * du, z = r.z + t * r.n;
    const double nz = 1.0 - q * c * z;
    if (nz < -kSheetTolerance) continue;
    const double nu = -c * u;
    const double inverse_length = 1.0 / std::sqrt(nu * nu + nz * nz);
    const double nx = g.cylinder_in_x ? nu * inverse_length : 0.0, ny = g.cylinder_in_x ? 0.0 : nu * inverse_length;
    const double cos_i = nx * r.l + ny * r.m + nz * inverse_length * r.n;
    if (!(sense * cos_i > 0.0)) continue;
    hit.t = t;
    hit.nx = nx;
    hit.ny = ny;
    hit.nz = nz * inverse_length;
    hit.cos_i = cos_i;
    hit.cos_i_squared = cos_i * cos_i;
    return RayStatus::Ok;
  }
  return RayStatus::Missed;
}

// Newton's method on the ray's height above a shape given by Surface::sag_and_slope (a toroid or biconic),
// vertex at the local origin: G(t) = z(t) - sag(x(t), y(t)), G'(t) = n - sag_x l - sag_y m, from the vertex
// plane's crossing; where Newton fails, the sign change of G nearest that start (samples spaced geometrically
// either side) refined by bisection. The crossing must go in the direction of travel (`sense` N.d > 0).
RayStatus intersect_general(const Surface& shape, const State& r, double sense, Hit& hit) {
  auto height = [&](double t, double& value, double& derivative, double& sx, double& sy) {
    const double x = r.x + t * r.l, y = r.y + t * r.m;
    double sag = 0.0;
    if (!shape.sag_and_slope(x, y, sag, sx, sy)) return false;
    value = r.z + t * r.n - sag;
    derivative = r.n - sx * r.l - sy * r.m;
    return std::isfinite(value);
  };
  double t = r.n != 0.0 ? -r.z / r.n : 0.0;
  double value = 0.0, derivative = 0.0, sx = 0.0, sy = 0.0;
  bool converged = false;
  for (int iteration = 0; iteration < kMaxNewtonIterations; ++iteration) {
    if (!height(t, value, derivative, sx, sy) || derivative == 0.0) break;
    const double step = value / derivative;
    if (!std::isfinite(step)) break;
    t -= step;
    if (std::abs(step) <= kAsphereStepTolerance_mm) {
      converged = height(t, value, derivative, sx, sy);
      break;
    }
  }
  auto finish = [&](double at) {
    double v = 0.0, d = 0.0, gx = 0.0, gy = 0.0;
    if (!height(at, v, d, gx, gy)) return false;
    const double inverse_length = 1.0 / std::sqrt(gx * gx + gy * gy + 1.0);
    hit.t = at;
    hit.nx = -gx * inverse_length;
    hit.ny = -gy * inverse_length;
    hit.nz = inverse_length;
    hit.cos_i = hit.nx * r.l + hit.ny * r.m + hit.nz * r.n;
    hit.cos_i_squared = hit.cos_i * hit.cos_i;
    return sense * hit.cos_i > 0.0;
  };
  if (converged && finish(t)) return RayStatus::Ok;
  // Fallback: samples either side of the start; the change of sense G from < 0 (before the surface) to >= 0
  // (after it) along +t nearest the start, refined by bisection.
  const double start = r.n != 0.0 ? -r.z / r.n : 0.0;
  constexpr int kSamples = 2 * kBracketDoublings + 1;
  std::array<double, kSamples> ts{};
  std::array<double, kSamples> gs{};
  std::array<bool, kSamples> valid{};
  ts[0] = start;
  for (int j = 0; j < kBracketDoublings; ++j) {
    ts[static_cast<std::size_t>(2 * j + 1)] = start - std::ldexp(kBracketFirstStep_mm, j);
    ts[static_cast<std::size_t>(2 * j + 2)] = start + std::ldexp(kBracketFirstStep_mm, j);
  }
  std::sort(ts.begin(), ts.end());
  for (std::size_t i = 0; i < ts.size(); ++i) {
    double d = 0.0;
    valid[i] = height(ts[i], gs[i], d, sx, sy);
    gs[i] *= sense;
  }
  double best_a = 0.0, best_b = 0.0, best_distance = kInfinity;
  for (std::size_t i = 0; i + 1 < ts.size(); ++i) {
    if (valid[i] && valid[i + 1] && gs[i] < 0.0 && gs[i + 1] >= 0.0) {
      const double distance = std::min(std::abs(ts[i] - start), std::abs(ts[i + 1] - start));
      if (distance < best_distance) {
        best_distance = distance;
        best_a = ts[i];
        best_b = ts[i + 1];
      }
    }
  }
  if (!(best_distance < kInfinity)) return RayStatus::Missed;
  for (int iteration = 0; iteration < kMaxFalsiIterations && best_b - best_a > kAsphereStepTolerance_mm; ++iteration) {
    const double mid = 0.5 * (best_a + best_b);
    double g = 0.0, d = 0.0;
    if (!height(mid, g, d, sx, sy)) return RayStatus::NotConverged;
    (sense * g < 0.0 ? best_a : best_b) = mid;
  }
  return finish(0.5 * (best_a + best_b)) ? RayStatus::Ok : RayStatus::NotConverged;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
namespace trace_detail {

// A surface's frame, and whether it is only moved along the global z axis (coaxial mirror systems, the
// surfaces between breaks that turn nothing): such a frame is entered by a subtraction, decided once here
// rather than per ray.
struct PlacedFrame {
  SurfaceFrame frame;
  bool along_z_only = true;

  PlacedFrame() = default;
  explicit PlacedFrame(const SurfaceFrame& f)
      : frame(f), along_z_only(f.origin_mm.x() == 0.0 && f.origin_mm.y() == 0.0 && f.axes.isIdentity(0.0)) {}
};

// Shared, immutable after construction except for the wavelength cache, which is thread-safe.
struct TracerCore {
  // Open-addressing table of wavelengths (keyed by their bit pattern) published with release stores,
  // so readers never lock: a reader either sees a complete row or an empty slot. Rows are only ever
  // added, under a mutex, into storage reserved at construction (no allocation after it).
  static constexpr std::size_t kSlots = 512;       // power of two, >= 2 x kMaxEntries
  static constexpr std::size_t kMaxEntries = 192;  // a 64-sample spectrum plus the lens's own wavelengths, 2x over

  std::vector<SurfaceGeometry> surfaces;
  std::vector<Glass> media;  // [0] object space, [k] after surface k
  double image_plane_z_mm = 0.0;
  // The general path (docs/trace.md, "Mirrors, coordinate breaks, toroids"): surfaces in their own frames
  // (vertex at the local origin, SurfaceGeometry::z_vertex_mm 0), the shapes Surface knows, the image plane's
  // frame and the direction light reaches it (+1: toward its +z).
  bool general = false;
  std::vector<PlacedFrame> frames;
  std::vector<Surface> shapes;
  PlacedFrame image_frame;
  double image_sense = 1.0;

  // Row layout for N surfaces: n_0..n_N, then mu_forward_k = n_(k-1) / n_k and mu_backward_k = n_k / n_(k-1)
  // for k = 1..N, so the loop does no division for the index ratio.
  std::size_t stride = 0;
  mutable std::vector<double> rows;  // kMaxEntries x stride, reserved at construction; rows are written once
  mutable std::array<std::atomic<std::uint64_t>, kSlots> keys{};  // 0 = empty (no valid wavelength has bits 0)
  mutable std::array<std::uint32_t, kSlots> row_of_slot{};
  mutable std::atomic<std::size_t> entries{0};
  mutable std::mutex insert_mutex;

  std::size_t count() const { return surfaces.size(); }
  std::size_t mu_forward_offset() const { return count() + 1; }
  std::size_t mu_backward_offset() const { return 2 * count() + 1; }

  static std::size_t hash(std::uint64_t bits) {
    // Fibonacci hashing: the high bits of the product spread neighbouring wavelengths over the table.
    return static_cast<std::size_t>((bits * 0x9E3779B97F4A7C15ULL) >> 55) & (kSlots - 1);
  }

  // The index row for a wavelength (> 0, finite), or nullptr when the table is full (the caller then
  // evaluates Glass::index per surface).
  const double* indices(double wavelength_nm) const noexcept {
    const std::uint64_t bits = std::bit_cast<std::uint64_t>(wavelength_nm);
    std::size_t slot = hash(bits);
    for (std::size_t probe = 0; probe < kSlots; ++probe) {
      const std::uint64_t key = keys[slot].load(std::memory_order_acquire);
      if (key == bits) return rows.data() + row_of_slot[slot] * stride;
      if (key == 0) break;
      slot = (slot + 1) & (kSlots - 1);
    }
    return insert(wavelength_nm, bits);
  }

  const double* insert(double wavelength_nm, std::uint64_t bits) const noexcept {
    if (entries.load(std::memory_order_relaxed) >= kMaxEntries) return nullptr;
    std::lock_guard<std::mutex> lock(insert_mutex);
    std::size_t slot = hash(bits);
    for (std::size_t probe = 0; probe < kSlots; ++probe) {
      const std::uint64_t key = keys[slot].load(std::memory_order_acquire);
      if (key == bits) return rows.data() + row_of_slot[slot] * stride;  // another thread added it
      if (key == 0) break;
      slot = (slot + 1) & (kSlots - 1);
    }
    const std::size_t row = entries.load(std::memory_order_relaxed);
    if (row >= kMaxEntries) return nullptr;
    double* out = rows.data() + row * stride;
    fill_row(wavelength_nm, out);
    row_of_slot[slot] = static_cast<std::uint32_t>(row);
    keys[slot].store(bits, std::memory_order_release);
    entries.store(row + 1, std::memory_order_relaxed);
    return out;
  }

  void fill_row(double wavelength_nm, double* out) const noexcept {
    const std::size_t n = count();
    for (std::size_t k = 0; k <= n; ++k) out[k] = media[k].index(wavelength_nm);
    for (std::size_t k = 1; k <= n; ++k) {
      out[mu_forward_offset() + k - 1] = out[k - 1] / out[k];
      out[mu_backward_offset() + k - 1] = out[k] / out[k - 1];
    }
  }
};

}  // namespace trace_detail

struct SequentialTracer::Impl : trace_detail::TracerCore {};

namespace {

using Core = trace_detail::TracerCore;
using trace_detail::PlacedFrame;

// A ray on its way through the lens: its state, the index row of its wavelength (nullptr: evaluate the
// glasses), the index of the medium it is in, and the next conic's B carried over the last refraction.
struct Walker {
  State r;
  const double* table;
  double wavelength_nm;
  double n_current;
  double next_b;
  bool carried_b;
};

// `first_step`: where a forward walk through part of the lens begins (it starts in medium first_step).
template <bool kForward>
inline Walker start_walk(const Core& impl, const State& r, double wavelength_nm, const double* table, int first_step = 0) {
  const std::size_t start_medium = kForward ? static_cast<std::size_t>(first_step) : impl.count();
  return Walker{r, table, wavelength_nm,
                table ? table[start_medium] : impl.media[start_medium].index(wavelength_nm), 0.0, false};
}

// One surface crossing, step 0..count-1 in the order of travel (kForward: first -> last). Returns Ok, or why
// the ray died at this surface (then w.r is the ray as it arrived: on the surface for Vignetted and TIR,
// before it for Missed and NotConverged). kRecord appends a SurfaceHit to `path`.
// Always inlined: the single-ray driver and the interleaved batch driver below run the same operations in
// the same order and so agree bit for bit.
template <bool kForward, bool kRecord>
[[gnu::always_inline]] inline RayStatus cross_surface(const Core& impl, int step, Walker& w,
                                                      std::vector<SurfaceHit>* path) {
  const int count = static_cast<int>(impl.count());
  const double sense = kForward ? 1.0 : -1.0;
  const int k = kForward ? step : count - 1 - step;  // 0-based surface
  const SurfaceGeometry& g = impl.surfaces[static_cast<std::size_t>(k)];
  State& r = w.r;
  Hit hit{};
  RayStatus status = RayStatus::Ok;
  if (g.shape == Shape::Sphere || g.shape == Shape::Conic) {
    const double z0 = r.z - g.z_vertex_mm;
    const double b = w.carried_b ? w.next_b : conic_b(g.curvature_per_mm, g.one_plus_conic, r.x, r.y, z0, r.l, r.m, r.n);
    if (!intersect_conic(g.curvature_per_mm, g.one_plus_conic, r.x, r.y, z0, r.l, r.m, r.n, b, sense, hit)) {
      status = RayStatus::Missed;
    }
  } else {
    status = intersect(g, r, sense, hit);
  }
  if (status != RayStatus::Ok) return status;
  r.x += hit.t * r.l;
  r.y += hit.t * r.m;
  r.z += hit.t * r.n;
  r.opl += w.n_current * hit.t;
  auto record = [&]() {
    if constexpr (kRecord) {
      path->push_back(SurfaceHit{k + 1, Eigen::Vector3d(r.x, r.y, r.z), Eigen::Vector3d(r.l, r.m, r.n),
                                 Eigen::Vector3d(hit.nx, hit.ny, hit.nz), r.opl});
    }
  };
  if (r.x * r.x + r.y * r.y > g.clip_radius2_mm2 ||
      (g.has_aperture && !g.aperture.passes(r.x, r.y, g.aperture_tolerance_mm))) {
    record();
    return RayStatus::Vignetted;
  }

  // Index after the crossing: medium k + 1 going forward, medium k going backward.
  const std::size_t next_medium = kForward ? static_cast<std::size_t>(k) + 1 : static_cast<std::size_t>(k);
  double n_next = 0.0;
  double mu = 0.0;
  if (w.table) {
    n_next = w.table[next_medium];
    mu = w.table[(kForward ? impl.mu_forward_offset() : impl.mu_backward_offset()) + static_cast<std::size_t>(k)];
  } else {
    n_next = impl.media[next_medium].index(w.wavelength_nm);
    mu = w.n_current / n_next;
  }
  // Vector Snell (Welford ch. 4; Spencer & Murty): n' (d' x N) = n (d x N) gives d' = mu d + gamma N with mu = n / n',
  // gamma = sigma cos I' - mu cos I, cos^2 I' = 1 - mu^2 (1 - cos^2 I) = (1 - mu^2) + mu^2 cos^2 I and
  // sigma = sign(cos I), which keeps d' on the far side whichever way N points. mu = 1 leaves d unchanged.
  double gamma = 0.0;
  if (mu != 1.0) {
    const double mu2 = mu * mu;
    const double radicand = (1.0 - mu2) + mu2 * hit.cos_i_squared;
    if (radicand < 0.0) {
      record();
      return RayStatus::TotalInternalReflection;
    }
    const double cos_r = std::sqrt(radicand);
    gamma = (hit.cos_i >= 0.0 ? cos_r : -cos_r) - mu * hit.cos_i;
  }

  // The next conic's B = d'.W is linear in the direction, so B = mu (d.W) + gamma (N.W): both dot products
  // depend only on the point, and B is ready one multiply-add after gamma instead of after d'.
  w.carried_b = false;
  if (step + 1 < count) {
    const SurfaceGeometry& next = impl.surfaces[static_cast<std::size_t>(kForward ? k + 1 : k - 1)];
    if (next.shape == Shape::Sphere || next.shape == Shape::Conic) {
      const double c = next.curvature_per_mm;
      const double wx = -c * r.x;
      const double wy = -c * r.y;
      const double wz = 1.0 - next.one_plus_conic * c * (r.z - next.z_vertex_mm);
      const double d_dot_w = r.l * wx + r.m * wy + r.n * wz;
      w.next_b = mu != 1.0 ? mu * d_dot_w + gamma * (hit.nx * wx + hit.ny * wy + hit.nz * wz) : d_dot_w;
      w.carried_b = true;
    }
  }
  if (mu != 1.0) {
    r.l = mu * r.l + gamma * hit.nx;
    r.m = mu * r.m + gamma * hit.ny;
    r.n = mu * r.n + gamma * hit.nz;
  }
  w.n_current = n_next;
  record();
  return RayStatus::Ok;
}

// Forward only: from the last surface to the image plane (Missed when the ray no longer travels +z).
[[gnu::always_inline]] inline RayStatus to_image_plane(const Core& impl, Walker& w) {
  State& r = w.r;
  if (!(r.n > 0.0)) return RayStatus::Missed;
  const double t = (impl.image_plane_z_mm - r.z) / r.n;
  r.x += t * r.l;
  r.y += t * r.m;
  r.z = impl.image_plane_z_mm;
  r.opl += w.n_current * t;
  return RayStatus::Ok;
}

// The 1-based surface where a ray died at `step` (count + 1: the image plane).
template <bool kForward>
inline int surface_of_step(const Core& impl, int step) {
  const int count = static_cast<int>(impl.count());
  if (step >= count) return count + 1;
  return kForward ? step + 1 : count - step;
}

// Which surfaces a forward trace crosses: steps [first, end) (0-based surfaces); end < 0: every
// surface. Only a trace through the last surface goes on to the image plane.
struct StepRange {
  int first = 0;
  int end = -1;
};

// The single-ray driver. Returns the status and sets `surface` (0 when Ok); `r` ends as TraceResult::ray.
template <bool kForward, bool kRecord>
RayStatus propagate(const Core& impl, State& r, double wavelength_nm, const double* table, int& surface,
                    std::vector<SurfaceHit>* path, StepRange range = {}) {
  Walker w = start_walk<kForward>(impl, r, wavelength_nm, table, range.first);
  const int count = static_cast<int>(impl.count());
  const int end = range.end < 0 ? count : range.end;
  RayStatus status = RayStatus::Ok;
  int step = range.first;
  for (; step < end && status == RayStatus::Ok; ++step) {
    status = cross_surface<kForward, kRecord>(impl, step, w, path);
  }
  if (status == RayStatus::Ok && end == count) {
    if constexpr (kForward) status = to_image_plane(impl, w);
    step = count + 1;
  }
  surface = status == RayStatus::Ok ? 0 : surface_of_step<kForward>(impl, step - 1);
  r = w.r;
  return status;
}

// ---- The general path: mirrors, coordinate breaks, toroids and biconics --------------------------------
// Each surface is met in its own frame: the ray is carried into it, intersected there (the side it comes
// from is the sign of its local z direction, so a ray that a mirror or a tilt sends back meets the next
// surface from behind as it should), clipped in the local x-y plane, refracted (vector Snell, as above) or
// reflected (d' = d - 2 (d.N) N), and carried back. Coordinate breaks do not touch the ray. Forward rays end
// on the image plane in the image frame (x, y as there; z = image_plane_z_mm, travelling +z: after an odd
// number of reflections the frame's z is reversed, so that every analysis sees light going +z).

inline void to_frame(const PlacedFrame& placed, State& r) {
  const SurfaceFrame& f = placed.frame;
  if (placed.along_z_only) {
    r.z -= f.origin_mm.z();
    return;
  }
  const Eigen::Vector3d p = f.to_local(Eigen::Vector3d(r.x, r.y, r.z));
  const Eigen::Vector3d d = f.axes.transpose() * Eigen::Vector3d(r.l, r.m, r.n);
  r.x = p.x(); r.y = p.y(); r.z = p.z();
  r.l = d.x(); r.m = d.y(); r.n = d.z();
}

inline void from_frame(const PlacedFrame& placed, State& r) {
  const SurfaceFrame& f = placed.frame;
  if (placed.along_z_only) {
    r.z += f.origin_mm.z();
    return;
  }
  const Eigen::Vector3d p = f.to_global(Eigen::Vector3d(r.x, r.y, r.z));
  const Eigen::Vector3d d = f.axes * Eigen::Vector3d(r.l, r.m, r.n);
  r.x = p.x(); r.y = p.y(); r.z = p.z();
  r.l = d.x(); r.m = d.y(); r.n = d.z();
}

template <bool kForward, bool kRecord>
RayStatus propagate_general(const Core& impl, State& r, double wavelength_nm, const double* table, int& surface,
                            std::vector<SurfaceHit>* path, bool clip = true, StepRange range = {}) {
  const int count = static_cast<int>(impl.count());
  const int end = range.end < 0 ? count : range.end;
  auto index_of = [&](std::size_t medium) { return table ? table[medium] : impl.media[medium].index(wavelength_nm); };
  if constexpr (!kForward) {
    // From the image plane's output frame (z reversed when light arrives toward -z) into global coordinates.
    r.z = impl.image_sense * (r.z - impl.image_plane_z_mm);
    r.n *= impl.image_sense;
    from_frame(impl.image_frame, r);
  }
  double n_current = index_of(kForward ? static_cast<std::size_t>(range.first) : impl.count());
  for (int step = range.first; step < end; ++step) {
    const int k = kForward ? step : count - 1 - step;
    const SurfaceGeometry& g = impl.surfaces[static_cast<std::size_t>(k)];
    const PlacedFrame& frame = impl.frames[static_cast<std::size_t>(k)];
    if (g.is_break) {
      // The ray moves (virtually where need be) to the break's x-y plane, as OpticStudio traces it: the next
      // surface's intersection starts from any point of the line, and the listing shows it there.
      State local = r;
      to_frame(frame, local);
      if (local.n != 0.0) {
        const double t = -local.z / local.n;
        local.x += t * local.l;
        local.y += t * local.m;
        local.z = 0.0;
        local.opl += n_current * t;
        r = local;
        from_frame(frame, r);
      }
      if constexpr (kRecord) {
        path->push_back(SurfaceHit{k + 1, Eigen::Vector3d(r.x, r.y, r.z), Eigen::Vector3d(r.l, r.m, r.n), frame.frame.axes.col(2), r.opl});
      }
      continue;
    }
    State local = r;
    to_frame(frame, local);
    const double sense = local.n > 0.0 ? 1.0 : -1.0;
    Hit hit{};
    RayStatus status = RayStatus::Ok;
    if (local.n == 0.0 && g.shape == Shape::Plane) {
      status = RayStatus::Missed;
    } else if (g.shape == Shape::General) {
      status = intersect_general(impl.shapes[static_cast<std::size_t>(k)], local, sense, hit);
    } else if (g.shape == Shape::Cylinder) {
      status = intersect_cylinder(g, local, sense, hit);
    } else {
      status = intersect(g, local, sense, hit);
    }
    if (status != RayStatus::Ok) {
      surface = k + 1;
      return status;
    }
    local.x += hit.t * local.l;
    local.y += hit.t * local.m;
    local.z += hit.t * local.n;
    local.opl += n_current * hit.t;
    auto record = [&]() {
      if constexpr (kRecord) {
        State global = local;
        from_frame(frame, global);
        path->push_back(SurfaceHit{k + 1, Eigen::Vector3d(global.x, global.y, global.z), Eigen::Vector3d(global.l, global.m, global.n),
                                   frame.frame.axes * Eigen::Vector3d(hit.nx, hit.ny, hit.nz), global.opl});
      }
    };
    if (clip && (local.x * local.x + local.y * local.y > g.clip_radius2_mm2 ||
                 (g.has_aperture && !g.aperture.passes(local.x, local.y, g.aperture_tolerance_mm)))) {
      record();
      r = local;
      from_frame(frame, r);
      surface = k + 1;
      return RayStatus::Vignetted;
    }
    const double n_next = index_of(kForward ? static_cast<std::size_t>(k) + 1 : static_cast<std::size_t>(k));
    if (g.mirror) {
      const double twice = 2.0 * hit.cos_i;
      local.l -= twice * hit.nx;
      local.m -= twice * hit.ny;
      local.n -= twice * hit.nz;
    } else if (n_next != n_current) {
      const double mu = n_current / n_next;
      const double mu2 = mu * mu;
      const double radicand = (1.0 - mu2) + mu2 * hit.cos_i_squared;
      if (radicand < 0.0) {
        record();
        r = local;
        from_frame(frame, r);
        surface = k + 1;
        return RayStatus::TotalInternalReflection;
      }
      const double cos_r = std::sqrt(radicand);
      const double gamma = (hit.cos_i >= 0.0 ? cos_r : -cos_r) - mu * hit.cos_i;
      local.l = mu * local.l + gamma * hit.nx;
      local.m = mu * local.m + gamma * hit.ny;
      local.n = mu * local.n + gamma * hit.nz;
    }
    n_current = n_next;
    record();
    r = local;
    from_frame(frame, r);
  }
  if constexpr (kForward) {
    if (end < count) {
      surface = 0;
      return RayStatus::Ok;
    }
    State local = r;
    to_frame(impl.image_frame, local);
    if (!(local.n * impl.image_sense > 0.0)) {
      surface = count + 1;
      return RayStatus::Missed;
    }
    const double t = -local.z / local.n;
    local.x += t * local.l;
    local.y += t * local.m;
    local.opl += n_current * t;
    r = State{local.x, local.y, impl.image_plane_z_mm, local.l, local.m, impl.image_sense * local.n, local.opl};
  }
  surface = 0;
  return RayStatus::Ok;
}

// Loads a ray into the loop state; false for NaN/infinite values, a zero direction or a wavelength
// that is not > 0. A direction that is not unit length is normalised.
inline bool load(double x, double y, double z, double l, double m, double n, double wavelength_nm, State& s) {
  if (!(std::isfinite(x) && std::isfinite(y) && std::isfinite(z) && std::isfinite(l) && std::isfinite(m) &&
        std::isfinite(n) && std::isfinite(wavelength_nm) && wavelength_nm > 0.0)) {
    return false;
  }
  const double length2 = l * l + m * m + n * n;
  if (!(length2 > 0.0)) return false;
  s = State{x, y, z, l, m, n, 0.0};
  if (std::abs(length2 - 1.0) > kUnitTolerance) {
    const double inverse = 1.0 / std::sqrt(length2);
    s.l *= inverse;
    s.m *= inverse;
    s.n *= inverse;
  }
  return true;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
void TracerOptions::validate() const {
  if (image_distance_mm && !std::isfinite(*image_distance_mm)) {
    throw OptionsError("TracerOptions::image_distance_mm = " + format_number(*image_distance_mm) + ": must be finite");
  }
}

std::string TraceResult::to_string() const {
  std::ostringstream os;
  os.precision(17);
  os << lensmith::to_string(status);
  if (status != RayStatus::Ok) os << " at surface " << surface;
  os << ": " << ray.to_string() << ", optical path " << optical_path_mm << " mm";
  return os.str();
}

void RayBatch::resize(std::size_t count) {
  x_mm.resize(count);
  y_mm.resize(count);
  z_mm.resize(count);
  l.resize(count);
  m.resize(count);
  n.resize(count);
  wavelength_nm.resize(count);
  status.resize(count);
  surface.resize(count);
}

void RayBatch::set(std::size_t i, const Ray& ray) {
  x_mm.at(i) = ray.position_mm.x();
  y_mm.at(i) = ray.position_mm.y();
  z_mm.at(i) = ray.position_mm.z();
  l.at(i) = ray.direction.x();
  m.at(i) = ray.direction.y();
  n.at(i) = ray.direction.z();
  wavelength_nm.at(i) = ray.wavelength_nm;
  status.at(i) = RayStatus::Ok;
  surface.at(i) = 0;
}

Ray RayBatch::get(std::size_t i) const {
  Ray ray;
  ray.position_mm = Eigen::Vector3d(x_mm.at(i), y_mm.at(i), z_mm.at(i));
  ray.direction = Eigen::Vector3d(l.at(i), m.at(i), n.at(i));
  ray.wavelength_nm = wavelength_nm.at(i);
  return ray;
}

// ---------------------------------------------------------------------------------------------
SequentialTracer::SequentialTracer(const Prescription& lens, const TracerOptions& options)
    : lens_(lens), options_(options) {
  options_.validate();
  lens_.validate();
  const std::size_t count = lens_.surfaces.size();

  vertex_z_mm_.resize(count);
  for (std::size_t k = 0; k < count; ++k) vertex_z_mm_[k] = lens_.vertex_z_mm(k);

  double image_distance_mm = 0.0;
  if (options_.image_distance_mm) {
    image_distance_mm = *options_.image_distance_mm;
  } else if (options_.image_plane == TracerOptions::ImagePlane::ParaxialFocus || lens_.image_at_paraxial_focus) {
    // Paraxial image of the prescription's object plane at the primary wavelength (throws for an afocal lens).
    image_distance_mm = ParaxialSystem(lens_).image_distance_mm();
  } else {
    image_distance_mm = lens_.surfaces.back().thickness_mm;
  }
  image_plane_z_mm_ = vertex_z_mm_.back() + image_distance_mm;

  auto impl = std::make_shared<Impl>();
  impl->general = lens_.has_mirrors() || std::any_of(lens_.surfaces.begin(), lens_.surfaces.end(), [](const Surface& s) {
                    return s.kind != SurfaceKind::Standard;
                  });
  if (impl->general) {
    const LensFrames frames = surface_frames(lens_, image_distance_mm);
    for (const SurfaceFrame& f : frames.surfaces) impl->frames.emplace_back(f);
    impl->image_frame = trace_detail::PlacedFrame(frames.image);
    impl->shapes = lens_.surfaces;
    // The output z of the image plane stays the sum of the thicknesses (where it lies in a coaxial system,
    // so that with an even number of mirrors the output frame is the global frame); light reaches it toward
    // +z or -z of its frame as the number of reflections says (a probe below corrects that for tilted planes).
    impl->image_sense = lens_.mirror_count() % 2 == 0 ? 1.0 : -1.0;
  }
  impl->image_plane_z_mm = image_plane_z_mm_;
  impl->media.reserve(count + 1);
  impl->media.push_back(lens_.object_medium);
  for (const Surface& s : lens_.surfaces) impl->media.push_back(s.medium);
  impl->surfaces.resize(count);
  for (std::size_t k = 0; k < count; ++k) {
    const Surface& s = lens_.surfaces[k];
    SurfaceGeometry& g = impl->surfaces[k];
    g.z_vertex_mm = vertex_z_mm_[k];
    g.curvature_per_mm = s.curvature_per_mm;
    g.one_plus_conic = 1.0 + s.conic;
    g.asphere = s.even_asphere;
    g.asphere_terms = 0;
    for (std::size_t j = 0; j < s.even_asphere.size(); ++j) {
      if (s.even_asphere[j] != 0.0) g.asphere_terms = static_cast<int>(j) + 1;
    }
    g.is_break = s.is_coordinate_break();
    g.mirror = s.mirror;
    if (impl->general) g.z_vertex_mm = 0.0;  // the frames place the surfaces
    // A cylinder: a biconic with one flat section, or a toroid without y terms swept along x (infinite radius of
    // rotation); otherwise the general Newton intersection.
    const bool biconic_cylinder = s.kind == SurfaceKind::Biconic && ((s.curvature_per_mm == 0.0) != (s.curvature_x_per_mm == 0.0));
    const bool toroid_cylinder = s.kind == SurfaceKind::Toroidal && s.curvature_x_per_mm == 0.0 && !s.has_asphere() && s.curvature_per_mm != 0.0;
    if (biconic_cylinder || toroid_cylinder) {
      g.shape = Shape::Cylinder;
      g.cylinder_in_x = s.curvature_per_mm == 0.0;
      g.curvature_per_mm = g.cylinder_in_x ? s.curvature_x_per_mm : s.curvature_per_mm;
      g.one_plus_conic = 1.0 + (g.cylinder_in_x ? s.conic_x : s.conic);
    } else if (s.kind == SurfaceKind::Toroidal || s.kind == SurfaceKind::Biconic) {
      g.shape = Shape::General;
    } else if (g.is_break) {
      g.shape = Shape::Plane;
    } else if (g.asphere_terms > 0) {
      g.shape = Shape::Asphere;
    } else if (s.curvature_per_mm == 0.0) {
      g.shape = Shape::Plane;  // the conic constant of a plane changes nothing
    } else {
      g.shape = s.conic == 0.0 ? Shape::Sphere : Shape::Conic;
    }
    // What clips (docs/lens-format.md, "Apertures"): an explicit aperture where the surface has one,
    // else the semi-diameter where it is a clear aperture (clips_rays), with the rim tolerance above.
    if (options_.clip_apertures && s.aperture) {
      g.has_aperture = true;
      g.aperture = *s.aperture;
      g.aperture_tolerance_mm = kClipRelativeTolerance * std::max(s.aperture->half_x_mm, s.aperture->half_y_mm);
    } else if (options_.clip_apertures && s.semi_diameter_mm && s.clips_rays) {
      const double limit = *s.semi_diameter_mm * (1.0 + kClipRelativeTolerance);
      g.clip_radius2_mm2 = limit * limit;
    }
  }
  impl->stride = 3 * count + 1;
  impl->rows.assign(Core::kMaxEntries * impl->stride, 0.0);
  // The prescription's wavelengths are the common case: put them in the table now.
  for (double w : lens_.wavelengths_nm) impl->indices(w);
  if (impl->general) {
    // Which way light reaches the image plane: that of a ray along the object-space axis (from the front of
    // surface 1, apertures ignored), where it gets there; the count of reflections otherwise.
    auto reaches_image = [&]() {
      State probe{0.0, 0.0, -1.0, 0.0, 0.0, 1.0, 0.0};
      int died = 0;
      const double w = lens_.primary_wavelength_nm();
      const RayStatus st = propagate_general<true, false>(*impl, probe, w, impl->indices(w), died, nullptr, false);
      return st == RayStatus::Ok || died != static_cast<int>(count) + 1;
    };
    const double parity = impl->image_sense;
    if (!reaches_image()) {
      impl->image_sense = -parity;
      if (!reaches_image()) impl->image_sense = parity;
    }
  }
  impl_ = std::move(impl);
}

double SequentialTracer::vertex_z_mm(int surface) const {
  if (surface < 1 || surface > static_cast<int>(vertex_z_mm_.size())) {
    throw std::out_of_range("SequentialTracer::vertex_z_mm: surface " + std::to_string(surface) + " is not in 1.." +
                            std::to_string(vertex_z_mm_.size()));
  }
  return vertex_z_mm_[static_cast<std::size_t>(surface) - 1];
}

SurfaceFrame SequentialTracer::surface_frame(int surface) const {
  const double z = vertex_z_mm(surface);  // checks the range
  if (impl_->general) return impl_->frames[static_cast<std::size_t>(surface) - 1].frame;
  SurfaceFrame f;
  f.origin_mm = Eigen::Vector3d(0.0, 0.0, z);
  return f;
}

Eigen::Vector3d SequentialTracer::image_point_in_global_frame(const Eigen::Vector3d& p) const {
  if (!impl_->general) return p;
  return impl_->image_frame.frame.to_global(Eigen::Vector3d(p.x(), p.y(), impl_->image_sense * (p.z() - impl_->image_plane_z_mm)));
}

double SequentialTracer::index_after(int surface, double wavelength_nm) const {
  if (surface < 0 || surface > static_cast<int>(vertex_z_mm_.size())) {
    throw std::out_of_range("SequentialTracer::index_after: surface " + std::to_string(surface) + " is not in 0.." +
                            std::to_string(vertex_z_mm_.size()));
  }
  return impl_->media[static_cast<std::size_t>(surface)].index(wavelength_nm);
}

namespace {

template <bool kForward>
TraceResult trace_one(const Core& impl, const Ray& ray, std::vector<SurfaceHit>* path, StepRange range = {}) {
  TraceResult result;
  result.ray = ray;
  if (path) path->clear();
  State s{};
  if (!load(ray.position_mm.x(), ray.position_mm.y(), ray.position_mm.z(), ray.direction.x(), ray.direction.y(),
            ray.direction.z(), ray.wavelength_nm, s)) {
    result.status = RayStatus::InvalidInput;
    return result;
  }
  const double* table = impl.indices(ray.wavelength_nm);
  int surface = 0;
  if (impl.general) {
    result.status = path ? propagate_general<kForward, true>(impl, s, ray.wavelength_nm, table, surface, path, true, range)
                         : propagate_general<kForward, false>(impl, s, ray.wavelength_nm, table, surface, nullptr, true, range);
  } else {
    result.status = path ? propagate<kForward, true>(impl, s, ray.wavelength_nm, table, surface, path, range)
                         : propagate<kForward, false>(impl, s, ray.wavelength_nm, table, surface, nullptr, range);
  }
  result.surface = surface;
  result.ray.position_mm = Eigen::Vector3d(s.x, s.y, s.z);
  result.ray.direction = Eigen::Vector3d(s.l, s.m, s.n);
  result.optical_path_mm = s.opl;
  return result;
}

// The batch driver: rays in groups of kLanes advance one surface at a time together, so the long dependency
// chains of independent rays (square root, division, square root per surface) overlap in the processor
// instead of running one after another. Each lane runs exactly the single-ray operations (cross_surface).
constexpr int kLanes = 4;

template <bool kForward>
void trace_many(const Core& impl, const RayBatchView& batch, int threads) {
  const auto count = static_cast<std::ptrdiff_t>(batch.count);
  // The team for this call only (num_threads): the caller's OpenMP settings stay as they are.
  const int team = threads > 0 ? threads : omp_get_max_threads();
  const auto groups = (count + kLanes - 1) / kLanes;
  const int surfaces = static_cast<int>(impl.count());
  const double *const x = batch.x_mm, *const y = batch.y_mm, *const z = batch.z_mm;
  const double *const l = batch.l, *const m = batch.m, *const n = batch.n;
  double *const x_out = batch.x_out_mm, *const y_out = batch.y_out_mm, *const z_out = batch.z_out_mm;
  double *const l_out = batch.l_out, *const m_out = batch.m_out, *const n_out = batch.n_out;
  const std::ptrdiff_t in = batch.stride, out = batch.out_stride, w = batch.wavelength_stride;
  const double* const wavelength = batch.wavelength_nm;
  RayStatus* const status = batch.status;
  int* const surface = batch.surface;
  // Ray i's result into the caller's arrays.
  auto store = [&](std::ptrdiff_t i, const State& s, RayStatus st, int died_at) {
    status[i] = st;
    surface[i] = st == RayStatus::Ok || st == RayStatus::InvalidInput ? 0 : died_at;
    x_out[i * out] = s.x;
    y_out[i * out] = s.y;
    z_out[i * out] = s.z;
    l_out[i * out] = s.l;
    m_out[i * out] = s.m;
    n_out[i * out] = s.n;
  };
  if (impl.general) {
    // One ray at a time through the frames (no lanes: the frame changes dominate).
#pragma omp parallel for schedule(static) if (count >= kParallelBatchThreshold) num_threads(team)
    for (std::ptrdiff_t i = 0; i < count; ++i) {
      State s{};
      int died_at = 0;
      RayStatus st = RayStatus::InvalidInput;
      if (load(x[i * in], y[i * in], z[i * in], l[i * in], m[i * in], n[i * in], wavelength[i * w], s)) {
        st = propagate_general<kForward, false>(impl, s, wavelength[i * w], impl.indices(wavelength[i * w]), died_at, nullptr);
      } else {
        s = State{x[i * in], y[i * in], z[i * in], l[i * in], m[i * in], n[i * in], 0.0};
      }
      store(i, s, st, died_at);
    }
    return;
  }
#pragma omp parallel for schedule(static) if (count >= kParallelBatchThreshold) num_threads(team)
  for (std::ptrdiff_t group = 0; group < groups; ++group) {
    const std::ptrdiff_t first = group * kLanes;
    const int lanes = static_cast<int>(std::min<std::ptrdiff_t>(kLanes, count - first));
    std::array<Walker, kLanes> walkers{};
    std::array<RayStatus, kLanes> lane_status{};
    std::array<int, kLanes> died_at{};
    for (int lane = 0; lane < kLanes; ++lane) {
      const std::ptrdiff_t i = first + lane;
      State s{};
      if (lane >= lanes) {
        lane_status[static_cast<std::size_t>(lane)] = RayStatus::InvalidInput;  // padding, never stored
      } else if (!load(x[i * in], y[i * in], z[i * in], l[i * in], m[i * in], n[i * in], wavelength[i * w], s)) {
        lane_status[static_cast<std::size_t>(lane)] = RayStatus::InvalidInput;
      } else {
        walkers[static_cast<std::size_t>(lane)] = start_walk<kForward>(impl, s, wavelength[i * w], impl.indices(wavelength[i * w]));
        lane_status[static_cast<std::size_t>(lane)] = RayStatus::Ok;
      }
    }
    for (int step = 0; step < surfaces; ++step) {
      for (std::size_t lane = 0; lane < kLanes; ++lane) {
        if (lane_status[lane] != RayStatus::Ok) continue;
        lane_status[lane] = cross_surface<kForward, false>(impl, step, walkers[lane], nullptr);
        if (lane_status[lane] != RayStatus::Ok) died_at[lane] = surface_of_step<kForward>(impl, step);
      }
    }
    for (std::size_t lane = 0; lane < static_cast<std::size_t>(lanes); ++lane) {
      const std::ptrdiff_t i = first + static_cast<std::ptrdiff_t>(lane);
      if (lane_status[lane] == RayStatus::InvalidInput) {
        status[i] = RayStatus::InvalidInput;
        surface[i] = 0;
        // The ray as given (in place for a RayBatch).
        x_out[i * out] = x[i * in];
        y_out[i * out] = y[i * in];
        z_out[i * out] = z[i * in];
        l_out[i * out] = l[i * in];
        m_out[i * out] = m[i * in];
        n_out[i * out] = n[i * in];
        continue;
      }
      if constexpr (kForward) {
        if (lane_status[lane] == RayStatus::Ok) {
          lane_status[lane] = to_image_plane(impl, walkers[lane]);
          if (lane_status[lane] != RayStatus::Ok) died_at[lane] = surfaces + 1;
        }
      }
      store(i, walkers[lane].r, lane_status[lane], died_at[lane]);
    }
  }
}

}  // namespace

TraceResult SequentialTracer::trace_forward(const Ray& ray, std::vector<SurfaceHit>* path) const {
  return trace_one<true>(*impl_, ray, path);
}

TraceResult SequentialTracer::trace_forward_through(const Ray& ray, int first_surface, int last_surface,
                                                    std::vector<SurfaceHit>* path) const {
  const int count = static_cast<int>(impl_->count());
  if (first_surface < 1 || last_surface < first_surface || last_surface > count) {
    throw OptionsError("SequentialTracer::trace_forward_through: surfaces " + std::to_string(first_surface) + " to " +
                       std::to_string(last_surface) + " are not a range within 1.." + std::to_string(count));
  }
  return trace_one<true>(*impl_, ray, path, StepRange{first_surface - 1, last_surface});
}

TraceResult SequentialTracer::trace_backward(const Ray& ray, std::vector<SurfaceHit>* path) const {
  return trace_one<false>(*impl_, ray, path);
}

TraceResult SequentialTracer::trace(const Ray& ray, TraceDirection direction, std::vector<SurfaceHit>* path) const {
  return direction == TraceDirection::Forward ? trace_forward(ray, path) : trace_backward(ray, path);
}

void SequentialTracer::trace_batch(RayBatch& batch, TraceDirection direction, int threads) const {
  const std::size_t count = batch.size();
  if (batch.y_mm.size() != count || batch.z_mm.size() != count || batch.l.size() != count ||
      batch.m.size() != count || batch.n.size() != count || batch.wavelength_nm.size() != count ||
      batch.status.size() != count || batch.surface.size() != count) {
    throw OptionsError("RayBatch: arrays of different sizes (x_mm has " + std::to_string(count) +
                       " entries); use RayBatch::resize()");
  }
  RayBatchView view;
  view.count = count;
  view.x_mm = view.x_out_mm = batch.x_mm.data();
  view.y_mm = view.y_out_mm = batch.y_mm.data();
  view.z_mm = view.z_out_mm = batch.z_mm.data();
  view.l = view.l_out = batch.l.data();
  view.m = view.m_out = batch.m.data();
  view.n = view.n_out = batch.n.data();
  view.wavelength_nm = batch.wavelength_nm.data();
  view.status = batch.status.data();
  view.surface = batch.surface.data();
  trace_batch(view, direction, threads);
}

void SequentialTracer::trace_batch(const RayBatchView& rays, TraceDirection direction, int threads) const {
  if (rays.count == 0) return;
  if (!rays.x_mm || !rays.y_mm || !rays.z_mm || !rays.l || !rays.m || !rays.n || !rays.wavelength_nm || !rays.status || !rays.surface ||
      !rays.x_out_mm || !rays.y_out_mm || !rays.z_out_mm || !rays.l_out || !rays.m_out || !rays.n_out) {
    throw OptionsError("RayBatchView: every array must be given for " + std::to_string(rays.count) + " rays");
  }
  if (rays.stride < 1 || rays.out_stride < 1 || rays.wavelength_stride < 0) {
    throw OptionsError("RayBatchView: strides must be >= 1 (the wavelength's >= 0)");
  }
  if (direction == TraceDirection::Forward) {
    trace_many<true>(*impl_, rays, threads);
  } else {
    trace_many<false>(*impl_, rays, threads);
  }
}

}  // namespace lensmith

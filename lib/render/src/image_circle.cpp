#include "image_circle.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "lensmith/camera/lens_camera.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"

namespace lensmith::render_detail {

namespace {
// Directions of the film marched outwards from the axis.
constexpr int kDirections = 48;
// Radial steps (output px) of the march, and the bisections between the last film point some ray
// leaves the lens from and the first none does (to 1/16 of a step).
constexpr double kStepPx = 8.0;
constexpr int kBisections = 4;
// Pupil samples tried at each film point (LensCamera's (u, v): u the share of the sampled disc's
// area inside the sample's radius): its centre and rings towards its edge.
constexpr std::array<double, 4> kRingAreas{0.2, 0.45, 0.7, 0.95};
constexpr int kSamplesPerRing = 8;
}  // namespace

ImageCircle::ImageCircle(const Camera& camera, int threads) {
  if (camera.is_thin_lens() || camera.lens() == nullptr) return;
  const double lambda = camera.reference_wavelength_nm();
  std::optional<LensCamera> lens;
  try {
    const std::array<double, 1> wavelengths{lambda};
    lens.emplace(camera, wavelengths);
  } catch (const Error&) {
    return;  // a lens LensCamera cannot trace backwards (no bound drawn)
  }
  const double w = camera.frame().width_px(), h = camera.frame().height_px();
  centre_x_ = 0.5 * w;  // the film's origin, the optical axis (LensCamera::film_point_mm)
  centre_y_ = 0.5 * h;
  // Whether a ray from output point (x, y) leaves the lens through any pupil sample.
  auto lit = [&](double x, double y) {
    const auto film = lens->film_point_mm(x, y);
    if (lens->sample_ray(film[0], film[1], 0.0, 0.0, lambda).ok()) return true;
    for (const double u : kRingAreas) {
      for (int k = 0; k < kSamplesPerRing; ++k) {
        if (lens->sample_ray(film[0], film[1], u, (k + 0.5) / kSamplesPerRing, lambda).ok()) return true;
      }
    }
    return false;
  };
  // Beyond the frame's corners nothing matters.
  const double corner = std::hypot(0.5 * w, 0.5 * h) + kStepPx;
  std::vector<double> radius(kDirections, kInfinity);
  bool any_bound = false;
#pragma omp parallel for num_threads(std::max(1, threads)) schedule(dynamic, 1) reduction(|| : any_bound)
  for (int d = 0; d < kDirections; ++d) {
    const double phi = 2.0 * kPi * d / kDirections;
    const double ux = std::cos(phi), uy = std::sin(phi);
    double in = 0.0;
    for (double r = kStepPx; r <= corner; r += kStepPx) {
      if (lit(centre_x_ + r * ux, centre_y_ + r * uy)) {
        in = r;
        continue;
      }
      double out = r;
      for (int k = 0; k < kBisections; ++k) {
        const double mid = 0.5 * (in + out);
        (lit(centre_x_ + mid * ux, centre_y_ + mid * uy) ? in : out) = mid;
      }
      radius[static_cast<std::size_t>(d)] = in;
      any_bound = true;
      break;
    }
  }
  if (any_bound) radius_px_ = std::move(radius);
}

bool ImageCircle::reaches(double x_px, double y_px) const {
  if (radius_px_.empty()) return true;
  const double dx = x_px - centre_x_, dy = y_px - centre_y_;
  // Between the two directions around this one, linearly (an unbounded one leaves it unbounded).
  double a = std::atan2(dy, dx) / (2.0 * kPi) * kDirections;
  if (a < 0.0) a += kDirections;
  const double f = std::floor(a);
  const int n = kDirections;
  const int d0 = static_cast<int>(f) % n, d1 = (d0 + 1) % n;
  const double r0 = radius_px_[static_cast<std::size_t>(d0)], r1 = radius_px_[static_cast<std::size_t>(d1)];
  if (std::isinf(r0) || std::isinf(r1)) return true;
  return std::hypot(dx, dy) <= r0 + (r1 - r0) * (a - f);
}

}  // namespace lensmith::render_detail

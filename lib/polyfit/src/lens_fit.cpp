// Fitting a lens: rays sampled from the sensor side as pbrt-v4's RealisticCamera does (a point on
// the sensor, a point on the exit pupil), traced backward by the exact tracer without clipping, and
// the maps of lens_fit.h fitted to them; held-out errors and timings; Newton aiming on the fit.
#include "lensmith/polyfit/lens_fit.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/split_mix.h"
#include "lensmith/core/units.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "lensmith/polyfit/polynomial_fit.h"
#include "lensmith/trace/fresnel.h"
#include "lensmith/trace/sequential_tracer.h"

namespace lensmith {
namespace {

// Half-diagonal of a 36 x 24 mm frame (mm).
// A surface joins the clipping set when its clear aperture cuts at least this fraction of the
// training rays (fewer would not change a rendered image).
constexpr double kClipFraction = 5e-4;
// Candidates traced per ray wanted before giving up: a lens that passes fewer than 1 in 200 of the
// sampled beam is not what the sampling assumes.
constexpr int kCandidatesPerRay = 200;
constexpr std::size_t kCandidateBatch = 8192;
// Newton leaves the fit's domain when a normalised input exceeds this.
constexpr double kDomainLimit = 1.5;
// Samples the greedy term selection scores candidates on (the coefficients use every sample): 20000
// random rays tell terms apart as well as all of them do, at a fraction of the time.
constexpr int kSelectionSamples = 20000;

// Candidate i draws from its own SplitMix64 stream, so it gets the same numbers whatever the
// thread that makes it.
double uniform(std::uint64_t& state) { return static_cast<double>(splitmix64(state) >> 11) * 0x1.0p-53; }

// One traced candidate of the sampled beam.
struct Candidate {
  bool traced = false;      // reached object space (no TIR, no miss) when traced without clipping
  bool in_domain = false;   // within every clear aperture enlarged by the margin
  bool passes = false;      // within every clear aperture
  PlaneRay sensor;
  PlaneRay outer;
  double wavelength_nm = 0.0;
  double transmittance = 0.0;
  std::vector<double> hit_x, hit_y;  // position on every surface (index surface - 1)
};

struct Sampler {
  const SequentialTracer& tracer;
  const LensFitOptions& options;
  double sensor_z_mm;
  double image_radius_mm;
  double z_exit_pupil_mm;
  double sampled_pupil_radius_mm;
  std::vector<double> semi_diameter;  // per surface, +inf when unlimited; the stop's at its wide-open radius

  Candidate make(std::uint64_t stream, std::uint64_t index, std::vector<SurfaceHit>& path) const {
    std::uint64_t state = stream ^ (index * 0xD1B54A32D192ED03ull);
    Candidate c;
    const double rs = image_radius_mm * std::sqrt(uniform(state));
    const double ps = 2.0 * kPi * uniform(state);
    const double rp = sampled_pupil_radius_mm * std::sqrt(uniform(state));
    const double pp = 2.0 * kPi * uniform(state);
    c.wavelength_nm = options.min_wavelength_nm + (options.max_wavelength_nm - options.min_wavelength_nm) * uniform(state);
    const Eigen::Vector3d on_sensor(rs * std::cos(ps), rs * std::sin(ps), sensor_z_mm);
    const Eigen::Vector3d on_pupil(rp * std::cos(pp), rp * std::sin(pp), z_exit_pupil_mm);
    // Light travels from the pupil point to the sensor (+z); a virtual exit pupil behind the sensor
    // reverses the difference.
    Eigen::Vector3d forward = (on_sensor - on_pupil).normalized();
    if (forward.z() < 0.0) forward = -forward;
    c.sensor = PlaneRay{on_sensor.x(), on_sensor.y(), forward.x(), forward.y()};
    Ray ray;
    ray.position_mm = on_sensor;
    ray.direction = -forward;
    ray.wavelength_nm = c.wavelength_nm;
    const TraceResult t = tracer.trace_backward(ray, &path);
    if (!t.ok()) return c;
    c.traced = true;
    const std::size_t surfaces = semi_diameter.size();
    c.hit_x.assign(surfaces, 0.0);
    c.hit_y.assign(surfaces, 0.0);
    c.in_domain = c.passes = true;
    // Backward through each surface: from the medium after it into the medium before it.
    c.transmittance = path_transmittance(tracer, ray.direction, path, c.wavelength_nm, /*backward=*/true);
    for (const SurfaceHit& h : path) {
      const std::size_t k = static_cast<std::size_t>(h.surface - 1);
      c.hit_x[k] = h.point_mm.x();
      c.hit_y[k] = h.point_mm.y();
      const double r = std::hypot(h.point_mm.x(), h.point_mm.y());
      c.passes = c.passes && r <= semi_diameter[k];
      c.in_domain = c.in_domain && r <= options.aperture_margin * semi_diameter[k];
    }
    // The object-space ray, as light travels it, where it meets surface 1.
    const Eigen::Vector3d f = -t.ray.direction;
    c.outer = PlaneRay{t.ray.position_mm.x(), t.ray.position_mm.y(), f.x(), f.y()};
    return c;
  }

  // Candidates of stream `stream` in index order until `enough` says stop; keeps those `keep`
  // accepts. Traced in parallel batches; the result does not depend on the thread count.
  template <class Keep, class Enough>
  std::vector<Candidate> collect(std::uint64_t stream, std::size_t wanted, Keep keep, Enough enough,
                                 const std::function<void(double)>& progress, double from, double to) const {
    std::vector<Candidate> kept;
    std::vector<Candidate> batch(kCandidateBatch);
    const std::uint64_t limit = static_cast<std::uint64_t>(wanted) * kCandidatesPerRay;
    for (std::uint64_t start = 0; !enough(kept); start += kCandidateBatch) {
      if (start >= limit) {
        throw FitError("lens fit: only " + std::to_string(kept.size()) + " of " + std::to_string(wanted) +
                       " rays wanted passed the lens after " + std::to_string(start) +
                       " traced: check the image radius and the lens's clear apertures");
      }
#pragma omp parallel
      {
        std::vector<SurfaceHit> path;
#pragma omp for schedule(dynamic, 256)
        for (std::size_t i = 0; i < kCandidateBatch; ++i) batch[i] = make(stream, start + i, path);
      }
      for (Candidate& c : batch) {
        if (enough(kept)) break;
        if (keep(c)) kept.push_back(std::move(c));
      }
      if (progress) progress(from + (to - from) * std::min(1.0, static_cast<double>(kept.size()) / static_cast<double>(wanted)));
    }
    return kept;
  }
};

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  const std::size_t k = std::min(values.size() - 1, static_cast<std::size_t>(std::ceil(p * static_cast<double>(values.size()))) - 1);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

template <class F>
double median_seconds(int runs, F f) {
  std::vector<double> t;
  for (int r = 0; r < runs; ++r) {
    const auto start = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

// Inputs of a map: the ray on its plane normalised, and the normalised wavelength.
PolyPoint normalised(const PlaneRay& r, double position_scale, double direction_scale, double lambda) {
  return {r.x_mm / position_scale, r.y_mm / position_scale, r.dx / direction_scale, r.dy / direction_scale, lambda};
}

// Newton stays where the fit was made: every normalised ray coordinate within kDomainLimit.
bool in_domain(const PolyPoint& v) {
  for (int i = 0; i < 4; ++i) {
    if (std::abs(v[static_cast<std::size_t>(i)]) > kDomainLimit) return false;
  }
  return true;
}

// The fitted 2x2 system of a Newton aim, solved; false when singular.
bool solve2(const std::array<double, 4>& j, double fx, double fy, double& dx, double& dy) {
  const double det = j[0] * j[3] - j[1] * j[2];
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return false;
  dx = (j[3] * fx - j[1] * fy) / det;
  dy = (j[0] * fy - j[2] * fx) / det;
  return true;
}

// Damped Newton on two unknowns: `residual(u, ex, ey, jacobian or null)` gives the stop miss (mm) at
// u and, when asked, d(miss) / du; false when u leaves the fit's domain. Each step is halved until
// the miss falls (the stop map is nearly linear, so the full step is almost always taken). Fills
// the iterations, miss, Jacobian and convergence of `aim`; returns the last accepted u.
template <class Residual>
std::array<double, 2> damped_newton(std::array<double, 2> u, const Residual& residual, const FitAimOptions& options,
                                    FitAim& aim) {
  double ex = 0.0, ey = 0.0;
  std::array<double, 4> j{};
  if (!residual(u, ex, ey, &j)) return u;
  aim.jacobian = j;
  aim.miss_mm = std::hypot(ex, ey);
  for (aim.iterations = 0; aim.iterations < options.max_iterations && aim.miss_mm > options.tolerance_mm;) {
    ++aim.iterations;
    double sx, sy;
    if (!solve2(j, ex, ey, sx, sy)) return u;
    bool improved = false;
    for (double step = 1.0; step > 1e-3 && !improved; step *= 0.5) {
      const std::array<double, 2> trial{u[0] - step * sx, u[1] - step * sy};
      double tx, ty;
      if (!residual(trial, tx, ty, nullptr) || std::hypot(tx, ty) >= aim.miss_mm) continue;
      u = trial;
      improved = true;
    }
    if (!improved) return u;
    residual(u, ex, ey, &j);
    aim.jacobian = j;
    aim.miss_mm = std::hypot(ex, ey);
  }
  aim.converged = aim.miss_mm <= options.tolerance_mm;
  return u;
}

}  // namespace

int LensFit::automatic_term_budget(std::size_t surfaces) {
  return std::clamp(5 * static_cast<int>(surfaces) - 12, 12, 40);
}

void LensFitOptions::validate() const {
  if (degree < 1 || degree > kMaxPolyDegree) {
    throw OptionsError("fit degree must be in 1.." + std::to_string(kMaxPolyDegree) + ", got " + std::to_string(degree));
  }
  if (terms < 0) throw OptionsError("fit term budget must be >= 1 (or 0 for automatic), got " + std::to_string(terms));
  if (training_rays < 200) throw OptionsError("a fit needs at least 200 training rays, got " + std::to_string(training_rays));
  if (test_rays < 100) throw OptionsError("a fit needs at least 100 test rays, got " + std::to_string(test_rays));
  if (!(std::isfinite(min_wavelength_nm) && std::isfinite(max_wavelength_nm) && min_wavelength_nm > 100.0 &&
        max_wavelength_nm > min_wavelength_nm)) {
    throw OptionsError("fit wavelength range must satisfy 100 < min < max (nm), got " + format_number(min_wavelength_nm) +
                       ".." + format_number(max_wavelength_nm));
  }
  if (image_radius_mm && !(std::isfinite(*image_radius_mm) && *image_radius_mm > 0.0)) {
    throw OptionsError("fit image radius must be a finite length > 0 mm, got " + format_number(*image_radius_mm));
  }
  if (f_number && !(std::isfinite(*f_number) && *f_number >= 0.5)) {
    throw OptionsError("fit f-number must be finite and >= 0.5, got " + format_number(*f_number));
  }
  if (!(pupil_margin >= 1.0 && pupil_margin <= 3.0)) {
    throw OptionsError("fit pupil margin must be in [1, 3], got " + format_number(pupil_margin));
  }
  if (!(aperture_margin >= 1.0 && aperture_margin <= 1.5)) {
    throw OptionsError("fit aperture margin must be in [1, 1.5], got " + format_number(aperture_margin));
  }
}

std::string LensFitOptions::to_string() const {
  std::ostringstream os;
  os << "LensFitOptions{degree=" << degree << ", terms=" << terms << ", training_rays=" << training_rays
     << ", test_rays=" << test_rays << ", seed=" << seed << ", wavelengths=" << min_wavelength_nm << ".."
     << max_wavelength_nm << " nm, image_radius="
     << (image_radius_mm ? format_number(*image_radius_mm) + " mm" : std::string("default"))
     << ", f_number=" << (f_number ? format_number(*f_number) : std::string("the lens's")) << ", pupil_margin=" << pupil_margin << ", aperture_margin=" << aperture_margin << "}";
  return os.str();
}

std::string PlaneRay::to_string() const {
  std::ostringstream os;
  os << "PlaneRay{x=" << x_mm << " mm, y=" << y_mm << " mm, dx=" << dx << ", dy=" << dy << "}";
  return os.str();
}

std::string LensFitErrors::to_string() const {
  std::ostringstream os;
  os << "LensFitErrors{test_rays=" << test_rays << ", position_rms=" << position_rms_um
     << " um, position_p99=" << position_p99_um << " um, direction_rms=" << direction_rms_mrad
     << " mrad, stop_rms=" << stop_rms_um << " um, transmittance_rms=" << transmittance_rms
     << ", sensor_position_rms=" << sensor_position_rms_um << " um, sensor_position_p99=" << sensor_position_p99_um
     << " um, sensor_direction_rms=" << sensor_direction_rms_mrad << " mrad, vignetting_mismatch="
     << vignetting_mismatch << "}";
  return os.str();
}

std::string LensFitTiming::to_string() const {
  std::ostringstream os;
  os << "LensFitTiming{fit=" << fit_seconds << " s, exact=" << exact_ns_per_ray << " ns/ray, poly=" << poly_ns_per_ray
     << " ns/ray}";
  return os.str();
}

std::string FitTrace::to_string() const {
  std::ostringstream os;
  os << "FitTrace{" << ray << ", stop=(" << stop_x_mm << ", " << stop_y_mm << ") mm, " << (passes ? "passes" : "clipped")
     << "}";
  return os.str();
}

std::string FitAim::to_string() const {
  std::ostringstream os;
  os << "FitAim{" << ray << ", " << (converged ? "converged" : "not converged") << " after " << iterations
     << " iterations, miss=" << miss_mm << " mm}";
  return os.str();
}

void FitAimOptions::validate() const {
  if (!(tolerance_mm > 0.0 && std::isfinite(tolerance_mm))) {
    throw OptionsError("aim tolerance must be a finite length > 0 mm, got " + format_number(tolerance_mm));
  }
  if (max_iterations < 1) throw OptionsError("aim needs at least 1 iteration, got " + std::to_string(max_iterations));
}

LensFit LensFit::fit(const Prescription& lens, const LensFitOptions& options,
                     const std::function<void(double)>& progress) {
  options.validate();
  const auto start_time = std::chrono::steady_clock::now();
  TracerOptions tracer_options;
  tracer_options.image_plane = TracerOptions::ImagePlane::ParaxialFocus;
  tracer_options.clip_apertures = false;
  const SequentialTracer tracer(lens, tracer_options);
  const ParaxialSystem paraxial(lens);

  LensFit fit;
  fit.lens_name_ = lens.name;
  fit.lens_hash_ = prescription_hash(lens);
  fit.options_ = options;
  fit.sensor_z_mm_ = tracer.image_plane_z_mm();
  fit.image_radius_mm_ = options.image_radius_mm.value_or(LensFitOptions::kDefaultImageRadiusMm);
  if (fit.sensor_z_mm_ <= lens.vertex_z_mm(lens.surfaces.size() - 1)) {
    throw FitError("lens fit: the paraxial focus (z = " + format_number(fit.sensor_z_mm_) +
                   " mm) is not behind the last surface: the sensor-side plane must lie in air after the lens");
  }

  const int stop = paraxial.stop_surface();
  const std::size_t stop_index = static_cast<std::size_t>(stop - 1);
  const double marginal_at_stop = std::abs(paraxial.marginal_ray().rows[stop_index].y_mm);
  double stop_radius = std::max(lens.surfaces[stop_index].semi_diameter_mm.value_or(0.0), marginal_at_stop);
  if (options.f_number) {
    // The stop a camera opens for this f-number (Camera::from_lens does the same).
    Prescription at_n = lens;
    at_n.aperture = ApertureSpec{ApertureSpec::Kind::ImageSpaceFNumber, *options.f_number};
    const ParaxialSystem p(at_n);
    stop_radius = std::max(stop_radius, std::abs(p.marginal_ray().rows[stop_index].y_mm));
  }
  const Pupil& ep = paraxial.entrance_pupil();
  const Pupil& xp = paraxial.exit_pupil();
  fit.pupils_.z_entrance_pupil_mm = ep.z_mm;
  fit.pupils_.entrance_per_stop = ep.magnification;
  fit.pupils_.z_exit_pupil_mm = xp.z_mm;
  fit.pupils_.exit_per_stop = xp.magnification;
  const Surface& front = lens.surfaces.front();
  fit.front_ = FrontSurface{front.curvature_per_mm, front.conic, front.even_asphere};

  Sampler sampler{tracer, options, fit.sensor_z_mm_, fit.image_radius_mm_, xp.z_mm,
                  options.pupil_margin * std::abs(xp.magnification) * stop_radius, {}};
  for (std::size_t k = 0; k < lens.surfaces.size(); ++k) {
    sampler.semi_diameter.push_back(k == stop_index ? stop_radius
                                                    : lens.surfaces[k].semi_diameter_mm.value_or(kInfinity));
  }

  // Training rays: the sampled beam within the enlarged clear apertures. Test rays: another stream.
  std::uint64_t training_seed = options.seed;
  const std::uint64_t training_stream = splitmix64(training_seed);
  std::uint64_t test_seed = options.seed ^ 0x5DEECE66Dull;
  const std::uint64_t test_stream = splitmix64(test_seed) + 1;
  const std::size_t n_train = static_cast<std::size_t>(options.training_rays);
  const std::vector<Candidate> train = sampler.collect(
      training_stream, n_train, [](const Candidate& c) { return c.in_domain; },
      [&](const std::vector<Candidate>& kept) { return kept.size() >= n_train; }, progress, 0.0, 0.25);
  const std::size_t n_test = static_cast<std::size_t>(options.test_rays);
  std::size_t test_passing = 0;
  const std::vector<Candidate> test = sampler.collect(
      test_stream, n_test,
      [&](const Candidate& c) {
        test_passing += c.passes ? 1 : 0;
        return c.in_domain;
      },
      [&](const std::vector<Candidate>&) { return test_passing >= n_test; }, progress, 0.25, 0.35);

  // The clipping set: the stop, then every surface that cuts enough training rays.
  fit.clip_.push_back({stop, stop_radius});
  for (std::size_t k = 0; k < lens.surfaces.size(); ++k) {
    if (k == stop_index || !std::isfinite(sampler.semi_diameter[k])) continue;
    std::size_t cut = 0;
    for (const Candidate& c : train) cut += std::hypot(c.hit_x[k], c.hit_y[k]) > sampler.semi_diameter[k] ? 1 : 0;
    if (static_cast<double>(cut) >= kClipFraction * static_cast<double>(train.size()) &&
        fit.clip_.size() < static_cast<std::size_t>(kMaxMapOutputs)) {
      fit.clip_.push_back({static_cast<int>(k + 1), sampler.semi_diameter[k]});
    }
  }

  // Scales: the largest training position and direction on each plane.
  Scales& s = fit.scales_;
  s.sensor_position_mm = s.sensor_direction = s.outer_position_mm = s.outer_direction = 0.0;
  for (const Candidate& c : train) {
    s.sensor_position_mm = std::max({s.sensor_position_mm, std::abs(c.sensor.x_mm), std::abs(c.sensor.y_mm)});
    s.sensor_direction = std::max({s.sensor_direction, std::abs(c.sensor.dx), std::abs(c.sensor.dy)});
    s.outer_position_mm = std::max({s.outer_position_mm, std::abs(c.outer.x_mm), std::abs(c.outer.y_mm)});
    s.outer_direction = std::max({s.outer_direction, std::abs(c.outer.dx), std::abs(c.outer.dy)});
  }
  s.wavelength_centre_nm = 0.5 * (options.min_wavelength_nm + options.max_wavelength_nm);
  s.wavelength_half_range_nm = 0.5 * (options.max_wavelength_nm - options.min_wavelength_nm);

  // Each training ray counts twice: as itself for the x outputs and mirrored in x = y for the y
  // outputs, which the same polynomial must give (lens_fit.h).
  const std::size_t clip_count = fit.clip_.size();
  std::vector<PolyPoint> sensor_in, outer_in;
  std::vector<std::vector<std::array<double, 2>>> to_outer(2), to_sensor(2), clip(clip_count);
  std::vector<std::vector<double>> transmittance_target(1);
  for (const Candidate& c : train) {
    const double lambda = fit.normalised_wavelength(c.wavelength_nm);
    sensor_in.push_back(normalised(c.sensor, s.sensor_position_mm, s.sensor_direction, lambda));
    outer_in.push_back(normalised(c.outer, s.outer_position_mm, s.outer_direction, lambda));
    to_outer[0].push_back({c.outer.x_mm, c.outer.y_mm});
    to_outer[1].push_back({c.outer.dx, c.outer.dy});
    to_sensor[0].push_back({c.sensor.x_mm, c.sensor.y_mm});
    to_sensor[1].push_back({c.sensor.dx, c.sensor.dy});
    for (std::size_t q = 0; q < clip_count; ++q) {
      const std::size_t k = static_cast<std::size_t>(fit.clip_[q].surface - 1);
      clip[q].push_back({c.hit_x[k], c.hit_y[k]});
    }
    transmittance_target[0].push_back(c.transmittance);
  }
  FitOptions fo;
  fo.max_degree = options.degree;
  fit.term_budget_ = options.terms > 0 ? options.terms : automatic_term_budget(lens.surfaces.size());
  fo.max_terms = fit.term_budget_;
  fo.max_selection_samples = kSelectionSamples;
  const std::vector<InvariantTerm> pool = vector_invariant_terms(options.degree);
  fit.sensor_to_outer_ = fit_rotational_map(sensor_in, to_outer, pool, fo).map;
  if (progress) progress(0.5);
  fit.outer_to_sensor_ = fit_rotational_map(outer_in, to_sensor, pool, fo).map;
  if (progress) progress(0.65);
  fit.sensor_clip_ = fit_rotational_map(sensor_in, clip, pool, fo).map;
  if (progress) progress(0.8);
  fit.outer_clip_ = fit_rotational_map(outer_in, clip, pool, fo).map;
  if (progress) progress(0.9);
  fit.transmittance_ =
      fit_rotational_scalar_map(sensor_in, transmittance_target, scalar_invariant_terms(options.degree), fo).map;
  fit.timing_.fit_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();

  // Held-out errors.
  LensFitErrors& e = fit.errors_;
  std::vector<double> position_um, sensor_um;
  double direction2 = 0.0, stop2 = 0.0, t2 = 0.0, sensor_direction2 = 0.0;
  std::size_t mismatched = 0;
  for (const Candidate& c : test) {
    const FitTrace back = fit.from_sensor(c.sensor, c.wavelength_nm);
    mismatched += back.passes != c.passes ? 1 : 0;
    if (!c.passes) continue;
    position_um.push_back(1e3 * std::hypot(back.ray.x_mm - c.outer.x_mm, back.ray.y_mm - c.outer.y_mm));
    direction2 += std::pow(back.ray.dx - c.outer.dx, 2) + std::pow(back.ray.dy - c.outer.dy, 2);
    stop2 += std::pow(back.stop_x_mm - c.hit_x[stop_index], 2) + std::pow(back.stop_y_mm - c.hit_y[stop_index], 2);
    t2 += std::pow(fit.transmittance(c.sensor, c.wavelength_nm) - c.transmittance, 2);
    const FitTrace fwd = fit.from_outer(c.outer, c.wavelength_nm);
    sensor_um.push_back(1e3 * std::hypot(fwd.ray.x_mm - c.sensor.x_mm, fwd.ray.y_mm - c.sensor.y_mm));
    sensor_direction2 += std::pow(fwd.ray.dx - c.sensor.dx, 2) + std::pow(fwd.ray.dy - c.sensor.dy, 2);
  }
  const double n = static_cast<double>(position_um.size());
  e.test_rays = static_cast<int>(position_um.size());
  double p2 = 0.0, q2 = 0.0;
  for (const double v : position_um) p2 += v * v;
  for (const double v : sensor_um) q2 += v * v;
  e.position_rms_um = std::sqrt(p2 / n);
  e.position_p99_um = percentile(position_um, 0.99);
  e.direction_rms_mrad = 1e3 * std::sqrt(direction2 / n);
  e.stop_rms_um = 1e3 * std::sqrt(stop2 / n);
  e.transmittance_rms = std::sqrt(t2 / n);
  e.sensor_position_rms_um = std::sqrt(q2 / n);
  e.sensor_position_p99_um = percentile(sensor_um, 0.99);
  e.sensor_direction_rms_mrad = 1e3 * std::sqrt(sensor_direction2 / n);
  e.vignetting_mismatch = static_cast<double>(mismatched) / static_cast<double>(test.size());

  // Timing on one thread: the passing test rays from the sensor to the outer plane, both ways.
  {
    RayBatch batch;
    std::vector<double> x, y, dx, dy, nm;
    for (const Candidate& c : test) {
      if (!c.passes) continue;
      x.push_back(c.sensor.x_mm);
      y.push_back(c.sensor.y_mm);
      dx.push_back(c.sensor.dx);
      dy.push_back(c.sensor.dy);
      nm.push_back(c.wavelength_nm);
    }
    const std::size_t count = x.size();
    std::vector<double> ox(count), oy(count), odx(count), ody(count);
    // One thread for the exact tracer, by its own argument: the polynomial's batch is serial, and the
    // caller's OpenMP settings are not touched (a library call must not change process-wide state).
    const double exact_s = median_seconds(5, [&] {
      batch.resize(count);
      for (std::size_t i = 0; i < count; ++i) {
        batch.x_mm[i] = x[i];
        batch.y_mm[i] = y[i];
        batch.z_mm[i] = fit.sensor_z_mm_;
        const double dz = std::sqrt(std::max(0.0, 1.0 - dx[i] * dx[i] - dy[i] * dy[i]));
        batch.l[i] = -dx[i];
        batch.m[i] = -dy[i];
        batch.n[i] = -dz;
        batch.wavelength_nm[i] = nm[i];
      }
      tracer.trace_batch(batch, TraceDirection::Backward, /*threads=*/1);
    });
    const double poly_s = median_seconds(5, [&] { fit.outer_rays(x, y, dx, dy, nm, ox, oy, odx, ody); });
    fit.timing_.exact_ns_per_ray = 1e9 * exact_s / static_cast<double>(count);
    fit.timing_.poly_ns_per_ray = 1e9 * poly_s / static_cast<double>(count);
  }
  if (progress) progress(1.0);
  return fit;
}

FitTrace LensFit::evaluate(const RotationalMap& map, const RotationalMap& clip, double position_scale,
                           double direction_scale, const PlaneRay& in, double wavelength_nm,
                           std::optional<double> stop_radius_mm) const {
  const double lambda = normalised_wavelength(wavelength_nm);
  const PolyPoint v = normalised(in, position_scale, direction_scale, lambda);
  std::array<double, 4> ray;
  map.evaluate(v, ray);
  std::array<double, 2 * kMaxMapOutputs> at;
  const std::size_t k = clip_.size();
  clip.evaluate(v, std::span<double>(at.data(), 2 * k));
  FitTrace t;
  t.ray = PlaneRay{ray[0], ray[1], ray[2], ray[3]};
  t.stop_x_mm = at[0];
  t.stop_y_mm = at[1];
  for (std::size_t q = 0; q < k; ++q) {
    const double limit = q == 0 && stop_radius_mm ? *stop_radius_mm : clip_[q].semi_diameter_mm;
    t.clearance = std::min(t.clearance, 1.0 - std::hypot(at[2 * q], at[2 * q + 1]) / limit);
  }
  t.passes = t.ray.dx * t.ray.dx + t.ray.dy * t.ray.dy < 1.0 && t.clearance >= 0.0;
  return t;
}

FitTrace LensFit::from_sensor(const PlaneRay& sensor, double wavelength_nm, std::optional<double> stop_radius_mm) const {
  return evaluate(sensor_to_outer_, sensor_clip_, scales_.sensor_position_mm, scales_.sensor_direction, sensor,
                  wavelength_nm, stop_radius_mm);
}

FitTrace LensFit::from_outer(const PlaneRay& outer, double wavelength_nm, std::optional<double> stop_radius_mm) const {
  return evaluate(outer_to_sensor_, outer_clip_, scales_.outer_position_mm, scales_.outer_direction, outer,
                  wavelength_nm, stop_radius_mm);
}

double LensFit::transmittance(const PlaneRay& sensor, double wavelength_nm) const {
  const double lambda = normalised_wavelength(wavelength_nm);
  double t = 0.0;
  transmittance_.evaluate(normalised(sensor, scales_.sensor_position_mm, scales_.sensor_direction, lambda),
                          std::span<double>(&t, 1));
  return std::clamp(t, 0.0, 1.0);
}

void LensFit::outer_rays(std::span<const double> x_mm, std::span<const double> y_mm, std::span<const double> dx,
                         std::span<const double> dy, std::span<const double> wavelength_nm, std::span<double> out_x_mm,
                         std::span<double> out_y_mm, std::span<double> out_dx, std::span<double> out_dy) const {
  const std::size_t count = x_mm.size();
  if (y_mm.size() != count || dx.size() != count || dy.size() != count || wavelength_nm.size() != count ||
      out_x_mm.size() != count || out_y_mm.size() != count || out_dx.size() != count || out_dy.size() != count) {
    throw FitError("LensFit::outer_rays: every span must hold the same number of rays");
  }
  const double ps = 1.0 / scales_.sensor_position_mm, ds = 1.0 / scales_.sensor_direction;
  const double ls = 1.0 / scales_.wavelength_half_range_nm;
  const std::array<double*, 4> out{out_x_mm.data(), out_y_mm.data(), out_dx.data(), out_dy.data()};
  sensor_to_outer_.evaluate_batch({x_mm.data(), y_mm.data(), dx.data(), dy.data(), wavelength_nm.data()}, out, count,
                                  {ps, ps, ds, ds, ls}, {0.0, 0.0, 0.0, 0.0, -scales_.wavelength_centre_nm * ls});
}

FitAim LensFit::aim_from_sensor(double x_mm, double y_mm, double stop_x_mm, double stop_y_mm, double wavelength_nm,
                                const FitAimOptions& options) const {
  options.validate();
  const double lambda = normalised_wavelength(wavelength_nm);
  const double ps = scales_.sensor_position_mm, ds = scales_.sensor_direction;
  // First guess: toward the paraxial exit-pupil image of the stop point.
  const double px = stop_x_mm * pupils_.exit_per_stop, py = stop_y_mm * pupils_.exit_per_stop;
  double fx = x_mm - px, fy = y_mm - py, fz = sensor_z_mm_ - pupils_.z_exit_pupil_mm;
  if (fz < 0.0) fx = -fx, fy = -fy, fz = -fz;
  const double norm = std::sqrt(fx * fx + fy * fy + fz * fz);
  FitAim aim;
  aim.ray = PlaneRay{x_mm, y_mm, fx / norm, fy / norm};
  const RotationalMap& map = sensor_clip_;
  std::array<double, 2> at;
  std::array<double, 8> jac;
  auto residual = [&](const std::array<double, 2>& u, double& ex, double& ey, std::array<double, 4>* j) {
    const PolyPoint va = normalised(PlaneRay{x_mm, y_mm, u[0], u[1]}, ps, ds, lambda);
    if (!in_domain(va)) return false;
    // Output 0 is the stop; its Jacobian columns 2, 3 are d/d(dx, dy) in normalised units.
    if (j) {
      map.evaluate_with_jacobian(va, 0, at, jac);
      *j = {jac[2] / ds, jac[3] / ds, jac[6] / ds, jac[7] / ds};
    } else {
      at = map.evaluate_output(va, 0);
    }
    ex = at[0] - stop_x_mm;
    ey = at[1] - stop_y_mm;
    return true;
  };
  const auto u = damped_newton({aim.ray.dx, aim.ray.dy}, residual, options, aim);
  aim.ray = PlaneRay{x_mm, y_mm, u[0], u[1]};
  return aim;
}

std::array<double, 2> LensFit::paraxial_outer_position(const ObjectPoint& o, double stop_x_mm, double stop_y_mm) const {
  const double w = o.inverse_depth_per_mm;
  const double ex = stop_x_mm * pupils_.entrance_per_stop, ey = stop_y_mm * pupils_.entrance_per_stop;
  const double ze = pupils_.z_entrance_pupil_mm;
  // w times the vector from the object point to the entrance-pupil point (finite at w = 0).
  const double ux = w * ex - o.tan_x, uy = w * ey - o.tan_y, uz = 1.0 + w * (ze - o.origin_z_mm);
  return {ex - ux / uz * ze, ey - uy / uz * ze};
}

FitAim LensFit::aim_from_object(const ObjectPoint& o, double stop_x_mm, double stop_y_mm, double wavelength_nm,
                                std::optional<std::array<double, 2>> guess, const FitAimOptions& options) const {
  options.validate();
  const double lambda = normalised_wavelength(wavelength_nm);
  const double ps = scales_.outer_position_mm, ds = scales_.outer_direction;
  const std::array<double, 2> start = guess ? *guess : paraxial_outer_position(o, stop_x_mm, stop_y_mm);
  const RotationalMap& map = outer_clip_;
  std::array<double, 2> at;
  std::array<double, 8> jac;
  auto residual = [&](const std::array<double, 2>& u, double& ex, double& ey, std::array<double, 4>* j) {
    const std::optional<OuterLine> found = outer_line(o, u[0], u[1]);
    if (!found) return false;
    const OuterLine& l = *found;
    const PolyPoint va = normalised(l.ray, ps, ds, lambda);
    if (!in_domain(va)) return false;
    if (!j) {
      at = map.evaluate_output(va, 0);
      ex = at[0] - stop_x_mm;
      ey = at[1] - stop_y_mm;
      return true;
    }
    map.evaluate_with_jacobian(va, 0, at, jac);
    ex = at[0] - stop_x_mm;
    ey = at[1] - stop_y_mm;
    {
      // Chain rule through the normalisation and the direction's dependence on the outer position.
      const double* gx = jac.data();      // d stop_x / d(normalised x, y, dx, dy)
      const double* gy = jac.data() + 4;  // d stop_y / d(...)
      *j = {gx[0] / ps + gx[2] / ds * l.ddx_dx + gx[3] / ds * l.ddy_dx,
            gx[1] / ps + gx[2] / ds * l.ddx_dy + gx[3] / ds * l.ddy_dy,
            gy[0] / ps + gy[2] / ds * l.ddx_dx + gy[3] / ds * l.ddy_dx,
            gy[1] / ps + gy[2] / ds * l.ddx_dy + gy[3] / ds * l.ddy_dy};
    }
    return true;
  };
  FitAim aim;
  const auto u = damped_newton(start, residual, options, aim);
  const std::optional<OuterLine> last = outer_line(o, u[0], u[1]);
  aim.ray = last ? last->ray : PlaneRay{u[0], u[1], 0.0, 0.0};
  return aim;
}

std::optional<double> LensFit::front_sag(double r2, double* dz_dr2) const {
  // z = c s / (1 + sqrt(1 - (1 + k) c^2 s)) + sum_j a_j s^(j + 1), s = r^2; dz/ds = c / (2 q) + ...
  const double c = front_.curvature_per_mm, k = front_.conic;
  const double q2 = 1.0 - (1.0 + k) * c * c * r2;
  if (q2 <= 0.0) return std::nullopt;
  const double q = std::sqrt(q2);
  double z = c * r2 / (1.0 + q);
  double slope = 0.5 * c / q;
  double power = 1.0;  // s^j
  for (std::size_t j = 0; j < front_.even_asphere.size(); ++j) {
    const double a = front_.even_asphere[j];
    slope += a * static_cast<double>(j + 1) * power;
    power *= r2;
    z += a * power;
  }
  if (dz_dr2) *dz_dr2 = slope;
  return z;
}

std::optional<LensFit::OuterLine> LensFit::outer_line(const ObjectPoint& o, double x, double y) const {
  double dz_ds = 0.0;
  const std::optional<double> z = front_sag(x * x + y * y, &dz_ds);
  if (!z) return std::nullopt;
  // w times the vector from the object point to the surface point (finite at w = 0).
  const double w = o.inverse_depth_per_mm;
  const double ux = w * x - o.tan_x, uy = w * y - o.tan_y, uz = 1.0 + w * (*z - o.origin_z_mm);
  if (uz <= 0.0) return std::nullopt;  // the object point is not in front of the surface
  const double len = std::sqrt(ux * ux + uy * uy + uz * uz);
  const double fx = ux / len, fy = uy / len, fz = uz / len;
  // d(w u) / dx = (w, 0, w dz/dx), d(w u) / dy = (0, w, w dz/dy); d f = (g - f (f.g)) / |w u|.
  const double zx = 2.0 * x * dz_ds, zy = 2.0 * y * dz_ds;
  const double fgx = w * (fx + fz * zx), fgy = w * (fy + fz * zy);
  return OuterLine{PlaneRay{x, y, fx, fy}, (w - fx * fgx) / len, (0.0 - fy * fgx) / len, (0.0 - fx * fgy) / len,
                   (w - fy * fgy) / len};
}

std::optional<PlaneRay> LensFit::outer_ray_from_object(const ObjectPoint& o, double x_mm, double y_mm) const {
  const std::optional<OuterLine> line = outer_line(o, x_mm, y_mm);
  if (!line) return std::nullopt;
  return line->ray;
}

std::optional<std::array<double, 2>> LensFit::stop_from_object(const ObjectPoint& o, double x_mm, double y_mm,
                                                              double wavelength_nm) const {
  const std::optional<PlaneRay> ray = outer_ray_from_object(o, x_mm, y_mm);
  if (!ray) return std::nullopt;
  const double lambda = normalised_wavelength(wavelength_nm);
  const PolyPoint v = normalised(*ray, scales_.outer_position_mm, scales_.outer_direction, lambda);
  if (!in_domain(v)) return std::nullopt;
  return outer_clip_.evaluate_output(v, 0);
}

std::string LensFit::prescription_hash(const Prescription& lens) {
  // FNV-1a, 64 bit (Fowler, Noll & Vo), over the numbers the rays see.
  std::uint64_t h = 0xcbf29ce484222325ull;
  auto mix = [&](double v) {
    if (v == 0.0) v = 0.0;  // -0 and +0 hash alike
    unsigned char bytes[sizeof v];
    std::memcpy(bytes, &v, sizeof v);
    for (const unsigned char b : bytes) h = (h ^ b) * 0x100000001b3ull;
  };
  const ParaxialSystem paraxial(lens);
  const int stop = paraxial.stop_surface();
  for (const double nm : {380.0, kWavelengthD_nm, 780.0}) mix(lens.object_medium.index(nm));
  for (std::size_t k = 0; k < lens.surfaces.size(); ++k) {
    const Surface& s = lens.surfaces[k];
    mix(s.curvature_per_mm);
    mix(k + 1 < lens.surfaces.size() ? s.thickness_mm : 0.0);  // the last thickness only places the image
    mix(s.conic);
    for (const double a : s.even_asphere) mix(a);
    mix(static_cast<int>(k + 1) == stop ? -1.0 : s.semi_diameter_mm.value_or(kInfinity));
    for (const double nm : {380.0, kWavelengthD_nm, 780.0}) mix(s.medium.index(nm));
  }
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}

void LensFit::check_matches(const Prescription& lens) const {
  const std::string h = prescription_hash(lens);
  if (h != lens_hash_) {
    throw OptionsError("the fit was made for '" + lens_name_ + "' (prescription hash " + lens_hash_ +
                       "), not for '" + lens.name + "' (hash " + h + "): fit this lens with lensmith fit");
  }
}

std::string LensFit::to_string() const {
  std::ostringstream os;
  os << "LensFit{lens=\"" << lens_name_ << "\", hash=" << lens_hash_ << ", degree=" << options_.degree
     << ", terms=" << term_budget_ << ", sensor_to_outer=" << sensor_to_outer_ << ", outer_to_sensor="
     << outer_to_sensor_ << ", clip_surfaces=" << clip_.size() << ", " << errors_.to_string() << "}";
  return os.str();
}

}  // namespace lensmith

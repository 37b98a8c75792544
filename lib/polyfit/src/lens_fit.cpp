// Fitting a lens (lens_fit.h): the stages of lens_fit_stages.h in order (the sampled beam, the
// clipping set, the scales, the maps fitted by greedy term selection and least squares, the held-out
// errors), and the fitted maps' evaluation.
#include "lensmith/polyfit/lens_fit.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "lens_fit_stages.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/polyfit/polynomial_fit.h"

namespace lensmith {

using polyfit_detail::Candidate;
using polyfit_detail::normalised;
using polyfit_detail::RaySampler;
using polyfit_detail::Stream;
using polyfit_detail::stream_of;

namespace {

// Samples the greedy term selection scores candidates on (the coefficients use every sample): 20000
// random rays tell terms apart as well as all of them do, at a fraction of the time.
constexpr int kSelectionSamples = 20000;
// Terms of the component form per term of the invariant form in the automatic budget: measured on
// lentil's Schneider anamorphic (docs/polyfit.md, "Anamorphic lenses").
constexpr int kComponentTermsPerInvariant = 3;

}  // namespace

std::string_view to_string(LensSymmetry symmetry) {
  switch (symmetry) {
    case LensSymmetry::kRotational: return "rotational";
    case LensSymmetry::kSectionMirrors: return "section mirrors";
  }
  return "unknown";
}

std::optional<std::string> LensFit::why_not_fittable(const Prescription& lens) {
  // A tilt-shift lens is fitted as its coaxial core, the breaks at its ends applied exactly where the fit is
  // used; a break between elements would need the fit to follow a folded or tilted axis inside the lens.
  const std::optional<CoaxialCore> core = coaxial_core(lens);
  if (!core) {
    if (const auto why = lens.why_not_rotationally_symmetric()) {
      return *why + " between elements (a fit of a lens tilted or decentred inside is not implemented; coordinate breaks "
                    "before and after all its elements, as in a tilt-shift lens, are)";
    }
    return std::string("it has no surface that is not a coordinate break");
  }
  if (const int mirrors = core->lens.mirror_count(); mirrors % 2 == 1) {
    return "it has " + std::to_string(mirrors) + " mirror" + (mirrors == 1 ? "" : "s") +
           " (an odd number: its image faces back toward the scene, which a fit does not take; not implemented)";
  }
  return std::nullopt;
}

LensSymmetry LensFit::symmetry_of(const Prescription& lens) {
  // Coaxial standard, toroidal and biconic surfaces: each is even in x and in y (Surface::sag_and_slope),
  // so the lens keeps both section mirrors when it is not rotationally symmetric.
  const std::optional<CoaxialCore> core = coaxial_core(lens);  // a tilt-shift lens's breaks are not the maps'
  return (core ? core->lens : lens).is_rotationally_symmetric() ? LensSymmetry::kRotational : LensSymmetry::kSectionMirrors;
}

void LensFit::set_front_surface(const FrontSurface& front) {
  front_ = front;
  front_shape_ = Surface{};
  front_shape_.kind = front.kind;
  front_shape_.curvature_per_mm = front.curvature_per_mm;
  front_shape_.conic = front.conic;
  front_shape_.even_asphere = front.even_asphere;
  front_shape_.curvature_x_per_mm = front.curvature_x_per_mm;
  front_shape_.conic_x = front.conic_x;
}

int LensFit::automatic_term_budget(std::size_t surfaces, LensSymmetry symmetry) {
  const int rotational = std::clamp(5 * static_cast<int>(surfaces) - 12, 12, 40);
  // The component form spends a term per monomial per component where one invariant term stood for
  // several (x^3 and x y^2, the x and the y output): kComponentTermsPerInvariant times the budget.
  return symmetry == LensSymmetry::kRotational ? rotational : kComponentTermsPerInvariant * rotational;
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

LensFit LensFit::fit(const Prescription& lens, const LensFitOptions& options,
                     const std::function<void(double)>& progress) {
  options.validate();
  if (const auto why = why_not_fittable(lens)) throw FitError("lens fit of '" + lens.name + "': " + *why);
  const auto start_time = std::chrono::steady_clock::now();
  // What the maps describe: the lens without the coordinate breaks at its ends (all of it for most lenses).
  const CoaxialCore core = *coaxial_core(lens);
  const Prescription& subject = core.lens;
  const RaySampler sampler(subject, options);
  const ParaxialSystem& paraxial = sampler.paraxial();

  LensFit fit;
  fit.lens_name_ = lens.name;
  fit.lens_hash_ = prescription_hash(subject);
  fit.options_ = options;
  fit.sensor_z_mm_ = sampler.sensor_z_mm();
  fit.image_radius_mm_ = sampler.image_radius_mm();
  const Pupil& ep = paraxial.entrance_pupil();
  const Pupil& xp = paraxial.exit_pupil();
  fit.pupils_.z_entrance_pupil_mm = ep.z_mm;
  fit.pupils_.entrance_per_stop = ep.magnification;
  fit.pupils_.z_exit_pupil_mm = xp.z_mm;
  fit.pupils_.exit_per_stop = xp.magnification;
  fit.symmetry_ = symmetry_of(subject);
  fit.pupils_x_ = fit.pupils_;
  if (const ParaxialSystem* x = sampler.paraxial_x()) {
    fit.pupils_x_ = Pupils{x->entrance_pupil().z_mm, x->entrance_pupil().magnification, x->exit_pupil().z_mm,
                           x->exit_pupil().magnification};
  }
  const Surface& front = subject.surfaces.front();
  fit.set_front_surface(FrontSurface{front.kind, front.curvature_per_mm, front.conic, front.even_asphere,
                                     front.curvature_x_per_mm, front.conic_x});

  // Training rays: the sampled beam within the enlarged clear apertures. Test rays: another stream.
  const std::size_t n_train = static_cast<std::size_t>(options.training_rays);
  const std::vector<Candidate> train = sampler.collect(
      stream_of(options.seed, Stream::Training), n_train, [](const Candidate& c) { return c.in_domain; },
      [&](const std::vector<Candidate>& kept) { return kept.size() >= n_train; }, progress, 0.0, 0.25);
  const std::size_t n_test = static_cast<std::size_t>(options.test_rays);
  std::size_t test_passing = 0;
  const std::vector<Candidate> test = sampler.collect(
      stream_of(options.seed, Stream::Test), n_test,
      [&](const Candidate& c) {
        test_passing += c.passes ? 1 : 0;
        return c.in_domain;
      },
      [&](const std::vector<Candidate>&) { return test_passing >= n_test; }, progress, 0.25, 0.35);

  fit.clip_ = polyfit_detail::choose_clip_surfaces(sampler, train);

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

  // Every training ray as the maps' inputs (normalised) and targets.
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
  fit.term_budget_ = options.terms > 0 ? options.terms : automatic_term_budget(subject.surfaces.size(), fit.symmetry_);
  fo.max_terms = fit.term_budget_;
  fo.max_selection_samples = kSelectionSamples;
  // One fit of each map in the form the lens's symmetry calls for.
  auto fit_vector = [&](const std::vector<PolyPoint>& in, const std::vector<std::vector<std::array<double, 2>>>& targets) {
    if (fit.symmetry_ == LensSymmetry::kRotational) return FittedMap(fit_rotational_map(in, targets, vector_invariant_terms(options.degree), fo).map);
    return FittedMap(fit_component_map(in, targets, vector_component_terms(options.degree), fo).map);
  };
  fit.sensor_to_outer_ = fit_vector(sensor_in, to_outer);
  if (progress) progress(0.5);
  fit.outer_to_sensor_ = fit_vector(outer_in, to_sensor);
  if (progress) progress(0.65);
  fit.sensor_clip_ = fit_vector(sensor_in, clip);
  if (progress) progress(0.8);
  fit.outer_clip_ = fit_vector(outer_in, clip);
  if (progress) progress(0.9);
  if (fit.symmetry_ == LensSymmetry::kRotational) {
    fit.transmittance_ = fit_rotational_scalar_map(sensor_in, transmittance_target, scalar_invariant_terms(options.degree), fo).map;
  } else {
    fit.transmittance_ = fit_component_scalar_map(sensor_in, transmittance_target, scalar_component_terms(options.degree), fo).map;
  }
  fit.timing_.fit_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();

  fit.errors_ = polyfit_detail::held_out_errors(fit, test, sampler.stop_surface());
  if (progress) progress(1.0);
  return fit;
}

FitTrace LensFit::evaluate(const FittedMap& map, const FittedMap& clip, double position_scale,
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
    t.clearance = std::min(t.clearance, clip_[q].clearance(at[2 * q], at[2 * q + 1], q == 0 ? stop_radius_mm : std::nullopt));
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

std::string LensFit::to_string() const {
  std::ostringstream os;
  os << "LensFit{lens=\"" << lens_name_ << "\", hash=" << lens_hash_ << ", degree=" << options_.degree
     << ", terms=" << term_budget_ << ", symmetry=" << lensmith::to_string(symmetry_) << ", sensor_to_outer=" << sensor_to_outer_ << ", outer_to_sensor="
     << outer_to_sensor_ << ", clip_surfaces=" << clip_.size() << ", " << errors_.to_string() << "}";
  return os.str();
}

}  // namespace lensmith

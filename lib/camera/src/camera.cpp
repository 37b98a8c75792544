#include "lensmith/camera/camera.h"
#include "lensmith/trace/surface_frames.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/paraxial/paraxial_spectral_table.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "model_implementations.h"

namespace lensmith {

namespace {

constexpr double kMinWavelengthNm = 380.0;
constexpr double kMaxWavelengthNm = 780.0;
constexpr int kWavelengthSamples = 64;  // as Asberg's method tabulates its lens parameters

// The renderer's view of a paraxial sample: pupil radii instead of diameters.
FirstOrderSample first_order_from(const ParaxialSample& p) {
  FirstOrderSample s;
  s.wavelength_nm = p.wavelength_nm;
  s.efl_mm = p.efl_mm;
  s.z_front_principal_mm = p.z_front_principal_mm;
  s.z_rear_principal_mm = p.z_rear_principal_mm;
  s.z_entrance_pupil_mm = p.z_entrance_pupil_mm;
  s.z_exit_pupil_mm = p.z_exit_pupil_mm;
  s.entrance_pupil_radius_mm = 0.5 * p.entrance_pupil_diameter_mm;
  s.exit_pupil_radius_mm = 0.5 * p.exit_pupil_diameter_mm;
  return s;
}

// 1 / (image distance from the rear principal plane) for an object at w_P = 1 / (distance from the
// front principal plane), Gauss's lens equation in air, kept away from 0 (object in the front focal
// plane: image at infinity) so callers need no special case.
double inverse_image_distance(double efl_mm, double w_principal) {
  const double v = 1.0 / efl_mm - w_principal;
  constexpr double kTiny = 1e-12;
  if (std::abs(v) < kTiny) return v < 0.0 ? -kTiny : kTiny;
  return v;
}

}  // namespace

void CameraOptions::validate() const {
  if (!(focus_distance_m > 0.0) || std::isnan(focus_distance_m)) {
    throw OptionsError("focus distance must be > 0 m (+inf for infinity), got " + format_number(focus_distance_m));
  }
  if (f_number && !(std::isfinite(*f_number) && *f_number >= 0.5 && *f_number <= 512.0)) {
    throw OptionsError("f-number must be between 0.5 and 512, got " + format_number(*f_number));
  }
  framing.validate();
  if (!(reference_wavelength_nm >= kMinWavelengthNm && reference_wavelength_nm <= kMaxWavelengthNm)) {
    throw OptionsError("reference wavelength must lie in 380..780 nm, got " + format_number(reference_wavelength_nm));
  }
}

std::string CameraOptions::to_string() const {
  std::ostringstream os;
  os << "CameraOptions(focus " << focus_distance_m << " m, f/"
     << (f_number ? format_number(*f_number) : std::string("lens")) << ", " << framing.to_string() << ", reference "
     << reference_wavelength_nm << " nm)";
  return os.str();
}

std::string FirstOrderSample::to_string() const {
  std::ostringstream os;
  os.precision(8);
  os << "FirstOrderSample(" << wavelength_nm << " nm: EFL " << efl_mm << " mm, principal planes " << z_front_principal_mm
     << " / " << z_rear_principal_mm << " mm, EP " << z_entrance_pupil_mm << " mm r " << entrance_pupil_radius_mm
     << " mm, XP " << z_exit_pupil_mm << " mm r " << exit_pupil_radius_mm << " mm)";
  return os.str();
}

Camera Camera::thin_lens(double focal_length_mm, const CameraOptions& options, int width_px, int height_px) {
  options.validate();
  if (!(std::isfinite(focal_length_mm) && focal_length_mm > 0.0)) {
    throw OptionsError("thin-lens focal length must be a finite length > 0 mm, got " + format_number(focal_length_mm));
  }
  if (!options.f_number) throw OptionsError("a thin-lens camera needs an f-number (--fstop)");
  Camera c(PinholeFrame::from_options(width_px, height_px, options.framing, focal_length_mm));
  c.options_ = options;
  c.f_number_ = *options.f_number;
  c.design_f_number_ = c.f_number_;
  c.reference_nm_ = options.reference_wavelength_nm;
  ParaxialSample s;
  s.wavelength_nm = options.reference_wavelength_nm;
  s.efl_mm = focal_length_mm;
  s.entrance_pupil_diameter_mm = s.exit_pupil_diameter_mm = focal_length_mm / c.f_number_;
  c.samples_ = {s};
  c.finish();
  return c;
}

Camera Camera::thin_lens_for(const Prescription& lens, const CameraOptions& options, int width_px, int height_px) {
  const ParaxialSystem paraxial(lens);
  CameraOptions o = options;
  if (!o.f_number) o.f_number = paraxial.f_number();
  Camera c = thin_lens(paraxial.efl_mm(), o, width_px, height_px);
  try {
    c.real_lens_ = std::make_shared<const Camera>(from_lens(lens, o, width_px, height_px));
  } catch (const OptionsError&) {
    // An f-number beyond the lens's stop: the thin lens alone (IlluminationTable does not apply).
  } catch (const ComputationError&) {
  }
  return c;
}

std::optional<std::string> Camera::exact_model_only_for(const Prescription& lens) {
  if (const auto why = lens.why_not_rotationally_symmetric()) return *why;
  if (const int mirrors = lens.mirror_count(); mirrors > 0) return "it has " + std::to_string(mirrors) + " mirrors";
  if (camera_detail::has_central_obscuration(lens)) return std::string("it has a central obscuration");
  return std::nullopt;
}

Camera Camera::from_lens(const Prescription& lens, const CameraOptions& options, int width_px, int height_px) {
  options.validate();
  // What the camera takes (docs/bokeh.md, "Mirror and anamorphic lenses"): coaxial systems whose image faces
  // the way light left the scene. Tilts, decentres and an odd number of mirrors are not implemented yet: the
  // camera's first-order frame would have to follow the folded axis.
  const int mirrors = lens.mirror_count();
  if (!lens.is_coaxial()) {
    // A tilt-shift lens: elements turned or moved between a break and its inverse, the sensor square to the
    // camera's axis (moved across it, as a shifted image is). A folded or off-axis system whose image plane is
    // turned is not (not implemented).
    const SurfaceFrame image = surface_frames(lens, 0.0).image;
    const bool square = image.axes.isIdentity(1e-12);
    if (!square) {
      throw ComputationError("the bokeh camera takes tilted or decentred elements only between a coordinate break and its inverse "
                             "(a tilt-shift lens, its sensor square to the axis); this system's image plane is turned (" +
                             *lens.why_not_rotationally_symmetric() + "): it is read, traced and analysed, but not photographed "
                             "through (not implemented)");
    }
  }
  if (mirrors % 2 == 1) {
    throw ComputationError("the bokeh camera does not take a lens with an odd number of mirrors yet (" + std::to_string(mirrors) +
                           "): its image faces back toward the scene (not implemented)");
  }
  const std::optional<std::string> exact_only = exact_model_only_for(lens);
  // A camera's pupil is where its stop images, at its f-number: a lens file's object-space telecentric
  // flag (a measuring lens's) is dropped.
  Prescription as_camera = lens;
  as_camera.object_space_telecentric = false;
  const ParaxialSystem own(as_camera);
  if (!(own.efl_mm() > 0.0)) {
    throw ComputationError("the bokeh renderer needs a lens that forms a real image (EFL > 0); this one has EFL " +
                           format_number(own.efl_mm()) + " mm");
  }
  auto at_f_number = std::make_shared<Prescription>(as_camera);
  const double n = options.f_number.value_or(own.f_number());
  at_f_number->aperture = ApertureSpec{ApertureSpec::Kind::ImageSpaceFNumber, n};
  // The stop's clear aperture follows the f-number (an iris), so the exact tracer clips the beam
  // that the paraxial pupils describe; the other clear apertures stay as prescribed (vignetting).
  const ParaxialSystem at_n(*at_f_number);
  const StopOpening opening = stop_opened_to_f_number(as_camera, n);
  const std::size_t stop = static_cast<std::size_t>(opening.surface - 1);
  const double stop_mm = opening.semi_diameter_mm;
  const double widest_stop_mm = at_f_number->surfaces[stop].max_semi_diameter_mm();
  if (stop_mm > widest_stop_mm) {
    // Marginal heights scale as 1 / N: the stop is as wide as its surface at N stop_mm / widest.
    throw OptionsError("f/" + format_rounded(n, 3) + " needs a stop " + format_rounded(stop_mm, 4) + " mm in radius, but surface " +
                       std::to_string(stop + 1) + " (the stop) can be at most " + format_rounded(widest_stop_mm, 4) +
                       " mm wide for its curvature: the fastest f-number this lens can be opened to is f/" +
                       format_rounded(std::ceil(n * stop_mm / widest_stop_mm * 100.0) / 100.0, 4) + " (its design aperture is f/" +
                       format_rounded(own.f_number(), 3) + ")");
  }
  at_f_number->surfaces[stop].semi_diameter_mm = stop_mm;
  at_f_number->surfaces[stop].aperture.reset();
  // A camera is a physical lens: its glass ends at each surface's semi-diameter, so every one clips,
  // also where a lens file gives it as a size only (a Zemax DIAM; docs/lens-format.md, "Apertures").
  for (Surface& s : at_f_number->surfaces) s.clips_rays = true;

  Camera c(PinholeFrame::from_options(width_px, height_px, options.framing, own.efl_mm()));
  c.options_ = options;
  c.f_number_ = n;
  c.design_f_number_ = own.f_number();
  c.reference_nm_ = options.reference_wavelength_nm;
  c.pupil_orientation_ = at_n.exit_pupil().magnification * at_n.entrance_pupil().magnification < 0.0 ? -1.0 : 1.0;
  SpectralTableOptions table_options;
  table_options.min_wavelength_nm = kMinWavelengthNm;
  table_options.max_wavelength_nm = kMaxWavelengthNm;
  table_options.samples = kWavelengthSamples;
  table_options.object_distance_mm = kInfinity;
  c.samples_ = ParaxialSpectralTable(*at_f_number, table_options).samples();
  c.lens_ = std::move(at_f_number);
  c.exact_model_only_ = exact_only;
  if (lens.is_anamorphic()) {
    // The x section frames x (finish()): its own focal length and principal planes, the y section's
    // perspective centre (the picture's pinhole).
    ParaxialOptions x;
    x.wavelength_nm = c.reference_nm_;
    x.object_distance_mm = kInfinity;
    x.section = Section::X;
    std::optional<ParaxialSystem> xs;
    try {
      xs.emplace(*c.lens_, x);
    } catch (const ComputationError& e) {
      throw ComputationError(std::string("the bokeh camera needs an anamorphic lens whose x section forms an image too: ") + e.what());
    }
    if (!(xs->efl_mm() > 0.0)) {
      throw ComputationError("the bokeh camera needs an anamorphic lens whose x section forms a real image (EFL_x > 0); this one has EFL_x " +
                             format_number(xs->efl_mm()) + " mm");
    }
    FirstOrderSample s;
    s.wavelength_nm = c.reference_nm_;
    s.efl_mm = xs->efl_mm();
    s.z_front_principal_mm = xs->z_front_principal_mm();
    s.z_rear_principal_mm = xs->z_rear_principal_mm();
    s.z_entrance_pupil_mm = xs->entrance_pupil().z_mm;
    s.z_exit_pupil_mm = xs->exit_pupil().z_mm;
    s.entrance_pupil_radius_mm = 0.5 * xs->entrance_pupil().diameter_mm;
    s.exit_pupil_radius_mm = 0.5 * xs->exit_pupil().diameter_mm;
    c.x_section_ = s;
  }
  c.finish();
  // The marginal ray from the axial point of the focus plane at N = n: its heights scale as n / N,
  // so the first clear aperture (the stop aside) it fills sets the fastest unclipped N.
  ParaxialOptions at_focus;
  at_focus.wavelength_nm = c.reference_nm_;
  at_focus.object_distance_mm = std::isinf(c.focus_mm_) ? kInfinity : std::max(1.0, c.focus_mm_ - c.z_perspective_mm_);
  const ParaxialSystem focused(*c.lens_, at_focus);
  for (std::size_t k = 0; k < c.lens_->surfaces.size(); ++k) {
    const std::optional<double>& r = lens.surfaces[k].semi_diameter_mm;
    if (k == stop || !r || !(*r > 0.0)) continue;
    c.fastest_unclipped_f_number_ = std::max(c.fastest_unclipped_f_number_, n * std::abs(focused.marginal_ray().rows[k].y_mm) / *r);
  }
  return c;
}

double Camera::min_wavelength_nm() const { return samples_.front().wavelength_nm; }
double Camera::max_wavelength_nm() const { return samples_.back().wavelength_nm; }

FirstOrderSample Camera::first_order(double wavelength_nm) const {
  if (samples_.size() == 1) {
    FirstOrderSample s = first_order_from(samples_.front());
    s.wavelength_nm = wavelength_nm;
    return s;
  }
  const double lo = samples_.front().wavelength_nm, hi = samples_.back().wavelength_nm;
  const double u = std::clamp((wavelength_nm - lo) / (hi - lo), 0.0, 1.0) * static_cast<double>(samples_.size() - 1);
  const std::size_t i = std::min(static_cast<std::size_t>(u), samples_.size() - 2);
  return first_order_from(interpolate(samples_[i], samples_[i + 1], u - static_cast<double>(i)));
}

GaussianImage Camera::gaussian_image(const ScenePoint& p, const FirstOrderSample& s) const {
  // Object at depth 1/w in front of the perspective centre; Delta = front principal plane minus
  // perspective centre, so 1 / (object distance from the front principal plane) = w / (1 + Delta w).
  const double w = p.inverse_depth_per_mm;
  const double scale = 1.0 / (1.0 + (s.z_front_principal_mm - z_perspective_mm_) * w);
  const double image_distance = 1.0 / inverse_image_distance(s.efl_mm, w * scale);
  // Height: m X with m = -s_i / s_o and X = tan * depth, i.e. -s_i * tan * scale (finite at w = 0).
  return {-image_distance * p.tan_x * scale, -image_distance * p.tan_y * scale, s.z_rear_principal_mm + image_distance};
}

void Camera::finish() {
  focus_mm_ = mm_from_m(options_.focus_distance_m);
  reference_first_order_ = first_order(reference_nm_);
  const FirstOrderSample& ref = reference_first_order_;
  z_perspective_mm_ = ref.z_entrance_pupil_mm;
  const double w_focus = inverse_per_mm(focus_mm_);
  const double scale = 1.0 / (1.0 + (ref.z_front_principal_mm - z_perspective_mm_) * w_focus);
  if (!(scale > 0.0) || 1.0 / ref.efl_mm - w_focus * scale <= 0.0) {
    throw ComputationError("cannot focus at " + format_rounded(options_.focus_distance_m, 6) +
                           " m: the plane is not beyond the front focal point (EFL " + format_rounded(ref.efl_mm, 5) +
                           " mm): focus farther away");
  }
  const GaussianImage focus_image = gaussian_image({1.0, 0.0, w_focus}, ref);
  z_sensor_mm_ = focus_image.z_mm;
  // focus_image.x_mm is the sensor height of tangent 1 on the focus plane.
  px_per_sensor_mm_ = frame_.focal_length_px() / focus_image.x_mm;
  px_per_sensor_mm_x_ = px_per_sensor_mm_;
  if (x_section_) {
    // The x section images the focus plane with its own magnification, and perhaps a little before or
    // behind the sensor: its chief ray (through its exit pupil's centre) meets the sensor at the height
    // the blurred image of the point is centred on.
    const GaussianImage gx = gaussian_image({1.0, 0.0, w_focus}, *x_section_);
    const double to_pupil = gx.z_mm - x_section_->z_exit_pupil_mm;
    const double x_on_sensor = to_pupil == 0.0 ? gx.x_mm : gx.x_mm * (z_sensor_mm_ - x_section_->z_exit_pupil_mm) / to_pupil;
    if (!(std::abs(x_on_sensor) > 0.0) || !std::isfinite(x_on_sensor)) {
      throw ComputationError("the anamorphic lens's x section images the focus plane at infinity: no x framing (focus elsewhere)");
    }
    px_per_sensor_mm_x_ = frame_.focal_length_px() / x_on_sensor;
  }
}

std::optional<double> Camera::x_section_focus_distance_mm() const {
  if (!x_section_) return std::nullopt;
  // Gauss between the x principal planes: 1 / s_o = 1 / f - 1 / s_i, s_o from the front principal plane,
  // which lies Delta = z_front_principal - z_perspective behind the perspective centre (gaussian_image).
  const FirstOrderSample& x = *x_section_;
  const double inverse_object = 1.0 / x.efl_mm - 1.0 / (z_sensor_mm_ - x.z_rear_principal_mm);
  if (!(inverse_object > 0.0)) return kInfinity;
  return 1.0 / inverse_object - (x.z_front_principal_mm - z_perspective_mm_);
}

double Camera::signed_coc_px(double inverse_depth_per_mm) const {
  const FirstOrderSample& ref = reference_first_order_;
  const GaussianImage g = gaussian_image({0.0, 0.0, inverse_depth_per_mm}, ref);
  const double to_pupil = g.z_mm - ref.z_exit_pupil_mm;
  if (to_pupil == 0.0) return 0.0;
  return 2.0 * ref.exit_pupil_radius_mm * (g.z_mm - z_sensor_mm_) / to_pupil * std::abs(px_per_sensor_mm_);
}

std::string Camera::to_string() const {
  std::ostringstream os;
  os.precision(8);
  os << "Camera(" << (lens_ ? "lens '" + lens_->name + "'" : std::string("thin lens")) << ", f/" << f_number_
     << ", focus " << focus_mm_ << " mm, sensor at z " << z_sensor_mm_ << " mm, perspective centre at z "
     << z_perspective_mm_ << " mm, " << px_per_sensor_mm_ << " px per sensor mm, " << frame_.to_string() << ")";
  return os.str();
}

}  // namespace lensmith

#include "lensmith/camera/ray_model.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "model_implementations.h"

namespace lensmith {

double passing_share(double clearance_a, double clearance_b, double clearance_c) {
  const double a = clearance_a, b = clearance_b, c = clearance_c;
  const int positive = (a >= 0.0) + (b >= 0.0) + (c >= 0.0);
  if (positive == 3) return 1.0;
  if (positive == 0) return 0.0;
  // Order so that `lone` is the corner alone on its side.
  double lone = a, u = b, v = c;
  const bool lone_positive = positive == 1;
  if ((b >= 0.0) == lone_positive) {
    lone = b, u = a, v = c;
  } else if ((c >= 0.0) == lone_positive) {
    lone = c, u = a, v = b;
  }
  const double corner = lone * lone / ((lone - u) * (lone - v));
  return lone_positive ? corner : 1.0 - corner;
}

std::string_view to_string(RayModelKind kind) {
  switch (kind) {
    case RayModelKind::Thin: return "thin";
    case RayModelKind::Paraxial: return "paraxial";
    case RayModelKind::Seidel: return "seidel";
    case RayModelKind::Poly: return "poly";
    case RayModelKind::Exact: return "exact";
  }
  return "unknown";
}

RayModelKind parse_ray_model_kind(std::string_view text) {
  for (RayModelKind k :
       {RayModelKind::Thin, RayModelKind::Paraxial, RayModelKind::Seidel, RayModelKind::Poly, RayModelKind::Exact}) {
    if (text == to_string(k)) return k;
  }
  throw OptionsError("unknown ray model '" + std::string(text) + "': expected thin, paraxial, seidel, poly or exact");
}

std::string_view to_string(SeidelCoefficients source) { return source == SeidelCoefficients::Fitted ? "fitted" : "sums"; }

SeidelCoefficients parse_seidel_coefficients(std::string_view text) {
  if (text == "fitted") return SeidelCoefficients::Fitted;
  if (text == "sums") return SeidelCoefficients::Sums;
  throw OptionsError("unknown Seidel coefficient source '" + std::string(text) + "': expected fitted or sums");
}

std::string RayModel::to_string() const {
  return std::string(lensmith::to_string(kind())) + " model, " + camera_.to_string();
}

void RayModelOptions::validate() const {
  if (!(std::isfinite(nearest_depth_m) && nearest_depth_m > 0.0)) {
    throw OptionsError("nearest scene depth must be a finite distance > 0 m, got " + format_number(nearest_depth_m));
  }
  if (seidel_distance_samples < 2) throw OptionsError("the Seidel table needs at least 2 object distances");
}

LensFitOptions lens_fit_options_for(const Camera& camera) {
  LensFitOptions o;
  o.f_number = camera.f_number();
  // The frame's corner on the camera's sensor; the fit's own sensor plane (the paraxial focus for
  // infinity) sees it about as far out, and the margin covers the difference.
  // A tilt-shift lens's frame measured from its core's axis (a shift moves it across the image circle).
  constexpr double kFrameMargin = 1.15;
  const double reach_mm = camera.is_thin_lens()
                              ? 0.5 * std::hypot(camera.frame().width_px(), camera.frame().height_px()) / std::abs(camera.px_per_sensor_mm())
                              : camera_detail::CorePlacement::of(camera).frame_reach_mm(camera);
  o.image_radius_mm = std::max(LensFitOptions::kDefaultImageRadiusMm, kFrameMargin * reach_mm);
  return o;
}

void require_poly_model_lens(const Camera& camera) {
  if (camera.is_thin_lens()) return;  // make_ray_model says what the poly model needs
  // A fit takes anamorphic lenses (their maps in the component form), mirror lenses with their central
  // obscurations and tilt-shift lenses (their coaxial core) too; what it cannot fit is refused with its reason.
  const Prescription& lens = *camera.lens();
  if (const auto why = LensFit::why_not_fittable(lens)) {
    throw OptionsError("the poly model cannot fit this lens: " + *why + ": use the exact model (--model exact)");
  }
}

double chief_ray_image_area(const RayModel& model, const PixelPoint& at, double inverse_depth_per_mm, double step_px) {
  const Camera& camera = model.camera();
  const std::array<PixelPoint, 3> in{at, PixelPoint{at.x + step_px, at.y}, PixelPoint{at.x, at.y + step_px}};
  std::array<PixelPoint, 3> out{};
  constexpr std::array<PupilPoint, 1> kChief{{{0.0, 0.0}}};
  for (std::size_t k = 0; k < in.size(); ++k) {
    const Tangents t = camera.frame().tangents_at(in[k]);
    std::array<SensorHit, 1> hit;
    model.map(ScenePoint{t.x, t.y, inverse_depth_per_mm}, camera.reference_wavelength_nm(), kChief, hit);
    if (!(hit[0].ok || hit[0].unclipped)) return 0.0;  // a blocked chief ray still lands where it would
    out[k] = camera.output_pixel(hit[0].x_mm, hit[0].y_mm);
  }
  const double det = (out[1].x - out[0].x) * (out[2].y - out[0].y) - (out[1].y - out[0].y) * (out[2].x - out[0].x);
  return std::isfinite(det) ? std::abs(det) / (step_px * step_px) : 0.0;
}

std::unique_ptr<RayModel> make_ray_model(RayModelKind kind, const Camera& camera, const RayModelOptions& options) {
  options.validate();
  if (kind == RayModelKind::Thin) {
    if (!camera.is_thin_lens()) {
      throw OptionsError("the thin model needs a thin-lens camera (Camera::thin_lens with the lens's EFL)");
    }
    return std::make_unique<camera_detail::ReferenceSphereModel>(kind, camera, options);
  }
  if (camera.is_thin_lens()) {
    throw OptionsError("the " + std::string(to_string(kind)) + " model needs a lens prescription, not a thin lens");
  }
  if (kind == RayModelKind::Exact) return std::make_unique<camera_detail::ExactModel>(camera);
  if (kind == RayModelKind::Poly) {
    require_poly_model_lens(camera);
  } else if (camera.exact_model_only()) {
    throw OptionsError("the " + std::string(to_string(kind)) + " model assumes a rotationally symmetric refracting lens with a round "
                       "aperture, and this one is not (" + *camera.exact_model_only() + "): use the exact model (--model exact)");
  }
  if (kind == RayModelKind::Poly) {
    auto fit = options.fit ? options.fit : std::make_shared<const LensFit>(LensFit::fit(*camera.lens(), lens_fit_options_for(camera)));
    return std::make_unique<camera_detail::PolyModel>(camera, std::move(fit));
  }
  return std::make_unique<camera_detail::ReferenceSphereModel>(kind, camera, options);
}

}  // namespace lensmith

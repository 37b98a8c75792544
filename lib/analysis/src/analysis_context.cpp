// The shared set-up of the real-ray analyses: tracers with and without aperture clipping, their ray
// aimers, the field points and the wavelengths.
#include "lensmith/analysis/analysis_context.h"

#include <cmath>
#include <cstdio>

#include "lensmith/core/errors.h"

namespace lensmith {

namespace {

std::string format_number(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

TracerOptions tracer_options(const AnalysisOptions& options, bool clip) {
  TracerOptions t;
  t.image_plane = options.image_plane;
  t.clip_apertures = clip;
  return t;
}

}  // namespace

void RayLossCount::add(RayStatus status) {
  switch (status) {
    case RayStatus::Ok: break;
    case RayStatus::Vignetted: ++vignetted; break;
    case RayStatus::Missed: ++missed; break;
    case RayStatus::TotalInternalReflection: ++total_internal_reflection; break;
    case RayStatus::NotConverged: ++not_converged; break;
    case RayStatus::InvalidInput: ++invalid_input; break;
  }
}

RayLossCount& RayLossCount::operator+=(const RayLossCount& other) {
  vignetted += other.vignetted;
  missed += other.missed;
  total_internal_reflection += other.total_internal_reflection;
  not_converged += other.not_converged;
  invalid_input += other.invalid_input;
  return *this;
}

std::string RayLossCount::to_string() const {
  if (total() == 0) return "none lost";
  std::string s = std::to_string(total()) + " lost:";
  const char* sep = " ";
  auto part = [&](std::size_t n, const char* what) {
    if (n == 0) return;
    s += sep + std::to_string(n) + " " + what;
    sep = ", ";
  };
  part(vignetted, "vignetted");
  part(missed, "missed");
  part(total_internal_reflection, "tir");
  part(not_converged, "not converged");
  part(invalid_input, "invalid");
  return s;
}

void AnalysisOptions::validate() const {
  if (relative_fields.empty()) throw OptionsError("AnalysisOptions::relative_fields is empty: give at least one field");
  for (std::size_t i = 0; i < relative_fields.size(); ++i) {
    const double f = relative_fields[i];
    if (!(f >= 0.0 && f <= 1.0)) {
      throw OptionsError("AnalysisOptions::relative_fields[" + std::to_string(i) + "] = " + format_number(f, 6) +
                         ": must lie in [0, 1] (a fraction of the maximum field)");
    }
  }
  for (std::size_t i = 0; i < wavelengths_nm.size(); ++i) {
    const double w = wavelengths_nm[i];
    if (!(w > 100.0 && w < 20000.0)) {
      throw OptionsError("AnalysisOptions::wavelengths_nm[" + std::to_string(i) + "] = " + format_number(w, 4) +
                         ": must lie in (100, 20000) nm");
    }
  }
  if (max_field_angle_deg && !(*max_field_angle_deg > 0.0 && *max_field_angle_deg < 90.0)) {
    throw OptionsError("AnalysisOptions::max_field_angle_deg = " + format_number(*max_field_angle_deg, 6) +
                       ": must lie in (0, 90) degrees");
  }
}

struct AnalysisContext::Impl {
  Impl(const Prescription& lens, const AnalysisOptions& options)
      : clipped(lens, tracer_options(options, true)),
        unclipped(lens, tracer_options(options, false)),
        aimer(clipped, aim_options(lens, options)),
        unclipped_aimer(unclipped, aim_options(lens, options)) {}
  static AimOptions aim_options(const Prescription& lens, const AnalysisOptions& options) {
    AimOptions a;
    a.aiming = options.aiming.value_or(lens.ray_aiming);
    a.use_vignetting_factors = options.use_vignetting_factors;
    return a;
  }
  // The aimers keep references to the tracers: Impl lives on the heap and never moves.
  SequentialTracer clipped;
  SequentialTracer unclipped;
  RayAimer aimer;
  RayAimer unclipped_aimer;
};

AnalysisContext::AnalysisContext(const Prescription& lens, const AnalysisOptions& options) : options_(options) {
  options_.validate();
  lens.validate();
  impl_ = std::make_unique<Impl>(lens, options_);

  wavelengths_nm_ = options_.wavelengths_nm.empty() ? lens.wavelengths_nm : options_.wavelengths_nm;
  reference_wavelength_nm_ = wavelengths_nm_.front();
  for (double w : wavelengths_nm_) {
    if (w == lens.primary_wavelength_nm()) reference_wavelength_nm_ = w;
  }

  if (options_.max_field_angle_deg || !lens.field) {
    field_unit_ = "deg";
  } else {
    field_unit_ = lens.field->kind == FieldSpec::Kind::AngleDeg ? "deg" : "mm";
  }
  for (double f : options_.relative_fields) {
    if (f > 0.0 && !has_field()) {
      throw OptionsError("the lens \"" + lens.name + "\" states no field: give the field angle that relative field 1 means "
                         "(--field-angle DEG), or analyse on axis only");
    }
  }
}

AnalysisContext::AnalysisContext(AnalysisContext&&) noexcept = default;
AnalysisContext& AnalysisContext::operator=(AnalysisContext&&) noexcept = default;
AnalysisContext::~AnalysisContext() = default;

const Prescription& AnalysisContext::lens() const { return impl_->clipped.lens(); }
const SequentialTracer& AnalysisContext::tracer() const { return impl_->clipped; }
const RayAimer& AnalysisContext::aimer() const { return impl_->aimer; }
const ParaxialSystem& AnalysisContext::paraxial() const { return impl_->aimer.paraxial(); }

bool AnalysisContext::has_field() const {
  if (options_.max_field_angle_deg) return true;
  const auto& field = lens().field;
  return field && field->max_value() > 0.0;
}

FieldPoint AnalysisContext::field_at(double relative) const {
  if (options_.max_field_angle_deg) return FieldPoint::angle_deg(relative * *options_.max_field_angle_deg);
  if (relative == 0.0 && !has_field()) return FieldPoint::angle_deg(0.0);
  if (!has_field()) {
    throw OptionsError("the lens \"" + lens().name + "\" states no field: give the field angle that relative field 1 means "
                       "(--field-angle DEG)");
  }
  return impl_->aimer.field_at(relative);
}

double AnalysisContext::field_value(double relative) const {
  if (options_.max_field_angle_deg) return relative * *options_.max_field_angle_deg;
  if (!has_field()) return 0.0;
  return relative * lens().field->max_value();
}

std::string AnalysisContext::field_label(double relative) const {
  std::string label = format_number(field_value(relative), 2) + " " + field_unit_;
  if (!options_.max_field_angle_deg && lens().field) {
    if (lens().field->kind == FieldSpec::Kind::ObjectHeightMm) label += " object height";
    if (lens().field->kind == FieldSpec::Kind::ImageHeightMm) label += " image height";
  }
  return label;
}

namespace {

TracedRay aim_and_trace(const RayAimer& aimer, const SequentialTracer& tracer, const FieldPoint& field,
                        const PupilCoordinate& pupil, double wavelength_nm, std::vector<SurfaceHit>* path) {
  TracedRay out;
  const AimedRay aimed = aimer.make_ray(field, pupil, wavelength_nm);
  out.object_ray = aimed.ray;
  if (!aimed.ok()) {
    out.status = aimed.status;
    out.surface = aimed.surface;
    if (path) path->clear();
    return out;
  }
  const TraceResult result = tracer.trace_forward(aimed.ray, path);
  out.status = result.status;
  out.surface = result.surface;
  out.image_ray = result.ray;
  out.optical_path_mm = result.optical_path_mm;
  return out;
}

}  // namespace

TracedRay AnalysisContext::trace(const FieldPoint& field, const PupilCoordinate& pupil, double wavelength_nm,
                                 std::vector<SurfaceHit>* path) const {
  return aim_and_trace(impl_->aimer, impl_->clipped, field, pupil, wavelength_nm, path);
}

TracedRay AnalysisContext::trace_unclipped(const FieldPoint& field, const PupilCoordinate& pupil, double wavelength_nm) const {
  return aim_and_trace(impl_->unclipped_aimer, impl_->unclipped, field, pupil, wavelength_nm, nullptr);
}

TracedRay AnalysisContext::reference_ray(const FieldPoint& field, double wavelength_nm) const {
  TracedRay ray = aim_and_trace(impl_->unclipped_aimer, impl_->unclipped, field, {0.0, 0.0}, wavelength_nm, nullptr);
  if (!ray.ok()) {
    throw ComputationError("field " + field.to_string() + ", " + format_number(wavelength_nm, 2) +
                           " nm: the chief ray cannot reach the image plane (" + std::string(to_string(ray.status)) +
                           (ray.surface > 0 ? " at surface " + std::to_string(ray.surface) : std::string()) +
                           "); the field lies beyond what this lens can image");
  }
  return ray;
}

const AnalysisContext& whole_pupil(const AnalysisContext& context, std::optional<AnalysisContext>& storage) {
  const auto& field = context.lens().field;
  if (!context.options().use_vignetting_factors || !field || field->vignetting.empty()) return context;
  AnalysisOptions whole = context.options();
  whole.use_vignetting_factors = false;
  storage.emplace(context.lens(), whole);
  return *storage;
}

}  // namespace lensmith

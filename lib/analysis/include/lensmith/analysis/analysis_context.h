// The set-up every real-ray analysis shares: an exact tracer and a ray aimer for the lens, the field
// points (relative to the prescription's maximum field, or to an explicit field angle), the
// wavelengths and the reference (primary) wavelength. Analyses are lensmith/analysis/*.h.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "lensmith/trace/ray_aiming.h"
#include "lensmith/trace/sequential_tracer.h"

namespace lensmith {

struct AnalysisOptions {
  // Field points as fractions of the maximum field, each in [0, 1] (0 = on axis, 1 = full field).
  std::vector<double> relative_fields{0.0, 0.7, 1.0};
  // Wavelengths, nm, each in (100, 20000); empty = the prescription's wavelengths.
  std::vector<double> wavelengths_nm;
  // Object-space half field angle that relative field 1 stands for, deg, in (0, 90). Overrides the
  // prescription's field; required for off-axis fields when the prescription has none.
  std::optional<double> max_field_angle_deg;
  // Empty: the aiming the lens file asks for (Prescription::ray_aiming: paraxial entrance pupil,
  // OpticStudio's "ray aiming off", unless a Zemax RAIM line or a CODE V file asks for real aiming).
  // lensmith clips rays at every clear aperture, so where the pupil has spherical aberration the
  // outermost paraxially aimed rays can be cut by a clipping stop even on axis (they are counted as
  // vignetted); RealStop fills the real stop exactly.
  std::optional<RayAiming> aiming;
  // Sample each field's vignetted pupil where the lens's field carries vignetting factors (OpticStudio's
  // VDX/VDY/VCX/VCY/VAN), as OpticStudio's spots, fans and ray traces do. Analyses that measure the
  // vignetting itself (relative illumination, pupil shape) sample the whole pupil whatever this says.
  bool use_vignetting_factors = true;
  // Where rays are evaluated: the prescription's image plane or the paraxial focus (primary).
  TracerOptions::ImagePlane image_plane = TracerOptions::ImagePlane::AsPrescribed;

  // Throws OptionsError naming the field and the violated constraint.
  void validate() const;
};

// The global-frame point where a ray meets the image plane, mm (frame of `lensmith info --json`).
struct ImagePoint {
  double x_mm = 0.0;
  double y_mm = 0.0;
  double z_mm = 0.0;
  static ImagePoint from(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }
};

// Rays that did not reach the image plane, by reason. Analyses exclude them from their statistics
// and report these counts; a dead ray is never counted as a zero.
struct RayLossCount {
  std::size_t vignetted = 0;
  std::size_t missed = 0;
  std::size_t total_internal_reflection = 0;
  std::size_t not_converged = 0;
  std::size_t invalid_input = 0;
  void add(RayStatus status);  // Ok is ignored
  std::size_t total() const { return vignetted + missed + total_internal_reflection + not_converged + invalid_input; }
  RayLossCount& operator+=(const RayLossCount& other);
  std::string to_string() const;  // "12 lost: 10 vignetted, 2 missed" or "none lost"
};

// A ray made from a field point and a pupil coordinate and traced to the image plane.
struct TracedRay {
  RayStatus status = RayStatus::Ok;  // why it died (aiming failures included)
  int surface = 0;                   // 1-based surface where it died; 0 when ok
  Ray object_ray;                    // the ray as aimed in object space
  Ray image_ray;                     // at the image plane when ok
  // Optical path from the aimed ray's start to the image plane, mm (n x length): the rays of one field
  // start on one wavefront (docs/trace.md, "Optical path"), so differences are OPDs.
  double optical_path_mm = 0.0;
  bool ok() const { return status == RayStatus::Ok; }
};

class AnalysisContext {
 public:
  // Throws OptionsError (bad options, or off-axis fields requested for a lens without a field and
  // no max_field_angle_deg), PrescriptionError, ComputationError (e.g. afocal lens).
  AnalysisContext(const Prescription& lens, const AnalysisOptions& options = {});
  AnalysisContext(AnalysisContext&&) noexcept;
  AnalysisContext& operator=(AnalysisContext&&) noexcept;
  ~AnalysisContext();

  const Prescription& lens() const;
  const AnalysisOptions& options() const { return options_; }
  // Tracer and aimer that clip rays at clear semi-diameters (what the lens really passes).
  const SequentialTracer& tracer() const;
  const RayAimer& aimer() const;
  // Paraxial system at the reference wavelength, the prescription's object distance.
  const ParaxialSystem& paraxial() const;

  const std::vector<double>& wavelengths_nm() const { return wavelengths_nm_; }
  // The prescription's primary wavelength when it is analysed, else the first analysed one (nm):
  // chief rays of this wavelength are the reference of fans and spots.
  double reference_wavelength_nm() const { return reference_wavelength_nm_; }
  const std::vector<double>& relative_fields() const { return options_.relative_fields; }

  // True when off-axis fields can be analysed (the prescription has a field, or one was given).
  bool has_field() const;
  // The field point at `relative` times the maximum field, along +y. Throws OptionsError when the
  // field is off axis and the lens has no field (message says to pass a field angle).
  FieldPoint field_at(double relative) const;
  // The field at `relative` in the prescription's field unit, and that unit ("deg" or "mm").
  double field_value(double relative) const;
  const std::string& field_unit() const { return field_unit_; }
  // "14.00 deg", "0.0 deg (on axis)".
  std::string field_label(double relative) const;

  // Aims and traces one ray (clipping at apertures). Never throws for a dead ray.
  TracedRay trace(const FieldPoint& field, const PupilCoordinate& pupil, double wavelength_nm,
                  std::vector<SurfaceHit>* path = nullptr) const;
  // The chief ray (pupil centre) traced without aperture clipping: the reference of every
  // aberration measure. Throws ComputationError naming the field and the reason when even the
  // unclipped chief ray cannot reach the image plane.
  TracedRay reference_ray(const FieldPoint& field, double wavelength_nm) const;
  // Aims and traces one ray without aperture clipping (for derivatives near a clipped ray).
  TracedRay trace_unclipped(const FieldPoint& field, const PupilCoordinate& pupil, double wavelength_nm) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  AnalysisOptions options_;
  std::vector<double> wavelengths_nm_;
  double reference_wavelength_nm_ = 0.0;
  std::string field_unit_;
};

// `context` itself, or, when it applies the lens file's vignetting factors, an equal context in `storage`
// that samples the whole pupil: for the analyses that measure vignetting (illumination, pupil shape).
const AnalysisContext& whole_pupil(const AnalysisContext& context, std::optional<AnalysisContext>& storage);

}  // namespace lensmith

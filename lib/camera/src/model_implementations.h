// The ray models behind make_ray_model (private to the camera layer).
#pragma once

#include <memory>
#include <optional>

#include "lensmith/camera/ray_model.h"
#include "lensmith/polyfit/lens_fit.h"
#include "lensmith/seidel/aberration_table.h"
#include "lensmith/trace/sequential_tracer.h"

namespace lensmith::camera_detail {

// thin, paraxial and seidel: the ray from the exit-pupil point towards the Gaussian image point,
// through the aberrated image point for seidel (Asberg's construction with the Gaussian reference
// sphere centred on the Gaussian image point and passing through the exit-pupil centre).
class ReferenceSphereModel final : public RayModel {
 public:
  ReferenceSphereModel(RayModelKind kind, const Camera& camera, const RayModelOptions& options);
  RayModelKind kind() const override { return kind_; }
  bool affine_in_pupil() const override { return kind_ != RayModelKind::Seidel; }
  void map(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil,
           std::span<SensorHit> hits) const override;

 private:
  RayModelKind kind_;
  std::optional<AberrationTable> table_;  // seidel only
};

// exact: rays traced through the prescription (stop at the camera's f-number), aimed at the stop.
class ExactModel final : public RayModel {
 public:
  explicit ExactModel(const Camera& camera);
  RayModelKind kind() const override { return RayModelKind::Exact; }
  bool affine_in_pupil() const override { return false; }
  void map(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil,
           std::span<SensorHit> hits) const override;

 private:
  std::shared_ptr<const SequentialTracer> clipped_;  // clear apertures clip: the final trace
  std::shared_ptr<const SequentialTracer> free_;     // no clipping: the aiming traces
  int stop_surface_ = 0;                             // 1-based
  double stop_radius_mm_ = 0.0;
  double z_stop_mm_ = 0.0;
};

// poly: a polynomial fit of the lens (lens_fit.h). Each pupil point is aimed by Newton steps on the
// fit's outer -> stop map from the scene point, then carried to the sensor by the outer -> sensor map
// and a straight line from the fit's sensor plane to the camera's; clipping by the fitted positions on
// the clear apertures and the stop at the camera's f-number.
class PolyModel final : public RayModel {
 public:
  PolyModel(const Camera& camera, std::shared_ptr<const LensFit> fit);
  RayModelKind kind() const override { return RayModelKind::Poly; }
  bool affine_in_pupil() const override { return false; }
  void map(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil,
           std::span<SensorHit> hits) const override;

 private:
  std::shared_ptr<const LensFit> fit_;
  double stop_radius_mm_ = 0.0;
};

}  // namespace lensmith::camera_detail

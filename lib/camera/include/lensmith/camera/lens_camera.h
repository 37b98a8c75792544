// Primary rays for a path tracer, through a real lens: for a point of the film and a sample of the
// pupil, the ray that leaves the front of the lens into the scene and the weight that makes the
// image radiometrically right. The way to put a lens of lensmith into a renderer of one's own
// (docs/lens-camera.md, examples/lens_camera).
//
// Method (pbrt-v4's RealisticCamera, with lensmith's Camera for where the sensor sits): the pupil
// sample picks a point of a disc 1.15 times the paraxial exit pupil at that wavelength; the ray from
// the film point towards it is traced backward through every surface and clear aperture (the exact
// sequential tracer) or through a polynomial fit of the lens (LensFit::from_sensor; clipped by the
// fitted crossings of the clipping surfaces). Where it passes, its weight is cos^4(theta) / D^2 times
// the sampled disc's area, divided by the same integral taken over the real on-axis beam of the
// film's centre: so the mean of weight x radiance over uniform pupil samples is the film point's
// irradiance in units where a uniform surface in focus at the centre of the frame gives its
// radiance, and the frame falls off as the lens's relative illumination (cos^4-type falloff,
// vignetting, pupil aberration). Weights at other wavelengths than those given at construction are
// interpolated linearly between them.
//
// Frames. Film: the camera's sensor plane, x right and y up in mm from the optical axis; the film
// point of output pixel (x, y) (pixel centres at + 0.5) is ((x - W / 2) / p, (H / 2 - y) / p) with p
// = Camera::px_per_sensor_mm(), as lensmith bokeh and lensmith scene render use it. Rays: the camera
// frame of lensmith bokeh, in metres: origin at the entrance pupil (the perspective centre at the
// reference wavelength), x right, y up, z forward along the optical axis (planar depth).
#pragma once

#include <memory>
#include <optional>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "lensmith/camera/camera.h"
#include "lensmith/polyfit/lens_fit.h"
#include "lensmith/trace/sequential_tracer.h"

namespace lensmith {

struct CameraRay {
  Eigen::Vector3d origin_m{0.0, 0.0, 0.0};  // where it leaves the front surface, camera frame, metres
  Eigen::Vector3d direction{0.0, 0.0, 1.0};  // unit, into the scene (+z forward)
  double weight = 0.0;                        // radiometric weight (file comment), > 0
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const CameraRay& r) { return os << r.to_string(); }
};

// Why no ray came back.
enum class CameraRayFate { Passed, Vignetted, Failed };  // Failed: missed a surface, total internal reflection

struct CameraRaySample {
  CameraRayFate fate = CameraRayFate::Failed;
  CameraRay ray;  // valid when fate == Passed
  bool ok() const { return fate == CameraRayFate::Passed; }
};

class LensCamera {
 public:
  // Rays by the exact tracer through camera.lens() (throws OptionsError for a thin-lens camera).
  // `wavelengths_nm`: where the exit pupil and the weights' normalisation are computed (the on-axis
  // beam traced on a 512 x 8 polar grid each); empty: 380 to 780 nm every 10 nm. Throws
  // ComputationError when no ray from the film's centre passes the lens at one of them.
  explicit LensCamera(const Camera& camera, std::span<const double> wavelengths_nm = {});
  // Rays by a polynomial fit of the same lens (LensFit::check_matches; the camera's stop at most as
  // open as the fit's): about 10 times cheaper per ray than tracing.
  LensCamera(const Camera& camera, std::shared_ptr<const LensFit> fit, std::span<const double> wavelengths_nm = {});

  // The ray from film point (film_x_mm, film_y_mm) through pupil sample (u, v) in [0, 1)^2 (radius
  // sqrt(u), angle 2 pi v over the sampled disc: uniform in area), at `wavelength_nm` (within the
  // constructor's range). Thread-safe and allocation-free.
  CameraRaySample sample_ray(double film_x_mm, double film_y_mm, double u, double v, double wavelength_nm) const;
  // The same, or nothing where the lens stops the ray.
  std::optional<CameraRay> generate_ray(double film_x_mm, double film_y_mm, double u, double v, double wavelength_nm) const;

  // The film point of output pixel position (x_px, y_px) (pixel centres at i + 0.5).
  std::array<double, 2> film_point_mm(double x_px, double y_px) const;
  const Camera& camera() const { return camera_; }
  bool uses_fit() const { return fit_ != nullptr; }
  std::string to_string() const;  // "LensCamera(exact tracer, 41 wavelengths 380-780 nm, ...)"
  friend std::ostream& operator<<(std::ostream& os, const LensCamera& c) { return os << c.to_string(); }

 private:
  // What a wavelength needs: where to aim and what a sample is worth.
  struct Node {
    double wavelength_nm = 0.0;
    double z_exit_pupil_mm = 0.0;
    double sampled_radius_mm = 0.0;
    double weight_scale = 1.0;  // sampled disc area / on-axis projected solid angle of the real beam
  };
  void make_nodes(std::span<const double> wavelengths_nm);
  Node node_at(double wavelength_nm) const;  // interpolated
  // Traces the film ray `towards` (from on_sensor) to the front of the lens: the ray leaving it in
  // the lens frame (position mm, direction along travel), or the fate.
  CameraRayFate trace(const Eigen::Vector3d& on_sensor, const Eigen::Vector3d& towards, double wavelength_nm,
                      Eigen::Vector3d& position_mm, Eigen::Vector3d& direction) const;

  const Camera& camera_;
  std::shared_ptr<const LensFit> fit_;
  std::optional<SequentialTracer> tracer_;
  double stop_radius_mm_ = 0.0;  // the camera's stop, for the fit's clipping
  std::vector<Node> nodes_;      // by increasing wavelength
};

}  // namespace lensmith

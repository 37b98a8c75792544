// Exact sequential ray tracing through spherical, conic and even-aspheric surfaces (closed-form
// intersection for quadrics, Newton's method on the sag for aspheres with a bracketed fallback),
// vector Snell refraction with each glass's index at the ray's wavelength, clipping by clear
// semi-diameters, in both directions. References: Welford, Aberrations of Optical Systems, ch. 4;
// Spencer & Murty, JOSA 52, 672 (1962) for the general ray-trace formulation.
#pragma once

#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "lensmith/prescription/prescription.h"
#include "lensmith/trace/ray.h"
#include "lensmith/trace/surface_frames.h"

namespace lensmith {

struct TracerOptions {
  // Where the image plane is: as the prescription puts it (its last thickness, or the paraxial focus
  // when the prescription says so), or at the paraxial focus of the primary wavelength for the
  // prescription's object distance.
  enum class ImagePlane { AsPrescribed, ParaxialFocus };
  ImagePlane image_plane = ImagePlane::AsPrescribed;
  // Override: distance from the last vertex to the image plane, mm (takes precedence when set).
  std::optional<double> image_distance_mm;
  // Clip rays at clear semi-diameters (Vignetted). Off: only geometry can kill a ray.
  bool clip_apertures = true;
  void validate() const;  // throws OptionsError naming the field
};

// One surface crossing of a traced ray.
struct SurfaceHit {
  int surface = 0;                              // 1-based surface number
  Eigen::Vector3d point_mm{0.0, 0.0, 0.0};      // intersection point, global frame
  Eigen::Vector3d direction_after{0.0, 0.0, 1.0};  // unit direction after refraction
  Eigen::Vector3d normal{0.0, 0.0, 1.0};        // unit surface normal at the point (pointing +z)
  double optical_path_mm = 0.0;                 // cumulative optical path from the ray's start, n * length
};

struct TraceResult {
  RayStatus status = RayStatus::Ok;
  int surface = 0;   // 1-based surface where the ray died; 0 when status is Ok
  // Forward: the ray at the image plane. Backward: the ray after surface 1 (in object space,
  // position on surface 1). When the ray died: the ray as it arrived at the surface that killed it.
  Ray ray;
  double optical_path_mm = 0.0;  // from the ray's start to the end point above
  bool ok() const { return status == RayStatus::Ok; }
  std::string to_string() const;
};

// Structure-of-arrays batch for the renderer and the fits. Inputs and outputs share the arrays:
// trace_batch() overwrites position/direction with the output ray and fills status/surface.
struct RayBatch {
  std::vector<double> x_mm, y_mm, z_mm;   // positions
  std::vector<double> l, m, n;            // unit directions
  std::vector<double> wavelength_nm;
  std::vector<RayStatus> status;
  std::vector<int> surface;
  std::size_t size() const { return x_mm.size(); }
  void resize(std::size_t count);  // resizes every array
  void set(std::size_t i, const Ray& ray);
  Ray get(std::size_t i) const;
};

// A batch in memory the caller owns (the numpy arrays of the Python module, a renderer's buffers):
// trace_batch() reads ray i from the inputs and writes it to the outputs, without a copy into a
// RayBatch. Coordinate arrays are strided: ray i's x is x_mm[i * stride], so rows of (x, y, z) are
// x_mm = p, y_mm = p + 1, z_mm = p + 2 with stride 3, and separate arrays have stride 1. Outputs may
// be the inputs (traced in place). A wavelength_stride of 0 gives every ray wavelength_nm[0].
struct RayBatchView {
  std::size_t count = 0;
  const double* x_mm = nullptr;  // positions
  const double* y_mm = nullptr;
  const double* z_mm = nullptr;
  const double* l = nullptr;     // directions (normalised when not unit)
  const double* m = nullptr;
  const double* n = nullptr;
  std::ptrdiff_t stride = 1;     // between consecutive rays' inputs, in doubles
  const double* wavelength_nm = nullptr;
  std::ptrdiff_t wavelength_stride = 1;
  double* x_out_mm = nullptr;    // the rays after the lens (as TraceResult::ray; as given when invalid)
  double* y_out_mm = nullptr;
  double* z_out_mm = nullptr;
  double* l_out = nullptr;
  double* m_out = nullptr;
  double* n_out = nullptr;
  std::ptrdiff_t out_stride = 1;
  RayStatus* status = nullptr;   // count entries each
  int* surface = nullptr;
};

class SequentialTracer {
 public:
  // Precomputes surface positions and, per wavelength met, the refractive indices. Throws
  // PrescriptionError / OptionsError / ComputationError (paraxial focus of an afocal lens).
  SequentialTracer(const Prescription& lens, const TracerOptions& options = {});

  // Forward: `ray` starts anywhere in object space before surface 1 (z < vertex of surface 1 or on
  // it) travelling +z; traced through every surface to the image plane. `path`, when given, receives
  // one SurfaceHit per surface reached (and is cleared first).
  TraceResult trace_forward(const Ray& ray, std::vector<SurfaceHit>* path = nullptr) const;
  // Forward through surfaces first_surface..last_surface (1-based, inclusive) alone: `ray` lies in
  // the medium before first_surface (object space for surface 1), and the result's ray is the ray
  // leaving last_surface, on it, or on the image plane when last_surface is the last (then it is
  // trace_forward, bit for bit, from surface 1). A ray aimed at the aperture stop needs only the
  // surfaces up to it until it is aimed, and then the rest from the stop on (the exact ray model).
  // Throws OptionsError for surfaces that are not a range of the lens's.
  TraceResult trace_forward_through(const Ray& ray, int first_surface, int last_surface,
                                    std::vector<SurfaceHit>* path = nullptr) const;
  // Backward: `ray` starts in image space (e.g. on the sensor) travelling -z; traced through the
  // surfaces from the last to the first. The result is the ray leaving surface 1 into object space.
  TraceResult trace_backward(const Ray& ray, std::vector<SurfaceHit>* path = nullptr) const;
  TraceResult trace(const Ray& ray, TraceDirection direction, std::vector<SurfaceHit>* path = nullptr) const;

  // Traces every ray of `batch` in `direction`, multi-threaded (OpenMP), without allocating per ray, on
  // `threads` threads (0: OpenMP's default team; the process's OpenMP settings are not changed).
  void trace_batch(RayBatch& batch, TraceDirection direction, int threads = 0) const;
  // The same on arrays the caller owns; throws OptionsError for a null pointer or a bad stride.
  void trace_batch(const RayBatchView& rays, TraceDirection direction, int threads = 0) const;

  const Prescription& lens() const { return lens_; }
  double vertex_z_mm(int surface) const;  // 1-based
  double image_plane_z_mm() const { return image_plane_z_mm_; }
  // Index of the medium after surface k (k = 0: object space) at a wavelength.
  double index_after(int surface, double wavelength_nm) const;
  // Where surface k (1-based) lies: its vertex and axes in the global frame (on the z axis, unturned, for a
  // coaxial lens; docs/trace.md, "Mirrors, coordinate breaks, toroids").
  SurfaceFrame surface_frame(int surface) const;
  // A point of the image plane's output frame (TraceResult::ray of a forward trace) in the global frame.
  Eigen::Vector3d image_point_in_global_frame(const Eigen::Vector3d& output_point_mm) const;

 private:
  Prescription lens_;
  TracerOptions options_;
  std::vector<double> vertex_z_mm_;
  double image_plane_z_mm_ = 0.0;
  // Implementation-defined members follow (cached indices etc.).
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace lensmith

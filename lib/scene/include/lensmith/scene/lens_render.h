// Ground truth for the defocus renderer: an analytic scene photographed through the exact
// prescription by Monte-Carlo ray tracing from the sensor (backward through every surface, clipped
// by every clear aperture), or through the classic thin lens of path tracers (pbrt-v4
// cameras.cpp, PerspectiveCamera; Cycles' thin lens). Sensor placement and framing are the
// Camera's (camera.h, docs/bokeh.md), so a render lines up pixel for pixel with `lensmith bokeh`
// on the pinhole render of the same scene (docs/scene-format.md, "Rendering through the lens").
//
// Frames: a lens-frame object-space point (x, y, z) mm is the camera-space point
// (x, y, z_perspective - z) mm (x right, y up, z = planar depth from the entrance pupil), and a
// lens-frame direction (l, m, n) is (l, m, -n), as the bokeh models place scene points
// (exact_model.cpp, ray_towards).
//
// Radiometry: the irradiance of a sensor point is the radiance of each ray times the projected solid
// angle it stands for, cos^4(theta) / D^2 per unit area of the sampled exit-pupil plane at axial
// distance D (pbrt-v4 RealisticCamera's weight). It is normalised, per wavelength, by the projected
// solid angle of the real on-axis beam of the sensor's centre, so a uniform surface in focus renders
// to exactly its radiance at the centre and falls off across the frame as the lens's relative
// illumination (cos^4-type falloff, clear-aperture vignetting, pupil aberration), as `lensmith
// analyze --what illumination` computes it. The thin lens, like path tracers' thin-lens cameras,
// has no falloff: every pixel of a uniform surface renders to its radiance.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "lensmith/camera/camera.h"
#include "lensmith/render/gather_renderer.h"
#include "lensmith/render/image.h"
#include "lensmith/scene/scene.h"

namespace lensmith {

struct LensRenderOptions {
  int spp = 64;  // samples per pixel of the first pass, 1 .. 1048576
  // Progressive: after each pass, while the estimated relative error (LensRender) is above this,
  // render as many samples again (doubling the total) up to max_spp. Empty: one pass of spp.
  // Finite and > 0.
  std::optional<double> noise_target;
  int max_spp = 4096;  // upper bound of the total with a noise target, >= spp
  int threads = 0;     // 0 = all hardware threads (OpenMP); > 0 = that many
  // Spectral: every sample carries one wavelength of a spectral_samples-node quadrature (380 to
  // 780 nm, color/spectral_quadrature.h), stratified over a pixel's samples; the scene's RGB
  // becomes a smooth spectrum and is integrated back. Off: every ray at the camera's reference
  // wavelength, RGB as it is. A thin lens has no dispersion and always carries RGB as it is.
  bool spectral = true;
  int spectral_samples = 16;  // 3 .. 64
  std::uint64_t seed = 1;     // the same seed gives the same image whatever the thread count
  // Called with the fraction done (0 .. 1) from the calling thread; with a noise target it counts
  // towards max_spp and jumps to 1 when the target is met. May be empty.
  std::function<void(double)> progress;

  void validate() const;  // throws OptionsError naming the field and the constraint
  std::string to_string() const;  // "LensRenderOptions(spp 64, max_spp 4096, ...)"
  friend std::ostream& operator<<(std::ostream& os, const LensRenderOptions& o) { return os << o.to_string(); }
};

// Where the traced rays went, summed over all samples.
struct LensRayCounts {
  std::uint64_t traced = 0;         // rays started on the sensor
  std::uint64_t reached_scene = 0;  // left surface 1 and were intersected with the scene
  std::uint64_t vignetted = 0;      // stopped by a clear aperture or the stop (outside the real pupil)
  std::uint64_t failed = 0;         // missed a surface, total internal reflection, not converged
  std::string to_string() const;  // "1000 traced, 756 reached the scene, 240 vignetted, 4 failed"
};

struct LensRender {
  Image rgb;  // linear RGB radiance, 3 channels, the camera frame's size
  int spp_used = 0;  // samples per pixel actually rendered
  // Mean over pixels of the standard error of a pixel's luminance (r + g + b) / 3 estimated from
  // its samples, relative to max(pixel mean, 1 % of the image mean): about 1 / sqrt(samples) times
  // the relative spread of one sample.
  double estimated_relative_error = 0.0;
  LensRayCounts rays;

  std::string to_string() const;  // "LensRender(Image(...), 64 spp, relative error 0.012, rays ...)"
  friend std::ostream& operator<<(std::ostream& os, const LensRender& r) { return os << r.to_string(); }
};

// The scene photographed through camera.lens() (a real lens; OptionsError for a thin-lens camera).
// Per pixel and sample: a uniformly jittered point of the pixel, mapped to the sensor by the inverse
// of Camera::output_pixel; a wavelength node; a point uniform on the paraxial exit-pupil disc at
// that wavelength enlarged by 15 % in radius (so that rays the real pupil lets through, which
// differs from the paraxial one by pupil aberrations, are not missed); the ray from the sensor point
// towards it traced backward (clear apertures clip: vignetting); a ray that leaves surface 1 is
// intersected with the scene (background at infinity). Rows are shared among OpenMP threads; each
// pixel's random numbers come from (seed, pixel, pass), so the image does not depend on the thread
// count. Throws SceneError for an invalid scene, OptionsError for invalid options.
LensRender render_through_lens(const Scene& scene, const Camera& camera, const LensRenderOptions& options);

// The scene photographed through the ideal thin lens of a Camera::thin_lens camera (OptionsError
// for a real lens): a point uniform on the lens disc of radius f / (2N) in the plane of the
// perspective centre, and the ray from it towards the point of the focus plane that the sensor
// point images to (the pinhole ray through the same output position), as pbrt's and Cycles' thin
// lens cameras do. Every ray reaches the scene; RGB is carried as it is (no dispersion).
LensRender render_through_thin_lens(const Scene& scene, const Camera& camera, const LensRenderOptions& options);

// The rays of Tan et al.'s hybrid (render_gather's GatherTracer, `--hidden trace`): per request,
// its rays sampled as render_through_lens (or, for a Camera::thin_lens camera,
// render_through_thin_lens) samples a pixel's, each through a uniform point of the request's
// square; fills in their mean radiance (a ray the lens stops adds black, as in a pixel's estimate)
// and how many reached the scene. Uses options' seed, threads and spectral settings (not spp).
void trace_regions(const Scene& scene, const Camera& camera, std::vector<GatherTraceRequest>& requests, const LensRenderOptions& options);

}  // namespace lensmith

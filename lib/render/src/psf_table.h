// The lens's blur of a scene point as its first two moments, tabulated over the frame and the
// picture's inverse depths: where the light of the point lands on average (the centroid's shift
// from the pinhole position: distortion, coma), its spread (a 2 x 2 covariance), the share of the
// light the lens lets through (vignetting) and the output area a picture's pixel maps to. Used by
// the methods that give each point one footprint instead of its rays: `ewa` (a Gaussian of that
// covariance) and `gather` (an ellipse of it).
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include "lensmith/camera/aperture.h"
#include "lensmith/camera/ray_model.h"
#include "illumination_table.h"

namespace lensmith::render_detail {

// The blur of a scene point: the shift of its centroid from the pinhole position (px), a signed
// Cholesky factor of its covariance (px; the sign of the blur, so that it passes through 0 at focus
// when interpolated), the share of light the lens lets through and the output area (px^2) a pixel
// of the picture maps to (the centroids' Jacobian).
struct PsfEntry {
  float dx = 0.0f, dy = 0.0f;
  float l11 = 0.0f, l21 = 0.0f, l22 = 0.0f;
  float throughput = 1.0f;
  float area = 1.0f;
};

// A symmetric 2 x 2 variance, px^2.
struct Variance {
  double xx = 0.0, xy = 0.0, yy = 0.0;
  double smaller_eigenvalue() const {
    const double mean = 0.5 * (xx + yy), half = 0.5 * (xx - yy);
    return mean - std::sqrt(half * half + xy * xy);
  }
  double larger_eigenvalue() const {
    const double mean = 0.5 * (xx + yy), half = 0.5 * (xx - yy);
    return mean + std::sqrt(half * half + xy * xy);
  }
  double determinant() const { return xx * yy - xy * xy; }
};

inline Variance variance_of(const PsfEntry& e) {
  const double a = e.l11, b = e.l21, c = e.l22;
  return {a * a, a * b, b * b + c * c};
}

struct PsfTableOptions {
  // The lens's PSF from the ray model; false (and always for a thin lens): a centred uniform disc
  // of the CoC, unvignetted but for the thin model of a real lens (Camera::real_lens), whose
  // throughput is that lens's brightness across the frame (IlluminationTable).
  bool lens_psf = true;
  bool vignetting = true;  // the throughput is the lens's (false: 1 wherever light passes)
  // The covariance is the light's second moment times this (ewa: 2 / ln 4, the L2-best Gaussian of
  // a disc; gather: 1).
  double variance_scale = 1.0;
};

// The table: kGridX x kGridY field points over the frame and a margin around it, a depth sample
// per 8 px of blur between the inverse depths w_min and w_max (1/mm), read by trilinear
// interpolation (psf_table.cpp says why these sizes).
class PsfTable {
 public:
  PsfTable(const RayModel& model, const Aperture& aperture, double w_min, double w_max, int margin_px, const PsfTableOptions& options,
           int threads);
  // The blur of the point seen at pixel position (x, y) (px) at inverse depth w (1/mm).
  PsfEntry at(double x, double y, double w) const;

 private:
  std::size_t index(int gx, int gy, int d) const;
  const Camera& camera_;
  PsfTableOptions options_;
  int margin_ = 0;
  double cell_x_ = 1.0, cell_y_ = 1.0, w0_ = 0.0, dw_ = 1.0;
  int depths_ = 2;
  std::vector<PsfEntry> entries_;
  IlluminationTable thin_illumination_;  // the thin model of a real lens, vignetting on (else empty)
};

}  // namespace lensmith::render_detail

// The lens rays of the multiview method (multiview_renderer.h), tabulated: for each of a fixed set of
// pupil samples (a point of the aperture and a wavelength), the ray that leaves the lens into the
// scene from the film point of an output pixel, as a line in the pinhole image: the pinhole pixel
// it projects to at inverse depth w is p(w) = p_inf + w k (exactly linear: the pinhole sits at the
// perspective centre and the ray is straight in object space; Lee, Eisemann & Seidel 2009, eq. 3,
// with the lens's real ray instead of the thin lens's).
//
// Where rays come from:
//   exact, poly  LensCamera (lens_camera.h): the film ray traced backward through the prescription
//                or through the fit, pbrt's radiometric weight. Circular stop only.
//   thin, paraxial, seidel  the ray model's forward map inverted: for the pupil point, the scene
//                points at the focus plane and at infinity that the model sends to the film point
//                (Newton on the direction tangents, a few map() calls each), joined by a line; the
//                models' clear-aperture discs (widened as the scatter's, where the options give the
//                real lens's illumination) and radiometric weight at the focus-plane point.
// Rays are computed on a grid of film points every `grid_px` output pixels and interpolated
// bilinearly in between (the line's parameters are smooth in the film point); a pixel whose cell
// has a corner where the sample's ray is stopped gets its own ray, so a vignetted beam's edge is
// exact to the pixel.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "lensmith/camera/aperture.h"
#include "lensmith/camera/ray_model.h"
#include "illumination_table.h"

namespace lensmith {

// One lens ray as a line in pinhole pixel coordinates (x right, y down; pixel centres at + 0.5):
// p(w) = (inf_x, inf_y) + w (k_x, k_y), w the inverse planar depth in 1/mm.
struct PixelRay {
  float inf_x = 0.0f, inf_y = 0.0f;
  float k_x = 0.0f, k_y = 0.0f;
  float weight = 0.0f;  // radiometric weight x aperture transmission / its mean; 0: stopped
};

// A sample of the lens: where on the aperture and at which wavelength.
struct LensSample {
  double u = 0.0, v = 0.0;     // in [0, 1)^2
  int node = 0;                // index of the wavelength in the table's wavelengths
};

struct LensRayTableOptions {
  int grid_px = 16;            // film grid step, output pixels (>= 1)
  bool vignetting = true;      // false: every passing ray weighs 1 (the cat's eye kept, its light not)
  int threads = 0;
  // The first-order models' discs widened where the real lens passes more (IlluminationTable::widen;
  // kept by the caller), or null.
  const render_detail::IlluminationTable* illumination = nullptr;
};

class LensRayTable {
 public:
  // Throws OptionsError for an aperture the model's ray source cannot sample (a non-circular
  // aperture with exact or poly: not implemented).
  LensRayTable(const RayModel& model, const Aperture& aperture, std::vector<double> wavelengths_nm,
               std::vector<LensSample> samples, const LensRayTableOptions& options);
  ~LensRayTable();

  std::size_t sample_count() const { return samples_.size(); }
  const LensSample& sample(std::size_t j) const { return samples_[j]; }
  // The ray of sample j from output pixel (x, y) (integer pixel; its centre). Thread-safe.
  PixelRay ray(int x, int y, std::size_t j) const;
  // The same computed directly, without the grid (for tests and for cells with stopped corners).
  PixelRay direct_ray(double x_px, double y_px, std::size_t j) const;
  std::size_t direct_rays() const;  // rays computed without interpolation so far (statistics)
  // The mean ray weight (0 where the lens stops the ray) over `samples`, another pupil set than the
  // table's (a denser one), from the film point of output pixel position (x_px, y_px): the light the
  // pixel's beam passes. Computed directly, not from the grid. Thread-safe.
  double mean_weight(double x_px, double y_px, std::span<const LensSample> samples) const;

  // The grid: nodes at output pixel centres every grid_px() pixels; pixel (x, y) lies in the cell
  // whose corners are nodes (x / g, y / g) to (x / g + 1, y / g + 1) (clamped to the last node).
  int grid_px() const { return grid_; }
  int nodes_x() const { return nodes_x_; }
  int nodes_y() const { return nodes_y_; }
  const PixelRay& node_ray(int node_x, int node_y, std::size_t j) const {
    return grid_rays_[(j * static_cast<std::size_t>(nodes_y_) + static_cast<std::size_t>(node_y)) * static_cast<std::size_t>(nodes_x_) +
                      static_cast<std::size_t>(node_x)];
  }

  struct Source;  // where rays come from (lens_ray_table.cpp)

 private:

  std::vector<LensSample> samples_;
  std::vector<double> wavelengths_nm_;
  const Camera* camera_ = nullptr;  // the model's (outlives the table, as the model does)
  int width_ = 0, height_ = 0, grid_ = 8, nodes_x_ = 0, nodes_y_ = 0;
  std::vector<PixelRay> grid_rays_;  // [sample][node_y][node_x]
  std::unique_ptr<Source> source_;
  mutable std::atomic<std::size_t> direct_rays_{0};
};

}  // namespace lensmith

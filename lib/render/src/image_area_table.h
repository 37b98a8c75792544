// The output area a picture's pixel images to, relative to a pixel's at the frame's centre on the
// focus plane (chief_ray_image_area, lensmith/camera/ray_model.h): where a lens's barrel distortion
// packs more of the scene into each output pixel, the picture is brighter there by as much, and the
// bokeh renderer weighs a footprint's coverage by it (FootprintPlan::area). Tabulated over the frame
// and the margin beyond it and over the sources' inverse depths, read by trilinear interpolation:
// distortion changes over tens of pixels, and mapping three chief rays for every source took the
// Seidel model's 1080p render 8-10 % longer.
#pragma once

#include <vector>

#include "lensmith/camera/ray_model.h"

namespace lensmith::render_detail {

class ImageAreaTable {
 public:
  // Whether `model` has distortion to tabulate: not thin and paraxial, which map the field linearly.
  static bool needed(const RayModel& model) { return model.kind() != RayModelKind::Thin && model.kind() != RayModelKind::Paraxial; }
  // Every area 1.
  ImageAreaTable() = default;
  // For `model`'s frame and `margin_px` beyond it, inverse depths w_min..w_max (1/mm); empty where
  // not needed().
  ImageAreaTable(const RayModel& model, int margin_px, double w_min, double w_max, int threads);
  bool empty() const { return areas_.empty(); }
  // The relative area at input pixel point (x, y) (px) and inverse depth w (1/mm), clamped to the
  // table's extent.
  float at(double x, double y, double w) const;

 private:
  std::size_t index(int gx, int gy, int d) const {
    return (static_cast<std::size_t>(d) * static_cast<std::size_t>(ny_) + static_cast<std::size_t>(gy)) * static_cast<std::size_t>(nx_) +
           static_cast<std::size_t>(gx);
  }
  int nx_ = 0, ny_ = 0, depths_ = 0;
  double x0_ = 0.0, y0_ = 0.0, cell_x_ = 1.0, cell_y_ = 1.0, w0_ = 0.0, dw_ = 1.0;
  std::vector<float> areas_;
};

}  // namespace lensmith::render_detail

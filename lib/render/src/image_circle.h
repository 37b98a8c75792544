// The part of the output frame a lens can send light to: its image circle (or any region
// star-shaped about the axis: anamorphic, tilted and decentred lenses). Beyond it a real camera's
// picture is black, and the renderer must not fill the pixels no footprint reached there with the
// colours around them (layer_compositing): a fisheye's frame corners came out grey where
// `lensmith scene render --lens` leaves them black. Measured on the prescription itself, whatever
// the ray model: from film points marched outwards from the axis along 48 directions, rays traced
// backwards through the lens (LensCamera, as the ground truth traces them) towards 33 points of the
// pupil; the circle's edge in a direction is where the last of them still leaves the lens, bisected.
// The rays go from the film into the scene, so no aim can fail (the exact model's aimer refuses a
// fisheye's fields beyond about 60 deg, which would have drawn the circle too small).
#pragma once

#include <vector>

#include "lensmith/camera/camera.h"

namespace lensmith::render_detail {

class ImageCircle {
 public:
  // Reaches every pixel (a thin lens, a lens LensCamera cannot trace, a circle beyond the frame).
  ImageCircle() = default;
  // Measured through `camera`'s lens, whatever ray model renders with it.
  ImageCircle(const Camera& camera, int threads);

  // Whether a ray through the lens reaches output point (x, y) (px; a pixel's centre): with a margin of
  // a pixel, the fisheye's pixels just outside its circle were filled and came out at 0.3 to 0.5 of
  // the centre where the ground truth has none.
  bool reaches(double x_px, double y_px) const;
  bool bounded() const { return !radius_px_.empty(); }

 private:
  double centre_x_ = 0.0, centre_y_ = 0.0;  // the optical axis on the film, output px
  std::vector<double> radius_px_;           // per direction from it (infinite: beyond the frame's corner)
};

}  // namespace lensmith::render_detail

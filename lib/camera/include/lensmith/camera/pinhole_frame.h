// The framing of an all-in-focus (pinhole) image: which direction each pixel looks along. The
// pinhole sits at the camera's perspective centre (the entrance pupil of a real lens); the image is
// W x H pixels of pitch sensor_width / W on a sensor at the pinhole focal length.
#pragma once

#include <optional>
#include <ostream>
#include <string>

namespace lensmith {

// Direction tangents of a line through the pinhole: the point (tan_x * z, tan_y * z) at planar
// depth z. x to the right, y up (the image's rows run down).
struct Tangents {
  double x = 0.0;
  double y = 0.0;
};

// Continuous pixel coordinates: pixel (i, j) covers [i, i+1] x [j, j+1], y down.
struct PixelPoint {
  double x = 0.0;
  double y = 0.0;
};

struct PinholeFrameOptions {
  double sensor_width_mm = 36.0;               // width of the pinhole image's sensor, mm (> 0)
  std::optional<double> focal_length_mm;       // pinhole focal length, mm (> 0); empty = the caller's default
  std::optional<double> horizontal_fov_deg;    // instead of sensor width and focal length: (0, 180) degrees
  void validate() const;                       // throws OptionsError naming the option
  std::string to_string() const;
};

class PinholeFrame {
 public:
  // Throws OptionsError for sizes < 1 or a focal length in pixels that is not finite and > 0.
  PinholeFrame(int width_px, int height_px, double focal_length_px);
  // From options; default_focal_length_mm is used when neither a focal length nor a field of view
  // is given (the lens EFL for a real lens).
  static PinholeFrame from_options(int width_px, int height_px, const PinholeFrameOptions& options,
                                   double default_focal_length_mm);

  int width_px() const { return width_; }
  int height_px() const { return height_; }
  double focal_length_px() const { return focal_px_; }
  double horizontal_fov_deg() const;

  // The direction through a continuous pixel position (pixel centres at i + 0.5).
  Tangents tangents_at(const PixelPoint& p) const { return {(p.x - centre_x_) / focal_px_, (centre_y_ - p.y) / focal_px_}; }
  PixelPoint pixel_at(const Tangents& t) const { return {centre_x_ + t.x * focal_px_, centre_y_ - t.y * focal_px_}; }

  // The part of this frame from pixel (left, top), width x height pixels: its pixel (x, y) looks
  // where this frame's (left + x, top + y) does, so its axis is off its centre. For reading a
  // picture that covers part of a frame (an OpenEXR data window off the frame's centre); the
  // renderers take whole frames, axis at the centre. Throws OptionsError for an empty size.
  PinholeFrame window(int left, int top, int width_px, int height_px) const;

  std::string to_string() const;  // "PinholeFrame(640 x 360 px, f = 711.1 px, hfov 48.5 deg)"
  friend std::ostream& operator<<(std::ostream& os, const PinholeFrame& f) { return os << f.to_string(); }

 private:
  int width_ = 0;
  int height_ = 0;
  double focal_px_ = 0.0;
  double centre_x_ = 0.0;  // where the axis meets the image, pixels from the left edge (width / 2 but in a window)
  double centre_y_ = 0.0;  // ... from the top edge
};

}  // namespace lensmith

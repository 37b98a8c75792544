// The all-in-focus picture of an analytic scene through a pinhole, and its exact planar depth: the
// input that `lensmith bokeh` defocuses, made from known geometry.
//
// Colour: each pixel is the mean radiance of n x n rays through the centres of an n x n grid of
// equal sub-pixel cells (stratified, no jitter: deterministic), so an edge is anti-aliased.
// Depth: the ray through the pixel centre only, as renderers' depth passes are (Cycles' Z pass,
// pbrt's depth AOV): the planar depth along the camera axis, in metres, of the surface that one
// ray meets, +inf when it meets nothing. A pixel on an object's edge thus carries one surface's
// depth while its colour mixes both; a consumer that needs coverage must not infer it from depth.
#pragma once

#include <ostream>
#include <string>

#include "lensmith/camera/pinhole_frame.h"
#include "lensmith/render/deep_image.h"
#include "lensmith/render/image.h"
#include "lensmith/scene/scene.h"

namespace lensmith {

struct PinholeRenderOptions {
  int samples_per_axis = 4;  // n: n x n colour rays per pixel, 1 .. 64
  int threads = 0;           // 0 = all hardware threads (OpenMP); > 0 = that many

  void validate() const;  // throws OptionsError naming the field and the constraint
  std::string to_string() const;  // "PinholeRenderOptions(samples_per_axis 4, threads 0)"
  friend std::ostream& operator<<(std::ostream& os, const PinholeRenderOptions& o) { return os << o.to_string(); }
};

struct PinholeRender {
  Image rgb;       // linear RGB radiance, 3 channels, the frame's size
  DepthMap depth;  // planar depth of the pixel-centre ray, metres; +inf for the background

  std::string to_string() const;  // "PinholeRender(Image(...), DepthMap(...))"
  friend std::ostream& operator<<(std::ostream& os, const PinholeRender& r) { return os << r.to_string(); }
};

// Renders `scene` from its camera pose with `frame`'s pixels: pixel (i, j) looks along the tangents
// frame.tangents_at(i + x, j + y) (x right, y up in the camera frame of camera_pose.h). Rows are
// shared among threads; the result does not depend on the thread count. Throws SceneError for an
// invalid scene and OptionsError for invalid options.
PinholeRender render_pinhole(const Scene& scene, const PinholeFrame& frame, const PinholeRenderOptions& options = {});

// Most layers render_pinhole_layers peels.
inline constexpr int kMaxPeeledLayers = 16;

// The scene as layered (deep) input by depth peeling: each of the n x n colour rays of a pixel (as
// render_pinhole's) meets up to `layers` objects, nearest first, each object once (every shape is
// convex or flat: its front surface). Per pixel, one sample per object its rays meet: planar depth
// (metres) the mean over those rays; alpha the object's own coverage, the share of the rays known
// to meet or miss it that meet it (a ray cut off after `layers` objects in front of it is not
// known to miss it); colour alpha times their mean radiance (premultiplied). Where rays meet
// nothing, a sample of the background at +inf covering all (behind an opaque object the sky is not
// a surface to keep). So what hides behind every foreground edge, up to `layers` surfaces deep, is
// in the file. Composited front to back ("over", DeepImage::flatten) it is render_pinhole's picture
// where a pixel's hidden surfaces are uniform in colour and its surfaces' coverages independent (a
// silhouette over a wall); a textured surface behind an edge differs by its colour's variation
// within the pixel, and where three surfaces share a pixel their coverages are not independent.
// Throws SceneError for an invalid scene and OptionsError for invalid options or layers outside
// 1..kMaxPeeledLayers.
DeepImage render_pinhole_layers(const Scene& scene, const PinholeFrame& frame, int layers, const PinholeRenderOptions& options = {});

}  // namespace lensmith

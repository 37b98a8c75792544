// The light of a pixel's beam from a dense pupil set, on a coarse grid over the frame: the methods
// that trace or warp few rays per pixel (multiview's 32 lens rays, the light field's 36 views, one
// set of pupil points the whole frame shares) measure a vignetted beam's share of the light with a
// bias that depends on where the beam's cat's eye lies among those points (up to 20 % at lentil
// 0005's frame edge: docs/bokeh.md, "Brightness across the frame"). The share varies slowly over
// the frame, so it is measured with kLightSamples pupil points at the grid's nodes only and
// interpolated bilinearly in between.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace lensmith::render_detail {

// Pupil points (Halton) a node's light is measured with. 128 moved multiview's Seidel light at the
// retrofocus strip's edge (tests/scene) from 0.350 to 0.337 of the centre (truth 0.414).
constexpr std::size_t kLightSamples = 256;

// Nodes every max(kMinStepPx, shorter side / kNodesAcross) px from the first pixel, the last
// on the last pixel of each axis. 16 nodes left lentil 0005's bottom edge 0.028 too bright through
// multiview; the README's scene (640 x 360, Seidel) spends about 0.4 s of its 4.0-4.4 s on them.
class LightGrid {
 public:
  static constexpr int kNodesAcross = 32;
  static constexpr int kMinStepPx = 4;

  LightGrid() = default;
  // A grid over a width x height frame (px), every node `fill`.
  LightGrid(int width, int height, float fill)
      : width_(width), height_(height), step_(std::max(kMinStepPx, std::min(width, height) / kNodesAcross)),
        nx_((width - 1 + step_ - 1) / step_ + 1), ny_((height - 1 + step_ - 1) / step_ + 1),
        values_(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_), fill) {}

  int nodes_x() const { return nx_; }
  int nodes_y() const { return ny_; }
  // The pixel node i (j) lies on along x (y): its centre is 0.5 px on.
  int node_x_px(int i) const { return node_px(i, width_); }
  int node_y_px(int j) const { return node_px(j, height_); }
  float& at(int i, int j) { return values_[static_cast<std::size_t>(j) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(i)]; }
  float at(int i, int j) const { return values_[static_cast<std::size_t>(j) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(i)]; }

  // Bilinear between the four nodes around pixel (x, y) (clamped to the frame's outermost nodes).
  float sample(int x, int y) const {
    int i = 0, j = 0;
    float tx = 0.0f, ty = 0.0f;
    locate(x, width_, nx_, i, tx);
    locate(y, height_, ny_, j, ty);
    const int i1 = std::min(i + 1, nx_ - 1), j1 = std::min(j + 1, ny_ - 1);
    return (1.0f - ty) * ((1.0f - tx) * at(i, j) + tx * at(i1, j)) + ty * ((1.0f - tx) * at(i, j1) + tx * at(i1, j1));
  }

 private:
  int node_px(int i, int size) const { return std::min(i * step_, size - 1); }
  // The node at or before pixel p along an axis of `size` px and `nodes` nodes, and p's fraction of
  // the way to the next.
  void locate(int p, int size, int nodes, int& i, float& t) const {
    i = std::min(p / step_, std::max(nodes - 2, 0));
    const int a = node_px(i, size), b = node_px(std::min(i + 1, nodes - 1), size);
    t = b > a ? std::clamp(static_cast<float>(p - a) / static_cast<float>(b - a), 0.0f, 1.0f) : 0.0f;
  }

  int width_ = 1, height_ = 1, step_ = 1, nx_ = 1, ny_ = 1;
  std::vector<float> values_ = std::vector<float>(1, 1.0f);
};

}  // namespace lensmith::render_detail

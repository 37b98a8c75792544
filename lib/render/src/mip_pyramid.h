// A box-filtered mipmap of an RGBA image and the mean over a window of any size from it (trilinear
// between levels): the cone tracing of Lee et al. 2009 (multiview, their sec. 4.4) and the
// pre-filter against undersampling of Yu, Wang & Yu 2010 (lightfield, their sec. 4.2; they use a
// 3 x 3 Gaussian per level, lensmith the 2 x 2 box of Lee et al.'s mipmaps for both).
#pragma once

#include <array>
#include <cstddef>
#include <vector>

namespace lensmith::render_detail {

class MipPyramid {
 public:
  MipPyramid() = default;
  // Level 0 is `base`, w x h pixels, row-major; each next level averages 2 x 2 (edge pixels repeated).
  MipPyramid(std::vector<std::array<float, 4>> base, int w, int h);
  bool empty() const { return levels_.empty(); }
  // The mean over a window `diameter` px across centred at (x, y) (level-0 pixel coordinates,
  // pixel (i, j) covering [i, i+1] x [j, j+1]), clamped to the image.
  std::array<float, 4> window(float x, float y, float diameter) const;

 private:
  std::array<float, 4> at_level(std::size_t k, float x, float y) const;  // bilinear, clamped
  std::vector<std::vector<std::array<float, 4>>> levels_;  // level k: ceil(w / 2^k) x ceil(h / 2^k)
  std::vector<int> widths_, heights_;
};

}  // namespace lensmith::render_detail

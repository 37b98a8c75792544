#include "footprint_stamps.h"

#include <cmath>

namespace lensmith::render_detail {

namespace {
// Four sign combinations of the two scales (an image behind or before the sensor, y down).
constexpr int kSignCombinations = 4;
// The two scales count as equal in size within this (px): a thin lens's are equal to rounding.
constexpr double kScaleTolerancePx = 1e-6;
}  // namespace

FootprintStamps::FootprintStamps(const PupilMeshTable& meshes, double max_scale_px)
    : meshes_(meshes), steps_(static_cast<int>(std::ceil(std::max(0.0, max_scale_px) * kStepsPerPx)) + 1) {
  const auto slots = static_cast<std::size_t>(steps_) * kSignCombinations;
  built_ = std::make_unique<std::once_flag[]>(slots);
  stamps_ = std::make_unique<std::unique_ptr<DifferenceStamp>[]>(slots);
}

const DifferenceStamp* FootprintStamps::find(double scale_x_px, double scale_y_px) const {
  const double size = std::abs(scale_x_px);
  if (!(std::abs(size - std::abs(scale_y_px)) <= kScaleTolerancePx)) return nullptr;
  const double step = std::round(size * kStepsPerPx);
  if (!(step < steps_)) return nullptr;
  const bool flip_x = scale_x_px < 0.0, flip_y = scale_y_px < 0.0;
  const std::size_t slot = static_cast<std::size_t>(flip_x ? 1 : 0) + (flip_y ? 2u : 0u) +
                           kSignCombinations * static_cast<std::size_t>(step);
  std::call_once(built_[slot], [&] {
    const double scale = step / kStepsPerPx;
    const double sx = flip_x ? -scale : scale, sy = flip_y ? -scale : scale;
    // The outline the polygon path would draw at this size (a footprint's diameter is 2 scale).
    const std::vector<PupilPoint>& outline = meshes_.outline(PupilMeshTable::sector_step(2.0 * scale));
    std::vector<Point2f> polygon(outline.size());
    for (std::size_t i = 0; i < outline.size(); ++i) {
      polygon[i] = {static_cast<float>(0.5 + sx * outline[i].x), static_cast<float>(0.5 + sy * outline[i].y)};
    }
    stamps_[slot] = std::make_unique<DifferenceStamp>(SplatBuffer::record(polygon, kSubrows));
  });
  return stamps_[slot].get();
}

}  // namespace lensmith::render_detail

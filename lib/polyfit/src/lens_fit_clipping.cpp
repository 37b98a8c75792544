// Which clear apertures a fit clips at (lens_fit_stages.h): the stop, and every surface whose clear
// aperture cuts enough of the sampled beam to change a rendered image. At run time a ray passes when
// its fitted crossing of each lies within that surface's semi-diameter, so vignetting comes from the
// prescription's clear apertures, not from a polynomial's values.
#include <cmath>

#include "lens_fit_stages.h"

namespace lensmith::polyfit_detail {

namespace {
// A surface joins the clipping set when its clear aperture cuts at least this fraction of the
// training rays (fewer would not change a rendered image).
constexpr double kClipFraction = 5e-4;
}  // namespace

std::vector<ClipSurface> choose_clip_surfaces(const RaySampler& sampler, std::span<const Candidate> train) {
  const std::vector<double>& semi_diameter = sampler.semi_diameters();
  const std::size_t stop_index = static_cast<std::size_t>(sampler.stop_surface() - 1);
  std::vector<ClipSurface> clip{{sampler.stop_surface(), sampler.stop_radius_mm()}};
  for (std::size_t k = 0; k < semi_diameter.size(); ++k) {
    if (k == stop_index || !std::isfinite(semi_diameter[k])) continue;
    std::size_t cut = 0;
    for (const Candidate& c : train) cut += std::hypot(c.hit_x[k], c.hit_y[k]) > semi_diameter[k] ? 1 : 0;
    if (static_cast<double>(cut) >= kClipFraction * static_cast<double>(train.size()) &&
        clip.size() < static_cast<std::size_t>(kMaxMapOutputs)) {
      clip.push_back({static_cast<int>(k + 1), semi_diameter[k]});
    }
  }
  return clip;
}

}  // namespace lensmith::polyfit_detail

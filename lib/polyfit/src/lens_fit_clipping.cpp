// Which clear apertures a fit clips at (lens_fit_stages.h): the stop, and every surface whose clear
// aperture (or explicit aperture: a central obscuration) cuts enough of the sampled beam to change a
// rendered image. At run time a ray passes when its fitted crossing of each passes that surface's
// aperture, so vignetting comes from the prescription's apertures, not from a polynomial's values.
#include <cmath>

#include "lens_fit_stages.h"

namespace lensmith::polyfit_detail {

namespace {
// A surface joins the clipping set when its clear aperture cuts at least this fraction of the
// training rays (fewer would not change a rendered image).
constexpr double kClipFraction = 5e-4;
}  // namespace

std::vector<ClipSurface> choose_clip_surfaces(const RaySampler& sampler, std::span<const Candidate> train) {
  const std::vector<ClipSurface>& apertures = sampler.apertures();
  const std::size_t stop_index = static_cast<std::size_t>(sampler.stop_surface() - 1);
  std::vector<ClipSurface> clip{apertures[stop_index]};
  for (std::size_t k = 0; k < apertures.size(); ++k) {
    const ClipSurface& a = apertures[k];
    if (k == stop_index || (!a.aperture && !std::isfinite(a.semi_diameter_mm))) continue;
    std::size_t cut = 0;
    for (const Candidate& c : train) cut += a.clearance(c.hit_x[k], c.hit_y[k]) < 0.0 ? 1 : 0;
    if (static_cast<double>(cut) >= kClipFraction * static_cast<double>(train.size()) &&
        clip.size() < static_cast<std::size_t>(kMaxMapOutputs)) {
      clip.push_back(a);
    }
  }
  return clip;
}

}  // namespace lensmith::polyfit_detail

// The stages of fitting a lens (LensFit::fit, lens_fit.cpp), each in its own file:
//   lens_fit_sampling.cpp  the sampled beam: rays from the sensor side as pbrt-v4's RealisticCamera draws
//                          them (a sensor point, an exit-pupil point), traced backward without clipping;
//   lens_fit_clipping.cpp  which clear apertures the fit clips at (the stop, and every surface that cuts
//                          enough of the beam);
//   lens_fit_errors.cpp    the held-out errors against rays the fit never saw;
//   lens_fit_speed.cpp     the fit's speed against the exact tracer (LensFit::measure_speed, on request);
//   lens_fit_aiming.cpp    Newton aiming on the fitted maps;
//   lens_fit_hash.cpp      which prescription a fit belongs to.
// Internal to lensmith_polyfit.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "lensmith/core/errors.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "lensmith/polyfit/lens_fit.h"
#include "lensmith/trace/sequential_tracer.h"

namespace lensmith::polyfit_detail {

// Candidates traced per ray wanted before giving up: a lens that passes fewer than 1 in 200 of the
// sampled beam is not what the sampling assumes.
constexpr int kCandidatesPerRay = 200;
constexpr std::size_t kCandidateBatch = 8192;
// Newton leaves the fit's domain when a normalised input exceeds this.
constexpr double kDomainLimit = 1.5;

// Inputs of a map: the ray on its plane normalised, and the normalised wavelength.
inline PolyPoint normalised(const PlaneRay& r, double position_scale, double direction_scale, double lambda) {
  return {r.x_mm / position_scale, r.y_mm / position_scale, r.dx / direction_scale, r.dy / direction_scale, lambda};
}

// Newton stays where the fit was made: every normalised ray coordinate within kDomainLimit.
inline bool in_domain(const PolyPoint& v) {
  for (int i = 0; i < 4; ++i) {
    if (std::abs(v[static_cast<std::size_t>(i)]) > kDomainLimit) return false;
  }
  return true;
}

// One traced candidate of the sampled beam.
struct Candidate {
  // Both false when the unclipped trace did not reach object space (a miss, total internal reflection).
  bool in_domain = false;   // within every clear aperture enlarged by the margin (obscurations aside)
  bool passes = false;      // through every clear aperture
  PlaneRay sensor;
  PlaneRay outer;
  double wavelength_nm = 0.0;
  double transmittance = 0.0;
  std::vector<double> hit_x, hit_y;  // position on every surface (index surface - 1)
};

// The beam a fit samples: sensor points within the image radius on the paraxial focal plane, aimed at
// points of the exit pupil enlarged by the pupil margin, the stop wide open (and at least as wide as
// the f-number asked for opens it).
class RaySampler {
 public:
  // Throws FitError when the paraxial focus is not behind the last surface, and what the tracer throws.
  RaySampler(const Prescription& lens, const LensFitOptions& options);

  const SequentialTracer& tracer() const { return tracer_; }
  const ParaxialSystem& paraxial() const { return paraxial_; }
  // The x section's first-order data of a lens that is not rotationally symmetric; null otherwise.
  const ParaxialSystem* paraxial_x() const { return paraxial_x_ ? &*paraxial_x_ : nullptr; }
  double sensor_z_mm() const { return tracer_.image_plane_z_mm(); }
  double image_radius_mm() const { return image_radius_mm_; }
  int stop_surface() const { return paraxial_.stop_surface(); }  // 1-based
  double stop_radius_mm() const { return stop_radius_mm_; }
  // Per surface (index surface - 1): what clips there, as the exact tracer clips: the surface's explicit
  // aperture where it has one (not at the stop), else its semi-diameter (+inf when unlimited; the
  // stop's as sampled).
  const std::vector<ClipSurface>& apertures() const { return apertures_; }

  // Candidate `index` of stream `stream` (its own SplitMix64 sequence: the same whatever the thread).
  Candidate make(std::uint64_t stream, std::uint64_t index, std::vector<SurfaceHit>& path) const;

  // Candidates of `stream` in index order until `enough` says stop; keeps those `keep` accepts. Traced
  // in parallel batches; the result does not depend on the thread count. Progress from `from` to `to`.
  template <class Keep, class Enough>
  std::vector<Candidate> collect(std::uint64_t stream, std::size_t wanted, Keep keep, Enough enough,
                                 const std::function<void(double)>& progress, double from, double to) const {
    std::vector<Candidate> kept;
    std::vector<Candidate> batch(kCandidateBatch);
    const std::uint64_t limit = static_cast<std::uint64_t>(wanted) * kCandidatesPerRay;
    for (std::uint64_t start = 0; !enough(kept); start += kCandidateBatch) {
      if (start >= limit) {
        throw FitError("lens fit: only " + std::to_string(kept.size()) + " of " + std::to_string(wanted) +
                       " rays wanted passed the lens after " + std::to_string(start) +
                       " traced: check the image radius and the lens's clear apertures");
      }
#pragma omp parallel
      {
        std::vector<SurfaceHit> path;
#pragma omp for schedule(dynamic, 256)
        for (std::size_t i = 0; i < kCandidateBatch; ++i) batch[i] = make(stream, start + i, path);
      }
      for (Candidate& c : batch) {
        if (enough(kept)) break;
        if (keep(c)) kept.push_back(std::move(c));
      }
      if (progress) progress(from + (to - from) * std::min(1.0, static_cast<double>(kept.size()) / static_cast<double>(wanted)));
    }
    return kept;
  }

 private:
  LensFitOptions options_;
  SequentialTracer tracer_;
  ParaxialSystem paraxial_;
  std::optional<ParaxialSystem> paraxial_x_;
  double image_radius_mm_ = 0.0;
  double stop_radius_mm_ = 0.0;
  double sampled_pupil_radius_mm_ = 0.0;
  std::vector<ClipSurface> apertures_;
};

// The candidate streams of a seed: training, held-out test and speed rays never share a candidate.
enum class Stream { Training, Test, Speed };
std::uint64_t stream_of(std::uint64_t seed, Stream which);

// The clipping set: the stop first, then every surface whose clear aperture (or explicit aperture) cuts at least
// kClipFraction of the training rays (at most kMaxMapOutputs in all).
std::vector<ClipSurface> choose_clip_surfaces(const RaySampler& sampler, std::span<const Candidate> train);

// The fit's errors on held-out rays: positions, directions, stop crossings and transmittance against the
// exact tracer's, and how often the pass/clip verdict differs.
LensFitErrors held_out_errors(const LensFit& fit, std::span<const Candidate> test, int stop_surface);

}  // namespace lensmith::polyfit_detail

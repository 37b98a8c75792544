// Monte-Carlo ground truth through the exact prescription or an ideal thin lens (lens_render.h).
// Sampling follows pbrt-v4's RealisticCamera (sensor point, a point on the rear pupil, trace out
// through the lens) with the paraxial exit pupil as the sampling disc, and PerspectiveCamera's thin
// lens; random numbers from PCG32 (O'Neill, "PCG: a family of simple fast space-efficient
// statistically good algorithms for random number generation", 2014) seeded by SplitMix64.
#include "lensmith/scene/lens_render.h"

#include "lensmith/core/split_mix.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include <omp.h>

#include "lensmith/color/spectral_quadrature.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/units.h"
#include "lensmith/scene/scene_intersection.h"
#include "lensmith/camera/lens_camera.h"

namespace lensmith {

namespace {

constexpr int kMaxSpp = 1 << 20;
// Floor of the denominator of a pixel's relative error, as a fraction of the image's mean, so that
// near-black pixels do not dominate the mean relative error.
constexpr double kRelativeErrorFloor = 0.01;
constexpr double kMinWavelengthNm = 380.0;  // the bokeh renderer's quadrature range
constexpr double kMaxWavelengthNm = 780.0;

// PCG32 (XSH RR), one stream per (seed, pixel, pass).
class Pcg32 {
 public:
  Pcg32(std::uint64_t seed, std::uint64_t pixel, std::uint64_t pass) {
    std::uint64_t mix = seed ^ (pixel * 0xd1b54a32d192ed03ULL) ^ (pass * 0x8cb92ba72f3d8dd7ULL);
    inc_ = (splitmix64(mix) << 1u) | 1u;
    state_ = splitmix64(mix) + inc_;
    next();
  }
  std::uint32_t next() {
    const std::uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    const auto shifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
    const auto rot = static_cast<std::uint32_t>(old >> 59u);
    return (shifted >> rot) | (shifted << ((32u - rot) & 31u));
  }
  // Uniform in [0, 1).
  double uniform() { return next() * 0x1p-32; }

 private:
  std::uint64_t state_ = 0;
  std::uint64_t inc_ = 0;
};

// What one sample sends to its pixel.
enum class SampleFate : std::uint8_t { ReachedScene, Vignetted, Failed };
struct SampleResult {
  Rgb value;
  SampleFate fate = SampleFate::ReachedScene;
};

// Per-pixel sums of the progressive estimator.
struct PixelSums {
  double rgb[3] = {0.0, 0.0, 0.0};
  double luminance = 0.0;
  double luminance_squared = 0.0;
};

struct PerThreadCounts {
  std::uint64_t reached = 0, vignetted = 0, failed = 0;
};

// Runs the passes of options over the camera frame; sample(x_px, y_px, node_u, rng) gives one
// sample of the pixel whose continuous position is (x_px, y_px), node_u in [0, 1) choosing the
// wavelength stratum.
template <typename Sampler>
LensRender render_progressive(const Camera& camera, const LensRenderOptions& options, const Sampler& sample) {
  const int width = camera.frame().width_px();
  const int height = camera.frame().height_px();
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  std::vector<PixelSums> sums(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  LensRender out;
  const int planned = options.noise_target ? options.max_spp : options.spp;
  int total = 0;
  int pass_spp = options.spp;
  std::vector<PerThreadCounts> counts(static_cast<std::size_t>(threads));

  for (std::uint64_t pass = 0;; ++pass) {
    std::atomic<int> rows_done{0};
    const int done_before = total;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
    for (int y = 0; y < height; ++y) {
      PerThreadCounts& mine = counts[static_cast<std::size_t>(omp_get_thread_num())];
      for (int x = 0; x < width; ++x) {
        const std::size_t index = static_cast<std::size_t>(y) * width + x;
        Pcg32 rng(options.seed, index, pass);
        // Stratified wavelength: sample k takes stratum (offset + k) mod spp of [0, 1).
        const double offset = rng.uniform();
        PixelSums& s = sums[index];
        for (int k = 0; k < pass_spp; ++k) {
          double node_u = (offset * pass_spp + k) / pass_spp;
          if (node_u >= 1.0) node_u -= 1.0;
          const SampleResult r = sample(x + rng.uniform(), y + rng.uniform(), node_u, rng);
          switch (r.fate) {
            case SampleFate::ReachedScene: ++mine.reached; break;
            case SampleFate::Vignetted: ++mine.vignetted; break;
            case SampleFate::Failed: ++mine.failed; break;
          }
          for (int c = 0; c < 3; ++c) s.rgb[c] += r.value[c];
          const double l = (r.value.r + r.value.g + r.value.b) / 3.0;
          s.luminance += l;
          s.luminance_squared += l * l;
        }
      }
      const int finished = ++rows_done;
      if (options.progress && omp_get_thread_num() == 0) {
        options.progress((done_before + static_cast<double>(pass_spp) * finished / height) / planned);
      }
    }
    total += pass_spp;

    // Mean relative standard error of the pixels' luminance.
    double image_mean = 0.0;
    for (const PixelSums& s : sums) image_mean += s.luminance / total;
    image_mean /= static_cast<double>(sums.size());
    const double floor = std::max(kRelativeErrorFloor * std::abs(image_mean), std::numeric_limits<double>::min());
    double error = 0.0;
    if (total < 2) {
      error = kInfinity;  // one sample says nothing about its spread
    } else {
      for (const PixelSums& s : sums) {
        const double mean = s.luminance / total;
        const double variance = std::max(0.0, (s.luminance_squared / total - mean * mean) * total / (total - 1.0));
        error += std::sqrt(variance / total) / std::max(std::abs(mean), floor);
      }
      error /= static_cast<double>(sums.size());
    }
    out.estimated_relative_error = error;
    if (!options.noise_target || error <= *options.noise_target || total >= options.max_spp) break;
    pass_spp = std::min(total, options.max_spp - total);
  }
  if (options.progress) options.progress(1.0);

  out.spp_used = total;
  out.rgb = Image(width, height, 3, 0.0f);
  for (std::size_t i = 0; i < sums.size(); ++i) {
    for (int c = 0; c < 3; ++c) out.rgb.data[3 * i + c] = static_cast<float>(sums[i].rgb[c] / total);
  }
  for (const PerThreadCounts& c : counts) {
    out.rays.reached_scene += c.reached;
    out.rays.vignetted += c.vignetted;
    out.rays.failed += c.failed;
  }
  out.rays.traced = out.rays.reached_scene + out.rays.vignetted + out.rays.failed;
  return out;
}

}  // namespace

void LensRenderOptions::validate() const {
  if (spp < 1 || spp > kMaxSpp) {
    throw OptionsError("LensRenderOptions::spp = " + std::to_string(spp) + ": must be in 1..1048576");
  }
  if (max_spp < spp || max_spp > kMaxSpp) {
    throw OptionsError("LensRenderOptions::max_spp = " + std::to_string(max_spp) + ": must be in spp (" +
                       std::to_string(spp) + ")..1048576");
  }
  if (noise_target && !(std::isfinite(*noise_target) && *noise_target > 0.0)) {
    throw OptionsError("LensRenderOptions::noise_target = " + format_number(*noise_target) + ": must be finite and > 0");
  }
  if (threads < 0) {
    throw OptionsError("LensRenderOptions::threads = " + std::to_string(threads) + ": must be >= 0 (0 = all hardware threads)");
  }
  if (spectral_samples < 3 || spectral_samples > 64) {
    throw OptionsError("LensRenderOptions::spectral_samples = " + std::to_string(spectral_samples) + ": must be in 3..64");
  }
}

std::string LensRenderOptions::to_string() const {
  std::ostringstream os;
  os << "LensRenderOptions(spp " << spp << ", noise_target " << (noise_target ? format_number(*noise_target) : "none")
     << ", max_spp " << max_spp << ", threads " << threads << ", spectral "
     << (spectral ? std::to_string(spectral_samples) + " nodes" : std::string("off")) << ", seed " << seed << ")";
  return os.str();
}

std::string LensRayCounts::to_string() const {
  return std::to_string(traced) + " traced, " + std::to_string(reached_scene) + " reached the scene, " +
         std::to_string(vignetted) + " vignetted, " + std::to_string(failed) + " failed";
}

std::string LensRender::to_string() const {
  return "LensRender(" + rgb.to_string() + ", " + std::to_string(spp_used) + " spp, relative error " +
         format_number(estimated_relative_error) + ", " + rays.to_string() + ")";
}

namespace {

// Calls use(sample) with the sampler of render_through_lens: sample(x_px, y_px, node_u, rng).
template <class Use>
auto with_lens_sampler(const Scene& scene, const Camera& camera, const LensRenderOptions& options, Use&& use) {
  // The wavelengths sampled: the quadrature's nodes, or the reference wavelength.
  std::optional<SpectralQuadrature> quadrature;
  std::vector<double> wavelengths;
  std::vector<Rgb> rgb_weights;
  if (options.spectral) {
    SpectralQuadratureOptions q;
    q.sample_count = options.spectral_samples;
    q.min_wavelength_nm = kMinWavelengthNm;
    q.max_wavelength_nm = kMaxWavelengthNm;
    quadrature.emplace(q);
    for (std::size_t i = 0; i < quadrature->size(); ++i) {
      const WavelengthSample w = quadrature->sample_at(i);
      wavelengths.push_back(w.wavelength_nm);
      rgb_weights.push_back(w.rgb_weight);
    }
  } else {
    wavelengths.push_back(camera.reference_wavelength_nm());
    rgb_weights.push_back(Rgb{1.0, 1.0, 1.0});
  }
  // The primary rays and their weights (lens_camera.h), with the exit pupil and the on-axis
  // normalisation computed at exactly these wavelengths.
  const LensCamera lens_camera(camera, wavelengths);

  const CameraBasis basis = scene.camera.basis();
  const Eigen::Vector3d position_m = scene.camera.position_m;
  const SpectralBasis* spectrum = quadrature ? &quadrature->basis() : nullptr;

  auto sample = [&](double x_px, double y_px, double node_u, Pcg32& rng) -> SampleResult {
    const std::size_t node = std::min(wavelengths.size() - 1, static_cast<std::size_t>(node_u * static_cast<double>(wavelengths.size())));
    const std::array<double, 2> film = lens_camera.film_point_mm(x_px, y_px);
    const double u = rng.uniform();
    const double v = rng.uniform();
    const CameraRaySample s = lens_camera.sample_ray(film[0], film[1], u, v, wavelengths[node]);
    if (!s.ok()) return {Rgb{}, s.fate == CameraRayFate::Vignetted ? SampleFate::Vignetted : SampleFate::Failed};
    // Camera frame -> world.
    const Eigen::Vector3d& o = s.ray.origin_m;
    const Eigen::Vector3d& d = s.ray.direction;
    const Eigen::Vector3d origin_m = position_m + o.x() * basis.right + o.y() * basis.up + o.z() * basis.forward;
    const Eigen::Vector3d direction = (d.x() * basis.right + d.y() * basis.up + d.z() * basis.forward).normalized();
    const std::optional<SceneHit> hit = intersect(scene, SceneRay{origin_m, direction});
    const Rgb radiance = hit ? hit->radiance : scene.background;
    if (!spectrum) return {s.ray.weight * radiance, SampleFate::ReachedScene};
    return {(s.ray.weight * spectrum->spectrum_value(radiance, wavelengths[node])) * rgb_weights[node], SampleFate::ReachedScene};
  };
  return use(sample);
}

// Calls use(sample) with the sampler of render_through_thin_lens.
template <class Use>
auto with_thin_lens_sampler(const Scene& scene, const Camera& camera, Use&& use) {
  const double lens_radius_mm = camera.first_order(camera.reference_wavelength_nm()).entrance_pupil_radius_mm;
  const double image_distance_mm = camera.z_sensor_mm();  // the thin lens sits at z = 0
  const double focus_mm = camera.focus_distance_mm();
  const CameraBasis basis = scene.camera.basis();
  const Eigen::Vector3d position_m = scene.camera.position_m;

  auto sample = [&](double x_px, double y_px, double /*node_u*/, Pcg32& rng) -> SampleResult {
    // The sensor point and the tangents of its chief ray through the lens centre: the point it
    // images to on the focus plane.
    const auto [x_mm, y_mm] = camera.sensor_point_mm({x_px, y_px});
    const double tan_x = -x_mm / image_distance_mm, tan_y = -y_mm / image_distance_mm;
    const double r = lens_radius_mm * std::sqrt(rng.uniform());
    const double phi = 2.0 * kPi * rng.uniform();
    const Eigen::Vector3d on_lens_mm(r * std::cos(phi), r * std::sin(phi), 0.0);
    const Eigen::Vector3d towards = std::isinf(focus_mm) ? Eigen::Vector3d(tan_x, tan_y, 1.0)
                                                         : Eigen::Vector3d(tan_x * focus_mm, tan_y * focus_mm, focus_mm) - on_lens_mm;
    const Eigen::Vector3d origin_m = position_m + m_from_mm(on_lens_mm.x()) * basis.right + m_from_mm(on_lens_mm.y()) * basis.up;
    const Eigen::Vector3d direction = (towards.x() * basis.right + towards.y() * basis.up + towards.z() * basis.forward).normalized();
    const std::optional<SceneHit> hit = intersect(scene, SceneRay{origin_m, direction});
    return {hit ? hit->radiance : scene.background, SampleFate::ReachedScene};
  };
  return use(sample);
}

}  // namespace

LensRender render_through_lens(const Scene& scene, const Camera& camera, const LensRenderOptions& options) {
  options.validate();
  scene.validate();
  if (camera.is_thin_lens()) {
    throw OptionsError("render_through_lens needs a camera made from a prescription; use render_through_thin_lens");
  }
  return with_lens_sampler(scene, camera, options, [&](const auto& sample) { return render_progressive(camera, options, sample); });
}

LensRender render_through_thin_lens(const Scene& scene, const Camera& camera, const LensRenderOptions& options) {
  options.validate();
  scene.validate();
  if (!camera.is_thin_lens()) {
    throw OptionsError("render_through_thin_lens needs a Camera::thin_lens camera; use render_through_lens for a prescription");
  }
  return with_thin_lens_sampler(scene, camera, [&](const auto& sample) { return render_progressive(camera, options, sample); });
}

void trace_regions(const Scene& scene, const Camera& camera, std::vector<GatherTraceRequest>& requests, const LensRenderOptions& options) {
  options.validate();
  scene.validate();
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  auto run = [&](const auto& sample) {
#pragma omp parallel for num_threads(threads) schedule(dynamic, 16)
    for (std::size_t k = 0; k < requests.size(); ++k) {
      GatherTraceRequest& r = requests[k];
      Pcg32 rng(options.seed, k, 0);
      // Stratified wavelength, as render_progressive's pixels.
      const double offset = rng.uniform();
      double sum[3] = {0.0, 0.0, 0.0};
      int reached = 0;
      for (int i = 0; i < r.rays; ++i) {
        double node_u = (offset * r.rays + i) / r.rays;
        if (node_u >= 1.0) node_u -= 1.0;
        const SampleResult s = sample(r.x_px + r.size_px * rng.uniform(), r.y_px + r.size_px * rng.uniform(), node_u, rng);
        if (s.fate != SampleFate::ReachedScene) continue;
        ++reached;
        for (int c = 0; c < 3; ++c) sum[c] += s.value[c];
      }
      // The rays the lens stops carry no light: the mean over all rays (as a pixel's estimate).
      for (int c = 0; c < 3; ++c) r.rgb[static_cast<std::size_t>(c)] = static_cast<float>(r.rays > 0 ? sum[c] / r.rays : 0.0);
      r.reached = reached;
    }
    return 0;
  };
  if (camera.is_thin_lens()) {
    with_thin_lens_sampler(scene, camera, run);
  } else {
    with_lens_sampler(scene, camera, options, run);
  }
}

}  // namespace lensmith

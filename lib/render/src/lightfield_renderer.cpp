// Light-field synthesis (Yu, Wang & Yu 2010): per view, every source pixel warped through the ray
// model at one pupil point into a z-buffer (nearest wins), then each output pixel's colour read from
// the source that won it (through a mipmap against undersampling) and averaged over the views.
#include "lensmith/render/lightfield_renderer.h"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <vector>

#include "lensmith/core/errors.h"
#include "lensmith/core/halton.h"
#include "lensmith/core/huge_page_allocator.h"
#include "lensmith/core/units.h"
#include "lensmith/color/spectral_quadrature.h"
#include "illumination_table.h"
#include "image_area_table.h"
#include "light_grid.h"
#include "mip_pyramid.h"
#include "scatter_source.h"

namespace lensmith {

namespace {

// Views warped together: one RayModel::map call per source for all of them.
constexpr std::size_t kViewBatch = 6;

// Per RGB channel, the centroid of its weights over lensmith's spectral quadrature (380-780 nm, 64
// nodes; negative weights left out): the wavelength whose rays carry that channel's light.
std::vector<double> channel_wavelengths_nm() {
  const SpectralQuadrature quadrature;
  std::vector<double> out(3);
  for (std::size_t c = 0; c < 3; ++c) {
    double sum = 0.0, weighted = 0.0;
    for (std::size_t i = 0; i < quadrature.size(); ++i) {
      const double weight = std::max(0.0, quadrature.rgb_weights(i)[static_cast<int>(c)]);
      sum += weight;
      weighted += weight * quadrature.wavelengths_nm()[i];
    }
    out[c] = weighted / sum;
  }
  return out;
}


// `count` Halton points over the pupil (radius^2 and angle, uniform in area), each weighted by its
// share of the iris's area (1 for a circle).
void halton_pupil(const Aperture& aperture, std::size_t count, std::vector<PupilPoint>& points, std::vector<double>& weights) {
  points.resize(count);
  weights.resize(count);
  for (std::size_t k = 0; k < count; ++k) {
    const double theta = 2.0 * kPi * radical_inverse(k + 1, 3);
    const double edge = aperture.edge_radius(theta);
    const double r = std::sqrt(radical_inverse(k + 1, 2)) * edge;
    points[k] = {r * std::cos(theta), r * std::sin(theta)};
    weights[k] = edge * edge;
  }
}

// A source pixel as the views see it.
struct Source {
  ScenePoint point;
  float cone_px = 0.0f;  // the window its colour is read over (mip filter), px
  float light = 1.0f;    // the thin model of a real lens: that lens's brightness here (IlluminationTable)
};

// What one view keeps at an output pixel: the nearest source's inverse depth (float bits, ordered
// as unsigned for non-negative values) above the source's index + 1; 0 where none landed.
using ZEntry = std::uint64_t;
ZEntry z_entry(float inverse_depth, std::uint32_t source) {
  return static_cast<ZEntry>(std::bit_cast<std::uint32_t>(inverse_depth)) << 32 | static_cast<ZEntry>(source + 1);
}

// Nearest wins: `entry` replaces the pixel's if it is nearer (ties: the higher source index).
void claim(LargeVector<ZEntry>& buffer, std::size_t pixel, ZEntry entry) {
  std::atomic_ref<ZEntry> cell(buffer[pixel]);
  ZEntry seen = cell.load(std::memory_order_relaxed);
  while (seen < entry && !cell.compare_exchange_weak(seen, entry, std::memory_order_relaxed)) {
  }
}

}  // namespace

void LightfieldOptions::validate() const {
  if (threads < 0) throw OptionsError("threads must be >= 0 (0 = all), got " + std::to_string(threads));
  if (views < 1 || views > 1024) throw OptionsError("--views must be 1 to 1024 lens-plane views, got " + std::to_string(views));
  if (!(std::isfinite(max_blur_px) && max_blur_px >= 1.0)) {
    throw OptionsError("max blur must be a finite diameter >= 1 px, got " + std::to_string(max_blur_px));
  }
}

std::string LightfieldOptions::to_string() const {
  std::ostringstream os;
  os << "LightfieldOptions(" << views << " views, vignetting " << (vignetting ? "on" : "off") << ", mip filter "
     << (mip_filter ? "on" : "off") << ", threads " << threads << ")";
  return os.str();
}

std::string LightfieldStatistics::to_string() const {
  std::ostringstream os;
  os << "LightfieldStatistics(" << views << " views, " << warps << " warps, " << stopped << " stopped, "
     << holes << " holes, " << unfilled_pixels << " unfilled pixels, " << clamped_depths << " clamped depths)";
  return os.str();
}

Image render_lightfield(const Image& image, const DepthMap& depth, const RayModel& model, const Aperture& aperture,
                        const LightfieldOptions& options, LightfieldStatistics* statistics) {
  options.validate();
  const Camera& camera = model.camera();
  const int w = camera.frame().width_px(), h = camera.frame().height_px();
  render_detail::check_flat_input(image, depth, camera, aperture, "render_lightfield", "lightfield");
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  const auto n_views = static_cast<std::size_t>(options.views);
  const std::size_t pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  LightfieldStatistics stats;
  stats.views = options.views;

  // The views: Halton points over the pupil (halton_pupil).
  std::vector<PupilPoint> pupil;
  std::vector<double> view_weight;
  halton_pupil(aperture, n_views, pupil, view_weight);
  // The wavelengths the views are warped at: the reference, or with colour one per channel, each
  // the centroid of that channel's weights in lensmith's spectral quadrature (the scatter's, 380 to
  // 780 nm), so that each channel's light lands where the lens puts light of its colour.
  std::vector<double> band_nm{camera.reference_wavelength_nm()};
  if (options.spectral) band_nm = channel_wavelengths_nm();
  const std::size_t bands = band_nm.size();

  // The sources: every pixel, and beyond the frame a margin of half the largest blur and the lens's
  // shift of the frame's edges (frame_margin_px) where the picture continues as its edge pixels (as multiview's layers do): without them a view that moves
  // the picture inwards leaves the frame's edge pixels holes, and an object the frame cuts fell off
  // over its last pixels (a disc cut by the right edge: 0.33 of full scale in the last column where
  // the truth has 0.43).
  const double lambda = std::sqrt(kPi / (4.0 * static_cast<double>(n_views)));
  const render_detail::ClampedDepths depths = render_detail::clamped_inverse_depths(camera, depth, options.max_blur_px, threads);
  const std::vector<double>& inverse = depths.inverse;
  const double max_coc_px = depths.max_blur_px;
  stats.clamped_depths = depths.clamped;
  const int margin = render_detail::frame_margin_px(model, 0.5 * max_coc_px);
  const int sw = w + 2 * margin, sh = h + 2 * margin;
  const std::size_t n_sources = static_cast<std::size_t>(sw) * static_cast<std::size_t>(sh);
  // The picture's pixel a source stands for (clamped to the frame).
  auto source_pixel = [&](std::size_t index) {
    const int ex = static_cast<int>(index % static_cast<std::size_t>(sw)), ey = static_cast<int>(index / static_cast<std::size_t>(sw));
    return std::array<int, 2>{std::clamp(ex - margin, 0, w - 1), std::clamp(ey - margin, 0, h - 1)};
  };
  std::vector<Source> sources(n_sources);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int y = 0; y < sh; ++y) {
    for (int x = 0; x < sw; ++x) {
      const std::size_t index = static_cast<std::size_t>(y) * static_cast<std::size_t>(sw) + static_cast<std::size_t>(x);
      const std::array<int, 2> q = source_pixel(index);
      const double w_per_mm = inverse[static_cast<std::size_t>(q[1]) * static_cast<std::size_t>(w) + static_cast<std::size_t>(q[0])];
      const Tangents t = camera.frame().tangents_at({x - margin + 0.5, y - margin + 0.5});
      sources[index].point = {t.x, t.y, w_per_mm};
      sources[index].cone_px = static_cast<float>(lambda * std::abs(camera.signed_coc_px(w_per_mm)));
    }
  }
  // The real lens's brightness across the frame (IlluminationTable) for the models that approximate
  // it: the thin model of a real lens has no pupil geometry of its own; the first-order models' discs
  // stopped every view at a retrofocus's frame edge (lentil 0005 at f/2.65, 0.308 of the centre in
  // the ground truth, black through the paraxial and Seidel models), so their discs are widened as
  // the scatter's are, and each source's light scaled by the table's factor, as the poly model's
  // (its fit's weights). The exact model's own rays carry it.
  const render_detail::IlluminationTable illumination = render_detail::IlluminationTable::where_applies(
      model, aperture, options.vignetting, margin, depths.w_min, depths.w_max, threads);
  if (!illumination.empty()) {
#pragma omp parallel for schedule(static) num_threads(threads)
    for (std::size_t i = 0; i < n_sources; ++i) sources[i].light = illumination.factor(sources[i].point);
  }
  // A pixel takes one source's light per view (nearest wins), where the scatter spreads each
  // source's over its image: where distortion packs more of the scene into an output pixel (barrel,
  // towards a retrofocus's frame edge) the light per pixel grows by 1 / the image area of a source's
  // pixel (ImageAreaTable), which the winner's ray weight alone does not say (the exact model's
  // light was 0.585 of the centre at 0005's frame side, where the ground truth has 0.739).
  if (options.vignetting && render_detail::ImageAreaTable::needed(model)) {
    const render_detail::ImageAreaTable areas(model, margin, depths.w_min, depths.w_max, threads);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int y = 0; y < sh; ++y) {
      for (int x = 0; x < sw; ++x) {
        Source& s = sources[static_cast<std::size_t>(y) * static_cast<std::size_t>(sw) + static_cast<std::size_t>(x)];
        const float area = areas.at(x - margin + 0.5, y - margin + 0.5, s.point.inverse_depth_per_mm);
        if (area > 0.0f) s.light /= area;
      }
    }
  }
  // A set of pupil points mapped as the views are: the first-order models' rays pass the widened
  // discs (their landings do not depend on the discs).
  auto map_views = [&](const ScenePoint& point, double wavelength, std::span<const PupilPoint> set, std::span<SensorHit> hits,
                       std::vector<PupilDisc>& discs) {
    model.map(point, wavelength, set, hits);
    if (!illumination.empty() && illumination.widened_share(point) > 0.0) {
      model.clip_discs(point, discs);
      if (illumination.widen(point, discs)) {
        for (std::size_t j = 0; j < set.size(); ++j) {
          hits[j].clearance = disc_clearance(set[j], discs);
          hits[j].ok = hits[j].unclipped && hits[j].clearance >= 0.0;
        }
      }
    }
  };
  // Each source's light is scaled from the views' share of its beam to that of LightGrid's dense
  // pupil set at its nodes, at the focus plane's depth: the 36 views the whole frame shares measure
  // a cat's eye's share with a bias, as multiview's 64 points did (docs/bokeh.md, "Brightness across
  // the frame").
  if (options.vignetting) {
    std::vector<PupilPoint> dense;
    std::vector<double> dense_weight;
    halton_pupil(aperture, render_detail::kLightSamples, dense, dense_weight);
    const double w_focus =
        std::clamp(std::isfinite(camera.focus_distance_mm()) ? 1.0 / camera.focus_distance_mm() : 0.0, depths.w_min, depths.w_max);
    render_detail::LightGrid ratio(sw, sh, 1.0f);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int j = 0; j < ratio.nodes_y(); ++j) {
      std::vector<SensorHit> hits(std::max(render_detail::kLightSamples, n_views));
      std::vector<PupilDisc> discs;
      auto passing = [&](std::span<const PupilPoint> set, std::span<const double> weight, const ScenePoint& point) {
        std::span<SensorHit> out(hits.data(), set.size());
        map_views(point, camera.reference_wavelength_nm(), set, out, discs);
        double sum = 0.0, total = 0.0;
        for (std::size_t k = 0; k < set.size(); ++k) {
          total += weight[k];
          if (out[k].ok) sum += weight[k] * out[k].weight;
        }
        return total > 0.0 ? sum / total : 0.0;
      };
      for (int i = 0; i < ratio.nodes_x(); ++i) {
        const Tangents t = camera.frame().tangents_at({ratio.node_x_px(i) - margin + 0.5, ratio.node_y_px(j) - margin + 0.5});
        const ScenePoint point{t.x, t.y, w_focus};
        const double views = passing(pupil, view_weight, point);
        // Where every view is stopped nothing can be scaled: left as it is.
        if (views > 1e-6) ratio.at(i, j) = static_cast<float>(passing(dense, dense_weight, point) / views);
      }
    }
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int y = 0; y < sh; ++y) {
      for (int x = 0; x < sw; ++x) {
        sources[static_cast<std::size_t>(y) * static_cast<std::size_t>(sw) + static_cast<std::size_t>(x)].light *= ratio.sample(x, y);
      }
    }
  }
  render_detail::MipPyramid mip;
  if (options.mip_filter) {
    std::vector<std::array<float, 4>> base(pixels);
    for (std::size_t k = 0; k < pixels; ++k) base[k] = {image.data[3 * k], image.data[3 * k + 1], image.data[3 * k + 2], 1.0f};
    mip = render_detail::MipPyramid(std::move(base), w, h);
  }

  // Views are warped kViewBatch at a time: one RayModel::map call per source maps all of them (a
  // call per source and view took about 3 times as long through the Seidel model: 14.0-17.3 s
  // against 4.3-6.2 s at 1080p, docs/performance.md).
  const std::size_t batch = std::min(n_views, kViewBatch);
  LargeVector<ZEntry> zbuffer(pixels * batch), fill(pixels);
  LargeVector<std::array<float, 2>> landing(n_sources * batch);  // per view of the batch and source: where it lands (NaN: nowhere)
  LargeVector<float> landed_weight(n_sources * batch);  // ... and its ray's radiometric weight (0: stopped)
  // Per channel the views' light and their weight (the views that reached the pixel at that
  // channel's wavelength).
  LargeVector<std::array<float, 6>> sum(pixels, std::array<float, 6>{});
  std::size_t warps = 0, stopped = 0, holes = 0;
  const double landing_limit = model.landing_clearance_limit();
  for (std::size_t band = 0; band < bands; ++band) {
    const double wavelength = band_nm[band];
    // The channels this band carries: all three at one wavelength, else its own.
    const std::size_t c0 = bands == 1 ? 0 : band, c1 = bands == 1 ? 3 : band + 1;
    for (std::size_t k0 = 0; k0 < n_views; k0 += batch) {
      const std::size_t count = std::min(batch, n_views - k0);
      std::fill(zbuffer.begin(), zbuffer.end(), ZEntry{0});
      // Warp: every source to where its ray through each view's pupil point lands, nearest wins on
      // the pixel it lands in. A ray the lens stops still claims its pixel, dark (what is behind it
      // is hidden from that pupil point all the same).
  #pragma omp parallel for schedule(dynamic, 4) num_threads(threads) reduction(+ : warps, stopped)
      for (int y = 0; y < sh; ++y) {
        std::array<SensorHit, kViewBatch> hits;
        std::vector<PupilDisc> discs;
        for (int x = 0; x < sw; ++x) {
          const auto index = static_cast<std::uint32_t>(y * sw + x);
          const Source& s = sources[index];
          map_views(s.point, wavelength, std::span<const PupilPoint>(pupil.data() + k0, count), std::span<SensorHit>(hits.data(), count),
                    discs);
          warps += count;
          // A ray lost in the lens (it misses a surface: the exact and poly models' rays past a
          // retrofocus's vignetting cliff) claims, dark, where the source's other views land on
          // average: left out, its pixel took the mean of the views that reached it alone, and the
          // frame's edge through lentil 0005 came out 0.42 of the centre where the truth has 0.31.
          // So does a stopped ray whose landing the model cannot say (RayModel::
          // landing_clearance_limit: the poly model's beyond its fit's training rays): its dark claim
          // went 4-7 px from the beam's other rays, leaving holes, and 0005's frame edge through poly
          // came out 0.365 of the centre, its corner 0.098 (truth 0.308, 0.051).
          if (options.vignetting) {
            auto lands = [landing_limit](const SensorHit& hit) { return hit.ok || (hit.unclipped && hit.clearance >= landing_limit); };
            double mean_x = 0.0, mean_y = 0.0;
            std::size_t landed = 0;
            for (std::size_t j = 0; j < count; ++j) {
              if (!lands(hits[j])) continue;
              mean_x += hits[j].x_mm;
              mean_y += hits[j].y_mm;
              ++landed;
            }
            if (landed > 0 && landed < count) {
              for (std::size_t j = 0; j < count; ++j) {
                if (lands(hits[j])) continue;
                hits[j].x_mm = mean_x / static_cast<double>(landed);
                hits[j].y_mm = mean_y / static_cast<double>(landed);
                hits[j].unclipped = true;
              }
            }
          }
          const ZEntry entry = z_entry(static_cast<float>(s.point.inverse_depth_per_mm), index);
          for (std::size_t j = 0; j < count; ++j) {
            const SensorHit& hit = hits[j];
            const std::size_t slot = j * n_sources + index;
            landing[slot] = {std::numeric_limits<float>::quiet_NaN(), 0.0f};
            if (!hit.ok) ++stopped;
            landed_weight[slot] = hit.ok ? (options.vignetting ? static_cast<float>(hit.weight) * s.light : 1.0f) : 0.0f;
            // Without a landing, or without vignetting a stopped ray is no ray.
            if ((!hit.ok && !hit.unclipped) || (!hit.ok && !options.vignetting)) continue;
            const PixelPoint q = camera.output_pixel(hit.x_mm, hit.y_mm);
            if (!(std::isfinite(q.x) && std::isfinite(q.y)) || q.x < -1.0 || q.y < -1.0 || q.x > w + 1.0 || q.y > h + 1.0) continue;
            landing[slot] = {static_cast<float>(q.x), static_cast<float>(q.y)};
            const int px = static_cast<int>(std::floor(q.x)), py = static_cast<int>(std::floor(q.y));
            if (px < 0 || py < 0 || px >= w || py >= h) continue;
            claim(zbuffer, j * pixels + static_cast<std::size_t>(py) * static_cast<std::size_t>(w) + static_cast<std::size_t>(px), entry);
          }
        }
      }
      for (std::size_t j = 0; j < count; ++j) {
        const std::size_t k = k0 + j;
        ZEntry* const z = zbuffer.data() + j * pixels;
        const std::array<float, 2>* const lands = landing.data() + j * n_sources;
        const float* const weights = landed_weight.data() + j * n_sources;
        // Cracks, as the paper fills them: each source also claims the 2 x 2 pixels around where it
        // lands, but only those no source landed in (nearest wins among those): the grown support
        // over pixels some source lands in would move a sloping surface's colours by up to a pixel
        // and tie a plane in focus to its neighbours.
        std::fill(fill.begin(), fill.end(), ZEntry{0});
  #pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
        for (int y = 0; y < sh; ++y) {
          for (int x = 0; x < sw; ++x) {
            const auto index = static_cast<std::uint32_t>(y * sw + x);
            const std::array<float, 2> q = lands[index];
            if (!std::isfinite(q[0])) continue;
            const int x0 = static_cast<int>(std::floor(q[0] - 0.5f)), y0 = static_cast<int>(std::floor(q[1] - 0.5f));
            const ZEntry entry = z_entry(static_cast<float>(sources[index].point.inverse_depth_per_mm), index);
            for (int dy = 0; dy < 2; ++dy) {
              for (int dx = 0; dx < 2; ++dx) {
                const int px = x0 + dx, py = y0 + dy;
                if (px < 0 || py < 0 || px >= w || py >= h) continue;
                const std::size_t p = static_cast<std::size_t>(py) * static_cast<std::size_t>(w) + static_cast<std::size_t>(px);
                if (z[p] == 0) claim(fill, p, entry);
              }
            }
          }
        }
        // Gather: each pixel's winner's colour and its ray's weight.
        const auto share = static_cast<float>(view_weight[k]);
  #pragma omp parallel for schedule(static) num_threads(threads) reduction(+ : holes)
        for (int y = 0; y < h; ++y) {
          for (int x = 0; x < w; ++x) {
            const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
            const ZEntry e = z[p] != 0 ? z[p] : fill[p];
            if (e == 0) {
              ++holes;
              continue;
            }
            const auto index = static_cast<std::size_t>((e & 0xffffffffu) - 1);
            const auto [sx, sy] = source_pixel(index);
            std::array<float, 3> c{image.at(sx, sy, 0), image.at(sx, sy, 1), image.at(sx, sy, 2)};
            if (options.mip_filter && sources[index].cone_px > 1.0f) {
              const std::array<float, 4> m = mip.window(static_cast<float>(sx) + 0.5f, static_cast<float>(sy) + 0.5f, sources[index].cone_px);
              c = {m[0], m[1], m[2]};
            }
            const float light = weights[index] * share;
            std::array<float, 6>& acc = sum[p];
            for (std::size_t o = c0; o < c1; ++o) {
              acc[o] += light * c[o];
              acc[3 + o] += share;
            }
          }
        }
        if (options.progress) options.progress(static_cast<double>(band * n_views + k + 1) / static_cast<double>(bands * n_views));
      }
    }
  }
  stats.warps = warps;
  stats.stopped = stopped;
  stats.holes = holes;

  // The views' mean per channel; a channel no view reached keeps its input value (a pixel none
  // reached in any channel is counted).
  Image out(w, h, 3);
  std::size_t unfilled = 0;
  for (std::size_t p = 0; p < pixels; ++p) {
    const std::array<float, 6>& acc = sum[p];
    bool reached = false;
    for (std::size_t c = 0; c < 3; ++c) {
      reached = reached || acc[3 + c] > 0.0f;
      out.data[3 * p + c] = acc[3 + c] > 0.0f ? std::max(0.0f, acc[c] / acc[3 + c]) : image.data[3 * p + c];
    }
    if (!reached) ++unfilled;
  }
  stats.unfilled_pixels = unfilled;
  if (statistics) *statistics = stats;
  return out;
}

}  // namespace lensmith

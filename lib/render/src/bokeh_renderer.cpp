// The bokeh renderer's stages in order (docs/bokeh.md; each stage's file says where its method
// comes from): sources from the image and its depth (scatter_source), anti-aliased edge pixels split
// into their two surfaces (mixed_pixels), sharp pixels that nothing blurred reaches set apart to be
// copied (sharp_pixels), depth layers (depth_layers),
// per layer the hidden surfaces behind nearer pixels (hidden_surfaces), footprint planning and the
// deposit into per-thread bands of rows (footprint, with spectral_groups and pupil_mesh_table),
// then front-to-back compositing and the fill of what nothing covers (layer_compositing).
#include "lensmith/render/bokeh_renderer.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <sstream>
#include <vector>

#include "depth_layers.h"
#include "first_touch.h"
#include "footprint.h"
#include "hidden_surfaces.h"
#include "image_circle.h"
#include "illumination_table.h"
#include "image_area_table.h"
#include "layer_compositing.h"
#include "mixed_pixels.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/units.h"
#include "lensmith/render/deep_image.h"
#include "pupil_mesh_table.h"
#include "scatter_source.h"
#include "sharp_pixels.h"
#include "source_merging.h"
#include "spectral_groups.h"

namespace lensmith {

namespace {

using render_detail::DepthLayers;
using render_detail::fault_in;
using render_detail::FootprintPlan;
using render_detail::FootprintScatter;
using render_detail::FootprintScratch;
using render_detail::ScatterSource;
using render_detail::ScatterSources;

// Splat grids: full resolution, 2 x 2 and 4 x 4 px cells (FootprintPlan::level).
constexpr int kLevels = 3;
// A thread's splat buffers by [light | hidden coverage][grid level], and which of them the current
// band uses. Each footprint chooses its own sub-rows within them (footprint_subrows).
struct BandBuffers {
  std::array<std::array<std::optional<SplatBuffer>, kLevels>, 2> buffers;
  std::array<std::array<bool, kLevels>, 2> used{};
  // The band's rows of the layer's image, resolved from the buffers: light, and the hidden coverage.
  // Band-sized: a frame-sized layer image was 16 bytes a pixel of first-touched memory (33 MB at
  // 1080p, docs/performance.md), of which each band used only its own rows.
  std::array<LargeVector<float>, 2> rows;
};
// Bands of rows per thread: each band scatters the footprints that reach it, so a footprint that
// straddles a band's edge is deposited once per band it reaches. Where the model maps a footprint's
// rays (not affine: Seidel, poly, exact) that repeats its dearest work, and fewer, taller bands pay:
// bench/bokeh_bench's Seidel render at 1080p deposited 1.25 footprints per pixel in 8 bands and 1.14
// in 4 (16 px blur; 3.86 -> 3.81 s, and 2.80 -> 2.71 s at 48 px, 3.15 -> 2.92 s at 4 px, medians of 3
// interleaved). An affine model's footprints are cheap stamps, and there 4 bands were no faster than
// 8 on the 600 x 400 street scene (whose bands' memory, first touched per thread, doubles).
constexpr int kBandsPerThreadAffine = 4;
// But a layer of small footprints (blur up to kSmallBlurPx) is scattered in twice as many bands: its
// footprints overlap the next band by a few rows at most, and a band's buffers (32 bytes a pixel of
// its rows) stay in the processor's cache. Street f/4 (every layer under 4 px): deposit 16.92 ->
// 14.99 ms (medians of 21, alternately); 8 bands for every layer cost the fence at 6 m, whose bars
// blur 10 px, 0.3 ms and the portrait at 1 m 3 ms, so larger blurs keep 4.
constexpr int kBandsPerThreadSmallBlur = 8;
constexpr double kSmallBlurPx = 4.0;
constexpr int kBandsPerThreadMapped = 2;
// Sources planned together (FootprintScatter::plan_range): neighbours share mapped shapes within one.
constexpr std::size_t kPlanRange = 256;
// Hidden sources reach half the blur of the layer and of the nearer ones, plus this margin (px): the
// 2 px tent.
constexpr double kHiddenMarginPx = 2.0;
// Where the layer and the nearer ones blur less than this (px) together, nothing hidden shows.
constexpr double kMinHiddenBlurPx = 1.0;

int thread_count(const BokehOptions& options) { return options.threads > 0 ? options.threads : omp_get_max_threads(); }

// The stages after the sources: layers, and per layer hidden surfaces, planning, deposit and
// compositing. `sources` are the parts of the pixels of a w x h picture.
Image render_sources(const ScatterSources& sources, const DepthLayers& layers, int w, int h, int margin, const RayModel& model,
                     const Aperture& aperture, const BokehOptions& options, BokehStatistics& stats) {
  const Camera& camera = model.camera();
  const int threads = thread_count(options);
  const render_detail::SpectralGroups groups(camera, options.spectral, options.spectral_samples);
  const render_detail::PupilMeshTable meshes(aperture);
  // Where the model has distortion, the image area of a pixel over the frame and the sources' depths.
  // Where the model only approximates the lens's brightness across the frame, the real lens's.
  render_detail::ImageAreaTable areas;
  render_detail::IlluminationTable illumination;
  const bool real_illumination = render_detail::IlluminationTable::applies(model, aperture, options.vignetting, true);
  if ((render_detail::ImageAreaTable::needed(model) || real_illumination) && !sources.empty()) {
    double w_min = sources.front().inverse_depth_per_mm, w_max = w_min;
#pragma omp parallel for num_threads(threads) reduction(min : w_min) reduction(max : w_max)
    for (std::size_t i = 0; i < sources.size(); ++i) {
      w_min = std::min(w_min, sources[i].inverse_depth_per_mm);
      w_max = std::max(w_max, sources[i].inverse_depth_per_mm);
    }
    areas = render_detail::ImageAreaTable(model, margin, w_min, w_max, threads);
    if (real_illumination) {
      illumination = render_detail::IlluminationTable(model, meshes.mesh(render_detail::PupilMeshTable::light_mesh()), areas, margin, w_min,
                                                      w_max, threads);
    }
  }
  const FootprintScatter scatter(model, aperture, groups, meshes, areas, illumination, options);
  stats.layer_spacing_px = layers.spacing_px;
  const std::size_t unaimed_before = model.unaimed_rays();

  const bool stretch = options.hidden == HiddenSurfaces::Stretch;
  const std::size_t pixel_count = static_cast<std::size_t>(w) * static_cast<std::size_t>(h), frame_floats = pixel_count * 4;
  // Premultiplied RGB + coverage, zeroed by the threads (a resize to zeros wrote it on one).
  UnconstructedVector<float> result;
  fault_in(result, frame_floats, threads);
  result.resize(frame_floats);
#pragma omp parallel for num_threads(threads) schedule(static)
  for (int y = 0; y < h; ++y) std::fill_n(result.data() + static_cast<std::size_t>(y) * w * 4, static_cast<std::size_t>(w) * 4, 0.0f);
  stats.stages.lap("set-up");
  const auto bands_of = [&](std::size_t layer_index) {
    const int per_thread = !model.affine_in_pupil()                       ? kBandsPerThreadMapped
                           : layers.max_blur_px[layer_index] <= kSmallBlurPx ? kBandsPerThreadSmallBlur
                                                                            : kBandsPerThreadAffine;
    return std::max(1, std::min(h, threads * per_thread));
  };
  std::size_t done = 0;
  std::atomic<std::size_t> footprints{0}, triangles{0}, reused{0};
  // Per thread, its splat buffers, kept from band to band and layer to layer.
  std::vector<BandBuffers> pools(static_cast<std::size_t>(threads));
  // A layer's sources and their plans, kept from layer to layer (their memory is faulted in once).
  // Address space for the largest a layer can be (all sources and as many hidden ones), reserved
  // once: only what a layer touches is faulted in, and no layer copies it to grow.
  ScatterSources layer;
  layer.reserve(sources.size() + static_cast<std::size_t>(w) * h);
  // The plans and the rows each plan may touch, apart (every band scans them all, and 8 bytes a
  // footprint stream faster than its whole plan): written in full by each layer's planning, so not
  // constructed first (WriteFirstArray).
  render_detail::WriteFirstArray<FootprintPlan> plan_store(layer.capacity());
  render_detail::WriteFirstArray<std::array<float, 2>> plan_row_store(layer.capacity());
  std::vector<std::size_t> range_begin;  // of the plan ranges of a layer
  // Per plan range, the rows its footprints may touch (the least y_min, the largest y_max): a band
  // passes over the ranges that do not reach it without looking at their footprints. (A layer's
  // sources come mostly in row order, so a range spans a few rows; each of street f/4's 8 bands
  // looked at all of its 0.24 million footprints.)
  std::vector<std::array<float, 2>> range_rows;
  render_detail::MergeScratch merge_scratch;
  render_detail::HiddenScratch hidden_scratch;
  // Each thread's scratch space, kept from layer to layer (its caches of the table's nodes and light
  // images among it).
  std::vector<FootprintScratch> scratches(static_cast<std::size_t>(threads));
  // Per thread of a layer's copy, where its run's scattered members start in the layer (entry t).
  std::vector<std::size_t> run_scattered(static_cast<std::size_t>(threads) + 1, 0);

  for (int l = 0; l < layers.count; ++l) {
    const auto u = static_cast<std::size_t>(l);
    layer.clear();
    // (Room for the members it scatters: a sharp wall's copied pixels took 11 MB of fresh memory
    // on the fence focused at 6 m.)
    const std::span<const int> members = layers.members(l);
    const std::size_t scattered = members.size() - layers.copied_members[u];
    fault_in(layer, scattered, threads);
    layer.resize(scattered);  // (unconstructed: every element is written below)
    // Copied sharp pixels stay members: the hidden surfaces read them. Each is written to the result
    // as the scatter draws it: all its own light at its own centre, covering the pixel fully, over
    // what the farther layers left there; nothing of this layer reaches it (sharp_pixels.h), so the
    // layer's composite leaves it as it is, and the nearer layers are composited over it.
    // On the threads, each a run of the members, its scattered ones at the place the runs before
    // leave for them (on one thread this took the fence focused at 6 m 1.7-2.5 ms, most of it the
    // sharp wall's copies).
#pragma omp parallel num_threads(threads)
    {
      const auto t = static_cast<std::size_t>(omp_get_thread_num()), team = static_cast<std::size_t>(omp_get_num_threads());
      const std::size_t begin = members.size() * t / team, end = members.size() * (t + 1) / team;
      std::size_t own = 0;
      for (std::size_t k = begin; k < end; ++k) own += sources[static_cast<std::size_t>(members[k])].copied ? 0 : 1;
      run_scattered[t + 1] = own;
#pragma omp barrier
#pragma omp single
      for (std::size_t k = 0; k < team; ++k) run_scattered[k + 1] += run_scattered[k];
      std::size_t at = run_scattered[t];
      for (std::size_t k = begin; k < end; ++k) {
        const auto i = static_cast<std::size_t>(members[k]);
        const ScatterSource& s = sources[i];
        if (!s.copied) {
          layer[at++] = s;
        } else if (i < pixel_count) {  // (a copied edge pixel's copies beyond the frame: nothing)
          float* r = result.data() + 4 * i;
          r[0] = s.rgb[0];
          r[1] = s.rgb[1];
          r[2] = s.rgb[2];
          r[3] = s.coverage;
        }
      }
    }
    stats.stages.lap("layer copies");
    const double hidden_blur = layers.max_blur_px[u] + layers.nearer_blur_px[u];
    // (A layer whose pixels are all copied still has hidden sources: behind a blurred highlight in
    // front of a sharp wall, the wall shows through the highlight's disc.)
    if (!members.empty() && l + 1 < layers.count && hidden_blur >= kMinHiddenBlurPx) {
      const double reach = std::min(0.5 * hidden_blur + kHiddenMarginPx, 0.5 * (w + h));
      stats.hidden_sources += render_detail::append_hidden_sources(sources, layers, l, w, h, reach, options.hidden, camera,
                                                                   threads, hidden_scratch, layer);
    }
    stats.stages.lap("hidden surfaces");
    if (layer.empty()) continue;
    ++stats.layers;
    // Level of detail: sources whose footprints go to a coarse grid, merged by its cells.
    render_detail::merge_coarse_sources(layer, w, h, merge_scratch, margin);
    stats.stages.lap("merging");

    const std::span<FootprintPlan> plans = plan_store.first(layer.size(), threads);
    const std::span<std::array<float, 2>> plan_rows = plan_row_store.first(layer.size(), threads);
    render_detail::plan_range_starts(layer, kPlanRange, range_begin);
    const std::size_t ranges = range_begin.size() - 1;
    range_rows.resize(ranges);
#pragma omp parallel num_threads(threads)
    {
      FootprintScratch& scratch = scratches[static_cast<std::size_t>(omp_get_thread_num())];
#pragma omp for schedule(dynamic, 1)
      for (std::size_t r = 0; r < ranges; ++r) {
        const std::size_t begin = range_begin[r], end = range_begin[r + 1];
        scatter.plan_range(layer, plans, begin, end, scratch);
        std::array<float, 2> rows{std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()};
        for (std::size_t i = begin; i < end; ++i) {
          plan_rows[i] = {plans[i].y_min, plans[i].y_max};
          rows = {std::min(rows[0], plans[i].y_min), std::max(rows[1], plans[i].y_max)};
        }
        range_rows[r] = rows;
      }
    }
    stats.stages.lap("planning");

    const int bands = bands_of(u);
    std::atomic<int> bands_done{0};
    // Each band of rows scatters the footprints that reach it, then composites its rows of this
    // layer over the result so far.
#pragma omp parallel num_threads(threads)
    {
      FootprintScratch& scratch = scratches[static_cast<std::size_t>(omp_get_thread_num())];
      std::size_t local_footprints = 0, local_triangles = 0, local_reused = 0;
#pragma omp for schedule(dynamic, 1)
      for (int b = 0; b < bands; ++b) {
        const int row_begin = b * h / bands, row_end = (b + 1) * h / bands;
        if (row_begin == row_end) continue;
        // A buffer is made only for the grids this band meets in this layer; light and (Stretch) the
        // coverage of hidden sources apart.
        BandBuffers& buffers = pools[static_cast<std::size_t>(omp_get_thread_num())];
        for (auto& set : buffers.used) set.fill(false);
        const float band_top = static_cast<float>(row_begin) - 1.0f, band_bottom = static_cast<float>(row_end) + 1.0f;
        scratch.forget_shape();
        for (std::size_t r = 0; r < ranges; ++r) {
          if (range_rows[r][1] < band_top || range_rows[r][0] > band_bottom) continue;
          for (std::size_t i = range_begin[r]; i < range_begin[r + 1]; ++i) {
            if (plan_rows[i][1] < band_top || plan_rows[i][0] > band_bottom) continue;
            const int level = plans[i].level;
            const std::size_t set = layer[i].coverage_only ? 1 : 0, lv = static_cast<std::size_t>(level);
            // The thread's buffer for this grid, made once and reset for each band.
            std::optional<SplatBuffer>& slot = buffers.buffers[set][lv];
            bool& used = buffers.used[set][lv];
            if (!slot) {
              SplatOptions o = options.splat;
              o.downsample = 1 << level;
              slot.emplace(w, row_begin, row_end, o);
            } else if (!used) {
              slot->reset(row_begin, row_end);
            }
            used = true;
            if (!scatter.deposit_planned_point(layer[i], plans[i], *slot)) {
              scatter.deposit(layer[i], plans[i], i, *slot, scratch, local_triangles, local_reused);
            }
            // A footprint cross-faded between two group counts deposits both splits.
            local_footprints += static_cast<std::size_t>(plans[i].groups + (plans[i].blend < 1.0f ? plans[i].groups - 1 : 0));
          }
        }
        // The rows of the band this layer reaches are resolved and composited over the result; the
        // others are left as they are (the layer is empty there; its image is not even cleared).
        int first = row_end, end = row_begin;
        for (std::size_t set = 0; set < 2; ++set) {
          for (std::size_t lv = 0; lv < static_cast<std::size_t>(kLevels); ++lv) {
            if (!buffers.used[set][lv]) continue;
            const auto [touched_first, touched_end] = buffers.buffers[set][lv]->touched_rows();
            if (touched_first >= touched_end) continue;
            first = std::min(first, touched_first);
            end = std::max(end, touched_end);
          }
        }
        if (first < end) {
          const std::size_t row_floats = static_cast<std::size_t>(w) * 4;
          const std::size_t skip = static_cast<std::size_t>(first - row_begin) * row_floats;
          for (std::size_t set = 0; set < (stretch ? 2u : 1u); ++set) {
            LargeVector<float>& rows = buffers.rows[set];
            rows.resize(static_cast<std::size_t>(row_end - row_begin) * row_floats);
            std::fill(rows.begin() + static_cast<std::ptrdiff_t>(skip),
                      rows.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(end - row_begin) * row_floats), 0.0f);
            for (std::size_t lv = 0; lv < static_cast<std::size_t>(kLevels); ++lv) {
              if (buffers.used[set][lv]) buffers.buffers[set][lv]->resolve_rows_into(rows.data());
            }
          }
          render_detail::composite_layer_over(buffers.rows[0].data() + skip, stretch ? buffers.rows[1].data() + skip : nullptr, result, w,
                                              first, end);
        }
        // Progress in even steps: this layer's share of the sources times the bands it has done.
        if (options.progress) {
          const double fraction = (static_cast<double>(done) + static_cast<double>(members.size()) *
                                                                    static_cast<double>(++bands_done) / bands) /
                                  static_cast<double>(sources.size());
#pragma omp critical(lensmith_bokeh_progress)
          options.progress(fraction);
        }
      }
      footprints += local_footprints;
      triangles += local_triangles;
      reused += local_reused;
    }
    // This layer's light images freed (FootprintScatter::forget_light_images says why).
    scatter.forget_light_images();
    for (FootprintScratch& scratch : scratches) scratch.forget_light_images();
    done += members.size();
    if (options.progress) options.progress(static_cast<double>(done) / static_cast<double>(sources.size()));
    stats.stages.lap("deposit");
  }
  stats.footprints = footprints;
  stats.triangles = triangles;
  stats.light_images = scatter.light_images();
  stats.reused_shapes = reused;
  stats.unaimed_rays = model.unaimed_rays() - unaimed_before;
  LargeVector<render_detail::PushPullCell<5>> fill_cells;  // where some gap needs the push-pull fill
  // The lens's image circle, where some pixel is left uncovered (a fisheye's frame corners).
  const bool gaps = render_detail::has_gaps(result, threads);
  const render_detail::ImageCircle circle = gaps ? render_detail::ImageCircle(camera, threads) : render_detail::ImageCircle();
  Image out = render_detail::finish_composite(result, w, h, threads, gaps, fill_cells, hidden_scratch.push_pull, circle);
  stats.stages.lap("finishing");
  return out;
}

// Sources beyond a w x h frame over `margin` px each side, copies of the nearest edge pixel's parts
// (every source of that pixel: a split pixel's two parts, a layered input's samples) at their own
// positions. `pixels_first`: the first w x h sources are the frame's pixels in row order (a flat
// picture's; only their edge pixels are visited, then the sources after them).
void add_margin_sources(ScatterSources& sources, int w, int h, int margin, bool pixels_first) {
  if (margin <= 0) return;
  // Only the frame's edge pixels are copied: their sources are indexed by a slot per edge pixel
  // (top row, bottom row, left and right columns between), in source order. (Indexing every pixel
  // of the frame took the street scene's process 3-4 ms on one thread.)
  auto slot_of = [w, h](int x, int y) -> int {
    if (y == 0) return x;
    if (y == h - 1) return w + x;
    if (x == 0) return 2 * w + (y - 1);
    if (x == w - 1) return 2 * w + h + (y - 1);
    return -1;
  };
  const std::size_t slots = 2 * static_cast<std::size_t>(w) + 2 * static_cast<std::size_t>(h);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edge;  // (slot, source), in source order
  auto visit = [&](std::size_t i) {
    const ScatterSource& s = sources[i];
    if (s.x < 0 || s.y < 0 || s.x >= w || s.y >= h) return;
    const int slot = slot_of(s.x, s.y);
    if (slot >= 0) edge.emplace_back(static_cast<std::uint32_t>(slot), static_cast<std::uint32_t>(i));
  };
  const std::size_t frame = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  std::size_t rest = 0;  // the first source not yet visited
  if (pixels_first && sources.size() >= frame) {
    for (int y = 0; y < h; ++y) {
      const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
      if (y == 0 || y == h - 1) {
        for (int x = 0; x < w; ++x) visit(row + static_cast<std::size_t>(x));
      } else {
        visit(row);
        if (w > 1) visit(row + static_cast<std::size_t>(w - 1));
      }
    }
    rest = frame;
  }
  for (std::size_t i = rest; i < sources.size(); ++i) visit(i);
  std::vector<std::uint32_t> begin(slots + 1, 0);
  for (const auto& [slot, i] : edge) ++begin[slot + 1];
  for (std::size_t k = 0; k < slots; ++k) begin[k + 1] += begin[k];
  std::vector<std::uint32_t> of_slot(edge.size());
  {
    std::vector<std::uint32_t> next(begin.begin(), begin.end() - 1);
    for (const auto& [slot, i] : edge) of_slot[next[slot]++] = i;
  }
  auto edge_slot = [&](int x, int y) {
    return static_cast<std::size_t>(slot_of(std::clamp(x, 0, w - 1), std::clamp(y, 0, h - 1)));
  };
  std::size_t count = 0;
  for (int y = -margin; y < h + margin; ++y) {
    for (int x = -margin; x < w + margin; ++x) {
      if (x >= 0 && y >= 0 && x < w && y < h) continue;
      const std::size_t k = edge_slot(x, y);
      count += begin[k + 1] - begin[k];
    }
  }
  sources.reserve(sources.size() + count);
  for (int y = -margin; y < h + margin; ++y) {
    for (int x = -margin; x < w + margin; ++x) {
      if (x >= 0 && y >= 0 && x < w && y < h) continue;
      const std::size_t k = edge_slot(x, y);
      for (std::uint32_t j = begin[k]; j < begin[k + 1]; ++j) {
        ScatterSource s = sources[of_slot[j]];
        s.x = x;
        s.y = y;
        sources.push_back(s);
      }
    }
  }
}

// Checks that the picture has the camera's framing.
void check_framing(const RayModel& model, int width, int height, const std::string& what) {
  const PinholeFrame& frame = model.camera().frame();
  if (width != frame.width_px() || height != frame.height_px()) {
    throw OptionsError("the camera was framed for " + std::to_string(frame.width_px()) + " x " + std::to_string(frame.height_px()) +
                       " but the " + what + " is " + std::to_string(width) + " x " + std::to_string(height));
  }
}

}  // namespace

std::string_view to_string(HiddenSurfaces h) { return h == HiddenSurfaces::Extend ? "extend" : "stretch"; }

HiddenSurfaces parse_hidden_surfaces(std::string_view text) {
  if (text == "extend") return HiddenSurfaces::Extend;
  if (text == "stretch") return HiddenSurfaces::Stretch;
  throw OptionsError("unknown hidden-surface rule '" + std::string(text) + "': expected extend or stretch");
}

void BokehOptions::validate() const {
  if (threads < 0) throw OptionsError("threads must be >= 0 (0 = all), got " + std::to_string(threads));
  splat.validate();
  if (!(std::isfinite(layer_spacing_px) && layer_spacing_px > 0.0)) {
    throw OptionsError("layer spacing must be a finite blur step > 0 px, got " + format_number(layer_spacing_px));
  }
  if (max_layers < 1 || max_layers > 1024) throw OptionsError("max layers must be 1..1024, got " + std::to_string(max_layers));
  if (spectral_samples < 3 || spectral_samples > 64) {
    throw OptionsError("spectral samples must be 3..64, got " + std::to_string(spectral_samples));
  }
  if (!(std::isfinite(chromatic_tolerance_px) && chromatic_tolerance_px > 0.0)) {
    throw OptionsError("chromatic tolerance must be > 0 px, got " + format_number(chromatic_tolerance_px));
  }
  if (!(std::isfinite(max_blur_px) && max_blur_px >= 1.0)) {
    throw OptionsError("max blur must be a finite diameter >= 1 px, got " + format_number(max_blur_px));
  }
}

std::string BokehOptions::to_string() const {
  std::ostringstream os;
  os << "BokehOptions(threads " << threads << ", " << splat.to_string() << ", layer spacing " << layer_spacing_px
     << " px, max layers " << max_layers << ", hidden " << lensmith::to_string(hidden) << ", spectral "
     << (spectral ? std::to_string(spectral_samples) + " nodes" : std::string("off")) << ", chromatic tolerance "
     << chromatic_tolerance_px << " px, max blur " << max_blur_px << " px" << (reuse_shapes ? "" : ", shapes not reused") << (interpolated_rays ? "" : ", rays per pixel")
     << (copy_sharp_pixels ? "" : ", sharp pixels scattered") << ")";
  return os.str();
}

std::string BokehStatistics::to_string() const {
  std::ostringstream os;
  os << "BokehStatistics(" << layers << " layers at " << layer_spacing_px << " px, " << source_pixels << " pixels, "
     << hidden_sources << " hidden sources, " << split_edge_pixels << " edge pixels split, " << redepthed_edge_pixels
     << " moved, " << copied_pixels << " sharp pixels copied, " << footprints << " footprints, " << triangles << " triangles, " << reused_shapes << " shapes reused, "
     << clamped_depths << " clamped depths, max |CoC| " << max_abs_coc_px << " px";
  if (deep_samples > 0) os << ", " << deep_samples << " deep samples, " << volume_slabs << " volume slabs";
  if (unaimed_rays > 0) os << ", " << unaimed_rays << " rays not aimed";
  if (edge_gap_px > 0.0) os << ", input's edge " << edge_gap_px << " px inside the frame";
  os << ")";
  return os.str();
}

Image render_bokeh(const Image& image, const DepthMap& depth, const RayModel& model, const Aperture& aperture,
                   const BokehOptions& options, BokehStatistics* statistics) {
  options.validate();
  if (image.channels != 3) throw OptionsError("the bokeh renderer takes a 3-channel linear RGB image, got " + image.to_string());
  if (image.width != depth.width || image.height != depth.height) {
    throw OptionsError("image is " + std::to_string(image.width) + " x " + std::to_string(image.height) +
                       " but depth is " + std::to_string(depth.width) + " x " + std::to_string(depth.height));
  }
  check_framing(model, image.width, image.height, "image");
  for (std::size_t i = 0; i < depth.z_m.size(); ++i) {
    if (!(depth.z_m[i] > 0.0f)) {
      throw OptionsError("depth at pixel (" + std::to_string(i % static_cast<std::size_t>(depth.width)) + ", " +
                         std::to_string(i / static_cast<std::size_t>(depth.width)) + ") is " +
                         format_number(depth.z_m[i]) + " m: the renderer needs depths > 0");
    }
  }
  BokehStatistics local;
  BokehStatistics& stats = statistics ? *statistics : local;
  stats.stages.restart();
  const Camera& camera = model.camera();
  const int w = image.width, h = image.height, threads = thread_count(options);
  ScatterSources sources = render_detail::make_scatter_sources(image, depth, camera, options, threads, stats);
  stats.stages.lap("sources");
  if (options.split_edge_pixels) render_detail::split_mixed_pixels(sources, w, h, camera, threads, stats);
  stats.stages.lap("edge split");
  const int margin = render_detail::frame_margin_px(model, 0.5 * stats.max_abs_coc_px);
  stats.edge_gap_px = render_detail::frame_edge_gap_px(model);
  const render_detail::LayerSpacing spacing = render_detail::layer_spacing_of(sources, options.layer_spacing_px, options.max_layers, threads);
  if (render_detail::copies_sharp_pixels(model, aperture, options)) {
    stats.copied_pixels = render_detail::mark_sharp_pixels(sources, w, h, spacing, threads);
  }
  stats.stages.lap("sharp pixels");
  add_margin_sources(sources, w, h, margin, true);
  const DepthLayers layers = render_detail::make_depth_layers(sources, w, h, spacing, threads, true);
  stats.stages.lap("layering");
  return render_sources(sources, layers, w, h, margin, model, aperture, options, stats);
}

Image render_bokeh(const DeepImage& deep, const RayModel& model, const Aperture& aperture, const BokehOptions& options,
                   BokehStatistics* statistics) {
  options.validate();
  check_framing(model, deep.width, deep.height, "deep image");
  if (deep.first_sample.size() != static_cast<std::size_t>(deep.width) * static_cast<std::size_t>(deep.height) + 1) {
    throw OptionsError("the deep image has samples for " + std::to_string(deep.first_sample.size() - 1) + " pixels of its " +
                       std::to_string(deep.width) + " x " + std::to_string(deep.height));
  }
  BokehStatistics local;
  BokehStatistics& stats = statistics ? *statistics : local;
  stats.stages.restart();
  // Edge pixels need no split: a layered input has each surface of a pixel as its own sample.
  render_detail::DeepSources deep_sources = render_detail::make_deep_sources(deep, model.camera(), options, stats);
  stats.deep_samples = deep_sources.samples;
  stats.volume_slabs = deep_sources.volume_slabs;
  stats.stages.lap("sources");
  const int margin = render_detail::frame_margin_px(model, 0.5 * stats.max_abs_coc_px);
  ScatterSources sources = std::move(deep_sources.sources);
  stats.edge_gap_px = render_detail::frame_edge_gap_px(model);
  add_margin_sources(sources, deep.width, deep.height, margin, false);
  const DepthLayers layers =
      render_detail::make_depth_layers(sources, deep.width, deep.height, deep_sources.spacing, thread_count(options), false);
  stats.stages.lap("layering");
  return render_sources(sources, layers, deep.width, deep.height, margin, model, aperture, options, stats);
}

}  // namespace lensmith

// Lee, Eisemann & Seidel's multiview synthesis through the ray model's lens rays
// (multiview_renderer.h says what the paper does and what lensmith does differently).
#include "lensmith/render/multiview_renderer.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <vector>

#include <Eigen/Dense>

#include "illumination_table.h"
#include "image_area_table.h"
#include "lens_ray_table.h"
#include "light_grid.h"
#include "mip_pyramid.h"
#include "spectral_groups.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/halton.h"
#include "lensmith/core/huge_page_allocator.h"
#include "lensmith/core/split_mix.h"
#include "lensmith/core/units.h"

namespace lensmith {

using render_detail::MipPyramid;

namespace {

constexpr int kTilePx = 16;                    // early culling: occupancy per layer on tiles of this size
constexpr float kOpaque = 1e-4f;               // a ray whose remaining transmittance is below this stops
constexpr double kLayerOverlap = 0.25;         // share of the layer spacing a sample reaches into the next layer
constexpr double kConnectPx = 1.0;             // neighbouring samples whose signed CoC differs less are one surface (px)
constexpr std::size_t kMaxBands = 8;           // wavelength bands a pupil point may be traced in
constexpr float kChromaticTolerancePx = 0.5f;  // bands closer than this follow one ray (BokehOptions' default)

// A layer's sample at one pixel: inverse depth (1/mm; < 0: none) and where its colour is.
struct Cell {
  float w = -1.0f;
  std::uint32_t colour = 0;
};

struct Layers {
  int count = 1;
  int width = 0, height = 0, tiles_x = 0, tiles_y = 0;
  std::vector<float> w_near, w_far;  // per layer, inverse depth bounds (1/mm), near >= far
  float overlap = 0.0f;              // samples this close to a bound (1/mm) are in the neighbouring layer too
  float connect = 0.0f;              // neighbouring samples closer than this (1/mm) are one continuous surface
  std::vector<Cell, HugePageAllocator<Cell>> cells;                       // [layer][y][x]
  std::vector<std::array<float, 4>, HugePageAllocator<std::array<float, 4>>> colours;  // premultiplied RGB, alpha
  std::vector<std::uint8_t> occupied;                                    // [layer][tile]
  std::vector<std::uint8_t> layer_used;
  const Cell& cell(int l, int x, int y) const {
    return cells[(static_cast<std::size_t>(l) * height + static_cast<std::size_t>(y)) * width + static_cast<std::size_t>(x)];
  }
};

// Splits the samples into layers evenly spaced in inverse depth (= in signed CoC, Lee et al. eq. 4),
// compositing a pixel's samples of one layer front to back.
Layers make_layers(const DeepImage& scene, int layer_count, double& w_min_out, double& w_max_out) {
  Layers layers;
  layers.width = scene.width;
  layers.height = scene.height;
  double w_min = std::numeric_limits<double>::infinity(), w_max = -w_min;
  for (const DeepSample& s : scene.samples) {
    if (!(s.alpha > 0.0f)) continue;
    const double w = inverse_depth_per_mm(s.z_m);
    w_min = std::min(w_min, w);
    w_max = std::max(w_max, w);
  }
  if (!(w_max >= w_min)) w_min = w_max = 0.0;  // no sample covers anything
  w_min_out = w_min;
  w_max_out = w_max;
  layers.count = w_max > w_min ? layer_count : 1;
  const double step = (w_max - w_min) / layers.count;
  layers.overlap = static_cast<float>(kLayerOverlap * step);
  for (int l = 0; l < layers.count; ++l) {
    layers.w_near.push_back(static_cast<float>(w_max - l * step));
    layers.w_far.push_back(static_cast<float>(l + 1 == layers.count ? w_min : w_max - (l + 1) * step));
  }
  const std::size_t pixels = static_cast<std::size_t>(scene.width) * static_cast<std::size_t>(scene.height);
  layers.cells.assign(pixels * static_cast<std::size_t>(layers.count), Cell{});
  layers.colours.reserve(scene.samples.size());
  layers.tiles_x = (scene.width + kTilePx - 1) / kTilePx;
  layers.tiles_y = (scene.height + kTilePx - 1) / kTilePx;
  layers.occupied.assign(static_cast<std::size_t>(layers.tiles_x) * layers.tiles_y * layers.count, 0);
  layers.layer_used.assign(static_cast<std::size_t>(layers.count), 0);
  for (std::size_t p = 0; p < pixels; ++p) {
    const int x = static_cast<int>(p % static_cast<std::size_t>(scene.width)), y = static_cast<int>(p / static_cast<std::size_t>(scene.width));
    for (std::uint64_t k = scene.first_sample[p]; k < scene.first_sample[p + 1]; ++k) {
      const DeepSample& s = scene.samples[k];
      if (!(s.alpha > 0.0f)) continue;
      const double w = inverse_depth_per_mm(s.z_m);
      // Its layer, and the neighbouring one where it lies within the overlap of their bound (Lee et
      // al. sec. 4.2 overlap layers by 10 %, against seams; here a quarter of the spacing each side,
      // so that a surface sloping across a bound is continuous in both).
      const double position = step > 0.0 ? (w_max - w) / step : 0.0;
      const int home = std::clamp(static_cast<int>(position), 0, layers.count - 1);
      const double within = position - home;
      const int neighbour = within < kLayerOverlap && home > 0 ? home - 1 : within > 1.0 - kLayerOverlap && home + 1 < layers.count ? home + 1 : home;
      const std::array<int, 2> targets{home, neighbour};
      for (std::size_t i = 0; i < (neighbour == home ? 1u : 2u); ++i) {
        const int l = targets[i];
        Cell& c = layers.cells[static_cast<std::size_t>(l) * pixels + p];
        if (c.w < 0.0f) {
          c.w = static_cast<float>(w);
          c.colour = static_cast<std::uint32_t>(layers.colours.size());
          layers.colours.push_back({s.rgb[0], s.rgb[1], s.rgb[2], s.alpha});
          layers.occupied[(static_cast<std::size_t>(l) * layers.tiles_y + static_cast<std::size_t>(y / kTilePx)) * layers.tiles_x +
                          static_cast<std::size_t>(x / kTilePx)] = 1;
          layers.layer_used[static_cast<std::size_t>(l)] = 1;
        } else {
          // Behind the layer's nearer samples of this pixel: "over", front to back.
          std::array<float, 4>& q = layers.colours[c.colour];
          const float t = 1.0f - q[3];
          for (int ch = 0; ch < 3; ++ch) q[static_cast<std::size_t>(ch)] += t * s.rgb[static_cast<std::size_t>(ch)];
          q[3] += t * s.alpha;
        }
      }
    }
  }
  return layers;
}

// Approximate cone tracing (Lee et al. sec. 4.4): each layer's premultiplied colour and coverage
// (0 where the layer has no sample) as a mipmap (mip_pyramid.h); a ray that hits a layer takes the
// mean over the window its cone covers there instead of the one cell, as the share v of the cone
// the layer blocks, and goes on with the rest.
std::vector<MipPyramid> make_pyramids(const Layers& layers, int threads) {
  std::vector<MipPyramid> out(static_cast<std::size_t>(layers.count));
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (int l = 0; l < layers.count; ++l) {
    if (!layers.layer_used[static_cast<std::size_t>(l)]) continue;  // never hit
    const int w = layers.width, h = layers.height;
    std::vector<std::array<float, 4>> base(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), std::array<float, 4>{});
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const Cell& c = layers.cell(l, x, y);
        if (c.w >= 0.0f) base[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)] = layers.colours[c.colour];
      }
    }
    out[static_cast<std::size_t>(l)] = MipPyramid(std::move(base), w, h);
  }
  return out;
}

// What a ray's cone is: its diameter at inverse depth w is lambda |C(w)|, C the signed CoC (px),
// linear in w (Lee et al.: lambda the mean distance between lens samples, as a share of the pupil's
// diameter).
struct Cones {
  const std::vector<MipPyramid>* pyramids = nullptr;  // null: no cone tracing
  float lambda = 0.0f;
  float coc_per_w = 0.0f, coc_at_infinity = 0.0f;
};

// What one ray brought back.
struct RayResult {
  std::array<float, 3> colour{};  // premultiplied radiance it met, each hit weighted by what was left of the ray
  float transmittance = 1.0f;     // what passed every layer
  bool left_frame = false;         // it read the layers beyond the frame (as their edge pixels)
  std::size_t cells = 0;
};

// Follows the ray p(w) = inf + w k through the layers, nearest first (Lee et al. sec. 4.3), walking
// each layer's segment cell by cell. The ray hits a cell's sample where it crosses the sample's
// depth inside the cell, or where it steps from in front of the previous cell's sample to behind
// this one's (the surface is taken to be continuous between neighbouring samples of one layer, so a
// sloping surface is not missed between pixel centres; samples whose blur differs by more than
// kConnectPx are not one surface, whatever the layers). Unlike the paper's height field, a ray that
// passes behind a sample from the side (behind a foreground edge) does not hit it: it goes on to
// what the deeper layers hold there. A hit of alpha < 1 lets the rest of the ray go on.
RayResult follow(const Layers& layers, const PixelRay& ray, const Cones& cones) {
  RayResult r;
  float last_hit_w = std::numeric_limits<float>::infinity();  // layers overlap: a sample is hit once
  for (int l = 0; l < layers.count && r.transmittance > kOpaque; ++l) {
    if (!layers.layer_used[static_cast<std::size_t>(l)]) continue;
    // The layer's interval widened by the overlap its samples were copied into.
    const float w0 = layers.w_near[static_cast<std::size_t>(l)] + layers.overlap;
    const float w1 = layers.w_far[static_cast<std::size_t>(l)] - layers.overlap;
    const float x0 = ray.inf_x + w0 * ray.k_x, y0 = ray.inf_y + w0 * ray.k_y;
    const float x1 = ray.inf_x + w1 * ray.k_x, y1 = ray.inf_y + w1 * ray.k_y;
    // Early culling: no tile of this layer under the segment holds a sample.
    {
      const int tx0 = std::clamp(static_cast<int>(std::floor(std::min(x0, x1))) / kTilePx, 0, layers.tiles_x - 1);
      const int tx1 = std::clamp(static_cast<int>(std::floor(std::max(x0, x1))) / kTilePx, 0, layers.tiles_x - 1);
      const int ty0 = std::clamp(static_cast<int>(std::floor(std::min(y0, y1))) / kTilePx, 0, layers.tiles_y - 1);
      const int ty1 = std::clamp(static_cast<int>(std::floor(std::max(y0, y1))) / kTilePx, 0, layers.tiles_y - 1);
      bool any = false;
      for (int ty = ty0; ty <= ty1 && !any; ++ty) {
        const std::uint8_t* row = layers.occupied.data() + (static_cast<std::size_t>(l) * layers.tiles_y + ty) * layers.tiles_x;
        for (int tx = tx0; tx <= tx1; ++tx) any = any || row[tx];
      }
      if (!any) continue;
    }
    // Amanatides & Woo's walk over the pixel cells of the segment, s in [0, 1] along it.
    const float dx = x1 - x0, dy = y1 - y0;
    int cx = static_cast<int>(std::floor(x0)), cy = static_cast<int>(std::floor(y0));
    const int ex = static_cast<int>(std::floor(x1)), ey = static_cast<int>(std::floor(y1));
    const int step_x = dx > 0.0f ? 1 : -1, step_y = dy > 0.0f ? 1 : -1;
    const float inf = std::numeric_limits<float>::infinity();
    const float delta_x = dx != 0.0f ? 1.0f / std::abs(dx) : inf, delta_y = dy != 0.0f ? 1.0f / std::abs(dy) : inf;
    float next_x = dx != 0.0f ? (static_cast<float>(cx + (dx > 0.0f ? 1 : 0)) - x0) / dx : inf;
    float next_y = dy != 0.0f ? (static_cast<float>(cy + (dy > 0.0f ? 1 : 0)) - y0) / dy : inf;
    int steps_left = std::abs(ex - cx) + std::abs(ey - cy) + 1;
    float s_in = 0.0f;
    bool in_front_of_previous = false;  // the previous cell held a sample the ray left in front of
    float previous_w = 0.0f;
    while (steps_left-- > 0) {
      const float s_out = std::min({next_x, next_y, 1.0f});
      ++r.cells;
      // Beyond the frame the layers continue as their edge pixels (Lee et al. discard such rays,
      // which darkens or renormalises every blurred pixel near the border; a scene usually goes on
      // past the frame as it is at its edge).
      const bool outside = cx < 0 || cy < 0 || cx >= layers.width || cy >= layers.height;
      r.left_frame = r.left_frame || outside;
      const Cell& c = layers.cell(l, std::clamp(cx, 0, layers.width - 1), std::clamp(cy, 0, layers.height - 1));
      if (c.w < 0.0f) {
        in_front_of_previous = false;
      } else {
        const float w_in = w0 + s_in * (w1 - w0), w_out = w0 + s_out * (w1 - w0);
        const bool crosses = c.w <= w_in && c.w >= w_out;
        const bool steps_behind = in_front_of_previous && c.w > w_in && std::abs(c.w - previous_w) < layers.connect;
        if ((crosses || steps_behind) && c.w < last_hit_w) {
          std::array<float, 4> q = layers.colours[c.colour];
          bool cone = false;
          if (cones.pyramids) {
            const float diameter = cones.lambda * std::abs(cones.coc_per_w * c.w + cones.coc_at_infinity);
            if (diameter > 1.0f) {
              q = (*cones.pyramids)[static_cast<std::size_t>(l)].window(ray.inf_x + c.w * ray.k_x, ray.inf_y + c.w * ray.k_y, diameter);
              cone = true;
            }
          }
          for (std::size_t ch = 0; ch < 3; ++ch) r.colour[ch] += r.transmittance * q[ch];
          r.transmittance *= 1.0f - q[3];
          // A cone's window sees only this layer's share of a surface that runs on into the next
          // layer (a floor crossing the layers' bounds): the rest of the cone may meet it there.
          if (!cone) last_hit_w = c.w;
          if (r.transmittance <= kOpaque) break;
        }
        in_front_of_previous = w_out > c.w;
        previous_w = c.w;
      }
      if (s_out >= 1.0f) break;
      s_in = s_out;
      if (next_x < next_y) {
        cx += step_x;
        next_x += delta_x;
      } else {
        cy += step_y;
        next_y += delta_y;
      }
    }
  }
  return r;
}

}  // namespace

void MultiviewOptions::validate() const {
  if (threads < 0) throw OptionsError("threads must be >= 0 (0 = all), got " + std::to_string(threads));
  if (samples < 1 || samples > 4096) throw OptionsError("--samples must be 1 to 4096 lens rays per pixel, got " + std::to_string(samples));
  if (layers < 1 || layers > 64) throw OptionsError("--layers must be 1 to 64, got " + std::to_string(layers));
  if (spectral_samples < 3 || spectral_samples > 64) {
    throw OptionsError("--spectral-samples must be 3 to 64, got " + std::to_string(spectral_samples));
  }
  if (ray_grid_px < 1 || ray_grid_px > 64) throw OptionsError("the lens ray grid must be 1 to 64 px, got " + std::to_string(ray_grid_px));
}

std::string MultiviewOptions::to_string() const {
  std::ostringstream os;
  os << "MultiviewOptions(" << samples << " samples, " << layers << " layers, vignetting " << (vignetting ? "on" : "off")
     << ", spectral " << (spectral ? std::to_string(spectral_samples) + " nodes" : std::string("off")) << ", ray grid " << ray_grid_px
     << " px, cone tracing " << (cone_tracing ? "on" : "off") << ", threads " << threads << ")";
  return os.str();
}

std::string MultiviewStatistics::to_string() const {
  std::ostringstream os;
  os << "MultiviewStatistics(" << layers << " layers " << layer_spacing_px << " px apart, " << rays << " rays, " << stopped_rays
     << " stopped, " << lost_rays << " lost, " << cells_visited << " cells, " << direct_rays << " direct)";
  return os.str();
}

DeepImage deep_image_from_flat(const Image& image, const DepthMap& depth) {
  if (image.channels != 3 || image.width != depth.width || image.height != depth.height) {
    throw OptionsError("a flat picture for multiview needs 3 channels and a depth map of its size");
  }
  DeepImage deep;
  deep.width = image.width;
  deep.height = image.height;
  const std::size_t n = image.pixel_count();
  deep.first_sample.resize(n + 1);
  deep.samples.resize(n);
  for (std::size_t p = 0; p < n; ++p) {
    deep.first_sample[p] = p;
    DeepSample& s = deep.samples[p];
    s.rgb = {image.data[3 * p], image.data[3 * p + 1], image.data[3 * p + 2]};
    s.alpha = 1.0f;
    s.z_m = s.z_back_m = depth.z_m[p];
  }
  deep.first_sample[n] = n;
  return deep;
}

Image render_multiview(const DeepImage& scene, const RayModel& model, const Aperture& aperture, const MultiviewOptions& options,
                       MultiviewStatistics* statistics) {
  options.validate();
  const Camera& camera = model.camera();
  const int width = camera.frame().width_px(), height = camera.frame().height_px();
  if (scene.width != width || scene.height != height) {
    throw OptionsError("the layered scene is " + std::to_string(scene.width) + " x " + std::to_string(scene.height) +
                       " px, the camera frames " + std::to_string(width) + " x " + std::to_string(height));
  }
  double w_min = 0.0, w_max = 0.0;
  Layers layers = make_layers(scene, options.layers, w_min, w_max);
  {
    // Signed CoC is linear in inverse depth: its slope turns kConnectPx into inverse depth.
    const double slope = std::abs(camera.signed_coc_px(1e-3) - camera.signed_coc_px(0.0)) / 1e-3;
    layers.connect = static_cast<float>(slope > 0.0 ? kConnectPx / slope : std::numeric_limits<double>::infinity());
  }
  const bool opaque = scene.max_transparency() <= 1e-4;
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  // The real lens's brightness across the frame for the models that only approximate it: the thin
  // model of a real lens (no pupil geometry of its own) and the first-order models, whose discs
  // stopped every ray at a retrofocus's frame edge (lentil 0005 at f/2.65: black where the ground
  // truth has 0.31 of the centre) and are widened as the scatter's are (LensRayTableOptions). Each
  // pixel takes the table's factor at the focus plane's depth, within the scene's. The exact and poly
  // models' rays are traced through the lens or its fit, with pbrt's weights.
  const bool first_order = model.kind() == RayModelKind::Paraxial || model.kind() == RayModelKind::Seidel;
  const render_detail::IlluminationTable illumination =
      render_detail::IlluminationTable::where_applies(model, aperture, options.vignetting, 0, w_min, w_max, threads, !first_order);
  // A first-order model's ray weights are the étendue of a picture pixel's patch of scene; where its
  // distortion (Seidel's) packs more of the scene into an output pixel, that pixel gathers the light
  // of more of it (ImageAreaTable).
  render_detail::ImageAreaTable areas;
  if (first_order && !illumination.empty() && render_detail::ImageAreaTable::needed(model)) {
    areas = render_detail::ImageAreaTable(model, 0, w_min, w_max, threads);
  }
  const double w_light = std::clamp(std::isfinite(camera.focus_distance_mm()) ? 1.0 / camera.focus_distance_mm() : 0.0, w_min, w_max);
  const auto w_light_f = static_cast<float>(w_light);

  // Wavelengths: the scatter path's spectral groups (spectral_groups.h), split into at most
  // kMaxBands bands of neighbouring quadrature nodes, each traced at its middle node and carrying
  // the colour of all of its nodes; without spectral colour, the reference wavelength alone.
  const render_detail::SpectralGroups groups(camera, options.spectral, options.spectral_samples);
  const std::vector<render_detail::SpectralGroup>& split =
      groups.split(std::min(groups.max_count(), static_cast<int>(kMaxBands)));
  std::vector<double> wavelengths;
  std::vector<Eigen::Matrix3f> to_rgb;  // per band: bands x its group's matrix, so that they average to the identity
  for (const render_detail::SpectralGroup& g : split) {
    wavelengths.push_back(g.wavelength_nm);
    Eigen::Matrix3f m;
    for (int out = 0; out < 3; ++out) {
      for (int in = 0; in < 3; ++in) m(out, in) = static_cast<float>(split.size()) * g.m[static_cast<std::size_t>(out)][static_cast<std::size_t>(in)];
    }
    to_rgb.push_back(m);
  }
  const std::size_t bands = wavelengths.size(), middle_band = bands / 2;

  // The pupil points (Lee et al. sec. 4.5 use 2N Halton points and an offset per pixel): 2N points
  // in groups of four, a Halton point (bases 2 and 3: radius^2, angle) and its rotations by 180, 90
  // and 270 degrees, so that every pixel's set is balanced about the pupil's centre; a pixel takes
  // N consecutive ones from an offset of its own. Every band traces the same pupil points: where
  // the bands' rays of a point land within kChromaticTolerancePx of each other over the scene's
  // depths (most points, most pixels), the middle band's ray alone is followed and its colour
  // stands for all bands, so a pixel's colour is not the noise of different pupil points per
  // wavelength (one wavelength per ray put colour noise of 5 dB PSNR on a grey occluder); where the
  // lens separates the colours, each band's ray is followed.
  const std::size_t n_samples = static_cast<std::size_t>(options.samples);
  const std::size_t bases_per_pixel = (n_samples + 3) / 4, base_count = 2 * bases_per_pixel, points = 4 * base_count;
  std::vector<LensSample> lens_samples(bands * points);
  for (std::size_t b = 0; b < bands; ++b) {
    for (std::size_t q = 0; q < points; ++q) {
      static constexpr std::array<double, 4> kTurn{0.0, 0.5, 0.25, 0.75};
      LensSample& sample = lens_samples[b * points + q];
      sample.u = radical_inverse(q / 4 + 1, 2);
      sample.v = std::fmod(radical_inverse(q / 4 + 1, 3) + kTurn[q % 4], 1.0);
      sample.node = static_cast<int>(b);
    }
  }
  LensRayTableOptions table_options;
  table_options.grid_px = options.ray_grid_px;
  table_options.vignetting = options.vignetting;
  table_options.threads = options.threads;
  if (first_order && !illumination.empty()) table_options.illumination = &illumination;
  const LensRayTable rays(model, aperture, wavelengths, lens_samples, table_options);

  // The light of each pixel's beam (vignetting on): the mean ray weight over LightGrid's dense pupil
  // set (Halton, the middle band) at its nodes. A pixel's own 32 samples, out of 64 pupil points
  // shared by the whole frame, measured a cat's eye's share with a bias of up to 20 % (lentil 0005's
  // frame edge through the exact model: 0.370 of the centre against the ground truth's 0.308; 256
  // samples a pixel gave 0.325, the grid 0.328).
  render_detail::LightGrid light;
  if (options.vignetting) {
    using render_detail::kLightSamples;
    std::vector<LensSample> dense(kLightSamples);
    for (std::size_t i = 0; i < kLightSamples; ++i) {
      dense[i].u = radical_inverse(i + 1, 2);
      dense[i].v = radical_inverse(i + 1, 3);
      dense[i].node = static_cast<int>(middle_band);
    }
    light = render_detail::LightGrid(width, height, 0.0f);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int j = 0; j < light.nodes_y(); ++j) {
      for (int i = 0; i < light.nodes_x(); ++i) {
        light.at(i, j) = static_cast<float>(rays.mean_weight(light.node_x_px(i) + 0.5, light.node_y_px(j) + 0.5, dense));
      }
    }
  }

  // Per grid cell and pupil point: do the bands' rays agree at every corner (or all stop there)?
  const int cells_x = rays.nodes_x(), cells_y = rays.nodes_y();
  std::vector<std::uint8_t> achromatic(static_cast<std::size_t>(cells_x) * static_cast<std::size_t>(cells_y) * points, 1);
  if (bands > 1) {
    const auto w_near = static_cast<float>(w_max), w_far = static_cast<float>(w_min);
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
    for (int cy = 0; cy < cells_y; ++cy) {
      for (int cx = 0; cx < cells_x; ++cx) {
        for (std::size_t q = 0; q < points; ++q) {
          bool agree = true;
          for (int corner = 0; corner < 4 && agree; ++corner) {
            const int nx = std::min(cx + (corner & 1), cells_x - 1), ny = std::min(cy + (corner >> 1), cells_y - 1);
            const PixelRay& ref = rays.node_ray(nx, ny, middle_band * points + q);
            for (std::size_t b = 0; b < bands && agree; ++b) {
              const PixelRay& r = rays.node_ray(nx, ny, b * points + q);
              if ((r.weight > 0.0f) != (ref.weight > 0.0f)) agree = false;
              if (!(r.weight > 0.0f)) continue;
              for (const float w : {w_near, w_far}) {
                const float dx = (r.inf_x - ref.inf_x) + w * (r.k_x - ref.k_x), dy = (r.inf_y - ref.inf_y) + w * (r.k_y - ref.k_y);
                if (dx * dx + dy * dy > kChromaticTolerancePx * kChromaticTolerancePx) agree = false;
              }
            }
          }
          achromatic[(static_cast<std::size_t>(cy) * static_cast<std::size_t>(cells_x) + static_cast<std::size_t>(cx)) * points + q] = agree;
        }
      }
    }
  }

  Cones cones;
  std::vector<MipPyramid> pyramids;
  if (options.cone_tracing) {
    pyramids = make_pyramids(layers, threads);
    cones.pyramids = &pyramids;
    cones.lambda = static_cast<float>(std::sqrt(kPi / (4.0 * static_cast<double>(n_samples))));
    cones.coc_at_infinity = static_cast<float>(camera.signed_coc_px(0.0));
    cones.coc_per_w = static_cast<float>((camera.signed_coc_px(1e-3) - camera.signed_coc_px(0.0)) / 1e-3);
  }

  Image out(width, height, 4, 0.0f);
  std::size_t total_rays = 0, stopped = 0, lost = 0, cells = 0, outside = 0, chromatic = 0;
  int rows_done = 0;
#pragma omp parallel for schedule(dynamic, 2) num_threads(threads) reduction(+ : total_rays, stopped, lost, cells, outside, chromatic)
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      // The pixel's offset into the pupil points: fixed per pixel, decorrelated from its neighbours.
      std::uint64_t state = (static_cast<std::uint64_t>(y) << 32) ^ static_cast<std::uint64_t>(x);
      const std::size_t offset = static_cast<std::size_t>(splitmix64(state) % base_count);
      const std::uint8_t* cell_agrees =
          achromatic.data() + (static_cast<std::size_t>(std::min(y / rays.grid_px(), cells_y - 1)) * static_cast<std::size_t>(cells_x) +
                               static_cast<std::size_t>(std::min(x / rays.grid_px(), cells_x - 1))) * points;
      // Colour: per band b, the weighted mean of what its rays met (premultiplied; the share of a
      // ray lost where an opaque input knows nothing left out), through the band's RGB matrix M_b
      // (bands x its nodes' quadrature weights times the spectral basis), averaged over the bands:
      // Sum_b M_b = bands I (the quadrature's round trip), so grey stays grey. Rays followed once
      // for all bands count in every band's mean; a band whose rays the lens stopped takes the
      // pixel's mean colour, so a missing wavelength does not tint it.
      std::array<Eigen::Vector3f, kMaxBands> band_sum;
      std::array<float, kMaxBands> band_seen{};
      for (std::size_t b = 0; b < bands; ++b) band_sum[b].setZero();
      Eigen::Vector3f common_sum = Eigen::Vector3f::Zero();
      float common_seen = 0.0f;
      double weight_seen = 0.0, coverage = 0.0;  // bands' rays at 1 / bands each
      double source_x = 0.0, source_y = 0.0, source_rays = 0.0;
      for (std::size_t i = 0; i < n_samples; ++i) {
        const std::size_t q = 4 * ((offset + i / 4) % base_count) + i % 4;
        const bool all_bands = cell_agrees[q] != 0;
        const std::size_t first = all_bands ? middle_band : 0, last = all_bands ? middle_band + 1 : bands;
        const float share = all_bands ? 1.0f : 1.0f / static_cast<float>(bands);
        chromatic += all_bands ? 0 : 1;
        for (std::size_t b = first; b < last; ++b) {
          const PixelRay ray = rays.ray(x, y, b * points + q);
          ++total_rays;
          if (!(ray.weight > 0.0f)) {
            ++stopped;
            continue;
          }
          const RayResult r = follow(layers, ray, cones);
          cells += r.cells;
          outside += r.left_frame ? 1 : 0;
          float seen_share = 1.0f;
          if (opaque && r.transmittance > kOpaque) {
            seen_share = 1.0f - r.transmittance;
            ++lost;
          }
          // Where the passing rays meet the focus plane: the scene point the model images here.
          source_x += share * (ray.inf_x + w_light_f * ray.k_x);
          source_y += share * (ray.inf_y + w_light_f * ray.k_y);
          source_rays += share;
          weight_seen += share * ray.weight * seen_share;
          coverage += share * ray.weight * (1.0f - r.transmittance);
          const Eigen::Vector3f met = ray.weight * Eigen::Vector3f(r.colour[0], r.colour[1], r.colour[2]);
          if (all_bands) {
            common_sum += met;
            common_seen += ray.weight * seen_share;
          } else {
            band_sum[b] += met;
            band_seen[b] += ray.weight * seen_share;
          }
        }
      }
      float* px = &out.data[(static_cast<std::size_t>(y) * width + static_cast<std::size_t>(x)) * 4];
      if (!(weight_seen > 1e-9)) continue;
      Eigen::Vector3f all_sum = common_sum * static_cast<float>(bands);
      float all_seen = common_seen * static_cast<float>(bands);
      for (std::size_t b = 0; b < bands; ++b) {
        all_sum += band_sum[b];
        all_seen += band_seen[b];
      }
      const Eigen::Vector3f mean = all_sum / all_seen;
      Eigen::Vector3f rgb = Eigen::Vector3f::Zero();
      for (std::size_t b = 0; b < bands; ++b) {
        const float seen = common_seen + band_seen[b];
        rgb += to_rgb[b] * (seen > 1e-6f ? Eigen::Vector3f((common_sum + band_sum[b]) / seen) : mean);
      }
      // Vignetting on: the pixel's light is the mean weight over the dense pupil set (stopped rays
      // bring none); off: every passing ray counts alike.
      float brightness = options.vignetting ? light.sample(x, y) : 1.0f;
      if (!illumination.empty()) {
        // At the scene point the pixel images (where its passing rays meet the focus plane; a
        // barrel moves it outwards from the pixel's own field point), else at the pixel's.
        const PixelPoint at = source_rays > 0.0 ? PixelPoint{source_x / source_rays, source_y / source_rays} : PixelPoint{x + 0.5, y + 0.5};
        const Tangents t = camera.frame().tangents_at(at);
        brightness *= illumination.factor(ScenePoint{t.x, t.y, w_light});
        if (!areas.empty()) brightness /= std::max(areas.at(at.x, at.y, w_light), 1e-3f);
      }
      rgb *= brightness / static_cast<float>(bands);
      for (int c = 0; c < 3; ++c) px[c] = std::max(0.0f, rgb[c]);
      px[3] = static_cast<float>(std::clamp(coverage / weight_seen, 0.0, 1.0));
    }
    if (options.progress) {
#pragma omp critical(multiview_progress)
      {
        ++rows_done;
        if (rows_done % 16 == 0 || rows_done == height) options.progress(static_cast<double>(rows_done) / height);
      }
    }
  }
  if (statistics) {
    int used = 0;
    for (std::uint8_t u : layers.layer_used) used += u;
    statistics->layers = used;
    const double coc_near = camera.signed_coc_px(w_max), coc_far = camera.signed_coc_px(w_min);
    statistics->layer_spacing_px = std::abs(coc_near - coc_far) / layers.count;
    statistics->max_abs_coc_px = std::max(std::abs(coc_near), std::abs(coc_far));
    statistics->rays = total_rays;
    statistics->stopped_rays = stopped;
    statistics->lost_rays = lost;
    statistics->cells_visited = cells;
    statistics->outside_rays = outside;
    statistics->direct_rays = rays.direct_rays();
    statistics->chromatic_samples = chromatic;
  }
  return out;
}

}  // namespace lensmith

#include "scatter_source.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>

#include "first_touch.h"
#include "lensmith/core/units.h"

namespace lensmith::render_detail {

namespace {
// Nearest object the renderer places: this far in front of the lens's first surface (mm).
constexpr double kNearestObjectMm = 1.0;
// Bisection steps for the depth whose blur is the limit: 2^-60 of the inverse-depth interval.
constexpr int kClampBisections = 60;
}  // namespace

namespace {

// For the frame's edge midpoints and corners (output px) and where their chief rays land (output px;
// NaN where the ray fails): reference wavelength, focus distance.
template <class Visit>
void map_frame_edges(const RayModel& model, Visit visit) {
  const Camera& camera = model.camera();
  const double w = camera.frame().width_px(), h = camera.frame().height_px();
  const double inverse = inverse_per_mm(camera.focus_distance_mm());
  static constexpr std::array<PupilPoint, 1> kCentre{{{0.0, 0.0}}};
  std::array<SensorHit, 1> hit;
  for (const PixelPoint at : {PixelPoint{0.0, 0.5 * h}, PixelPoint{w, 0.5 * h}, PixelPoint{0.5 * w, 0.0}, PixelPoint{0.5 * w, h},
                              PixelPoint{0.0, 0.0}, PixelPoint{w, 0.0}, PixelPoint{0.0, h}, PixelPoint{w, h}}) {
    const Tangents t = camera.frame().tangents_at(at);
    model.map({t.x, t.y, inverse}, camera.reference_wavelength_nm(), kCentre, hit);
    if (!(hit[0].ok || hit[0].unclipped)) continue;
    const PixelPoint q = camera.output_pixel(hit[0].x_mm, hit[0].y_mm);
    if (std::isfinite(q.x) && std::isfinite(q.y)) visit(at, q);
  }
}

}  // namespace

int frame_margin_px(const RayModel& model, double reach_px) {
  constexpr double kMaxFrameMarginPx = 256.0, kTentPx = 2.0;
  double shift = 0.0;
  map_frame_edges(model, [&](const PixelPoint& at, const PixelPoint& q) { shift = std::max(shift, std::hypot(q.x - at.x, q.y - at.y)); });
  // (A shift of rounding size, a thin lens's, is none.)
  return static_cast<int>(std::min(std::ceil(std::max(0.0, reach_px + shift - 1e-6)) + kTentPx, kMaxFrameMarginPx));
}

double frame_edge_gap_px(const RayModel& model) {
  const double w = model.camera().frame().width_px(), h = model.camera().frame().height_px();
  double gap = 0.0;
  map_frame_edges(model, [&](const PixelPoint& at, const PixelPoint& q) {
    // Inwards from the edges the point lies on (a corner lies on two).
    if (at.x == 0.0) gap = std::max(gap, q.x);
    if (at.x == w) gap = std::max(gap, w - q.x);
    if (at.y == 0.0) gap = std::max(gap, q.y);
    if (at.y == h) gap = std::max(gap, h - q.y);
  });
  return gap;
}

double clamp_inverse_depth(const Camera& camera, double w, double max_blur_px, std::size_t& clamped, double* coc_px) {
  const double nearest_mm = std::max(camera.z_perspective_mm(), 0.0) + kNearestObjectMm;
  if (w > 1.0 / nearest_mm) {
    w = 1.0 / nearest_mm;
    ++clamped;
  }
  const double coc = camera.signed_coc_px(w);
  if (std::abs(coc) <= max_blur_px) {
    if (coc_px) *coc_px = coc;
    return w;
  }
  // Bisect between the focus plane (no blur) and w for the depth whose blur is the limit.
  double in = inverse_per_mm(camera.focus_distance_mm()), out = w;
  for (int k = 0; k < kClampBisections; ++k) {
    const double mid = 0.5 * (in + out);
    (std::abs(camera.signed_coc_px(mid)) <= max_blur_px ? in : out) = mid;
  }
  ++clamped;
  if (coc_px) *coc_px = camera.signed_coc_px(in);
  return in;
}

void check_flat_input(const Image& image, const DepthMap& depth, const Camera& camera, const Aperture& aperture,
                      const std::string& function, const std::string& method) {
  const int w = camera.frame().width_px(), h = camera.frame().height_px();
  if (image.width != w || image.height != h || image.channels != 3 || depth.width != w || depth.height != h) {
    throw OptionsError(function + ": the picture " + image.to_string() + " and its depth (" + std::to_string(depth.width) + " x " +
                       std::to_string(depth.height) + ") must both be the camera's " + std::to_string(w) + " x " + std::to_string(h) +
                       " px, the picture with 3 channels");
  }
  if (!aperture.is_uniform_convex()) {
    throw OptionsError("--method " + method + ": an aperture picture (mask) is not implemented; use a circular or bladed iris");
  }
}

ClampedDepths clamped_inverse_depths(const Camera& camera, const DepthMap& depth, double max_blur_px, int threads) {
  const int w = depth.width, h = depth.height;
  ClampedDepths out;
  out.inverse.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  std::size_t clamped = 0;
  double w_min = kInfinity, w_max = -kInfinity, max_blur = 0.0;
#pragma omp parallel for schedule(static) num_threads(threads) reduction(+ : clamped) reduction(min : w_min) reduction(max : w_max, max_blur)
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      double coc = 0.0;
      const double inverse = clamp_inverse_depth(camera, inverse_depth_per_mm(depth.at(x, y)), max_blur_px, clamped, &coc);
      out.inverse[p] = inverse;
      w_min = std::min(w_min, inverse);
      w_max = std::max(w_max, inverse);
      max_blur = std::max(max_blur, std::abs(coc));
    }
  }
  out.w_min = w_min;
  out.w_max = w_max;
  out.max_blur_px = max_blur;
  out.clamped = clamped;
  return out;
}

ScatterSources make_scatter_sources(const Image& image, const DepthMap& depth, const Camera& camera,
                                                const BokehOptions& options, int threads, BokehStatistics& stats) {
  const int w = image.width, h = image.height;
  // Room for the second parts of split edge pixels (mixed_pixels), so that they are appended
  // without a copy of the frame's sources: reserved address space costs nothing until touched, and
  // on a virtual machine touching fresh memory is what costs (docs/performance.md).
  const std::size_t pixels = static_cast<std::size_t>(w) * h;
  ScatterSources sources;
  sources.reserve(pixels + pixels / 4);
  fault_in(sources, pixels, threads);
  sources.resize(pixels);
  std::size_t clamped = 0;
  double coc_min = kInfinity, coc_max = -kInfinity;
#pragma omp parallel for num_threads(threads) schedule(static) reduction(+ : clamped) reduction(min : coc_min) reduction(max : coc_max)
  for (int y = 0; y < h; ++y) {
    // A depth equal to the previous pixel's (a wall facing the camera, the sky) takes its inverse
    // depth, blur and clamp count over: the camera's blur is the dearest part of a source.
    float last_z = std::numeric_limits<float>::quiet_NaN();
    double last_w = 0.0, last_coc = 0.0;
    std::size_t last_clamps = 0;
    for (int x = 0; x < w; ++x) {
      const float z = depth.at(x, y);
      if (!(z == last_z)) {
        std::size_t clamps = 0;
        last_w = clamp_inverse_depth(camera, inverse_depth_per_mm(z), options.max_blur_px, clamps, &last_coc);
        last_z = z;
        last_clamps = clamps;
      }
      // Written whole: the resize above constructed nothing (ScatterSources).
      sources[static_cast<std::size_t>(y) * w + x] = ScatterSource{.x = x,
                                                                   .y = y,
                                                                   .rgb = {image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2)},
                                                                   .inverse_depth_per_mm = last_w,
                                                                   .coc_px = last_coc};
      clamped += last_clamps;
      coc_min = std::min(coc_min, last_coc);
      coc_max = std::max(coc_max, last_coc);
    }
  }
  stats.source_pixels = sources.size();
  stats.clamped_depths = clamped;
  stats.max_abs_coc_px = std::max(std::abs(coc_min), std::abs(coc_max));
  return sources;
}

}  // namespace lensmith::render_detail

namespace lensmith::render_detail {

namespace {

// A surface or a volume's slab of one pixel before merging: premultiplied colour, alpha, inverse depth.
struct Piece {
  std::array<double, 3> rgb{};
  double alpha = 0.0;
  double inverse_depth_per_mm = 0.0;
  double coc_px = 0.0;
};

// The pieces of one pixel, front to back: surfaces as they are, volumes cut into slabs.
void pixel_pieces(std::span<const DeepSample> samples, const Camera& camera, double max_blur_px, std::size_t& clamped,
                  std::size_t& slabs, std::vector<Piece>& out) {
  out.clear();
  for (const DeepSample& s : samples) {
    const double w_front = clamp_inverse_depth(camera, inverse_depth_per_mm(s.z_m), max_blur_px, clamped);
    if (!s.is_volume()) {
      out.push_back({{s.rgb[0], s.rgb[1], s.rgb[2]}, s.alpha, w_front, camera.signed_coc_px(w_front)});
      continue;
    }
    std::size_t unused = 0;
    const double w_back = clamp_inverse_depth(camera, inverse_depth_per_mm(s.z_back_m), max_blur_px, unused);
    const double blur_span = std::abs(camera.signed_coc_px(w_front) - camera.signed_coc_px(w_back));
    const int n = std::clamp(static_cast<int>(std::ceil(blur_span / kVolumeSlabPx)), 1, kMaxVolumeSlabs);
    slabs += static_cast<std::size_t>(n);
    // Slab edges evenly in inverse depth (blur is linear in it); each slab's share of the volume by
    // its thickness in z, as OpenEXR's rule assumes a uniform volume (in inverse depth where the
    // back is infinitely far).
    const bool finite = std::isfinite(s.z_back_m);
    auto edge_z_mm = [&](int k) { return 1.0 / (w_front + (w_back - w_front) * k / n); };
    const double thickness = finite ? edge_z_mm(n) - edge_z_mm(0) : w_front - w_back;  // mm, or 1/mm
    const double transmit = 1.0 - static_cast<double>(s.alpha);
    for (int k = 0; k < n; ++k) {
      double f = 1.0 / n;
      if (finite && thickness > 0.0) f = (edge_z_mm(k + 1) - edge_z_mm(k)) / thickness;
      const double a = s.alpha >= 1.0f ? 1.0 : 1.0 - std::pow(transmit, f);
      // alpha' / alpha; for a volume that absorbs nothing (alpha 0) the colour goes by f.
      const double share = s.alpha > 0.0f ? a / s.alpha : f;
      const double w_mid = w_front + (w_back - w_front) * (k + 0.5) / n;
      out.push_back({{s.rgb[0] * share, s.rgb[1] * share, s.rgb[2] * share}, a, w_mid, camera.signed_coc_px(w_mid)});
    }
  }
}

}  // namespace

DeepSources make_deep_sources(const DeepImage& deep, const Camera& camera, const BokehOptions& options, BokehStatistics& stats) {
  DeepSources result;
  const int w = deep.width, h = deep.height;
  std::size_t clamped = 0, slabs = 0;
  std::vector<Piece> pieces;
  // Pass 1, over the samples themselves (a volume's slabs lie between its front and back, and
  // compose to its alpha): the range of blur, for the layers, and whether some pixel is left
  // uncovered (the remainder is infinitely far).
  double coc_min = kInfinity, coc_max = -kInfinity;
  bool backdrop = false;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      double transmitted = 1.0;
      for (const DeepSample& s : deep.pixel(x, y)) {
        std::size_t unused = 0;
        for (const float z : {s.z_m, s.z_back_m}) {
          const double coc = camera.signed_coc_px(clamp_inverse_depth(camera, inverse_depth_per_mm(z), options.max_blur_px, unused));
          coc_min = std::min(coc_min, coc);
          coc_max = std::max(coc_max, coc);
        }
        transmitted *= 1.0 - s.alpha;
      }
      backdrop = backdrop || transmitted > kOpaqueRemainder;
    }
  }
  const double backdrop_w = clamp_inverse_depth(camera, 0.0, options.max_blur_px, clamped);
  if (!(coc_min <= coc_max)) coc_min = coc_max = camera.signed_coc_px(backdrop_w);
  result.spacing = LayerSpacing::over(coc_min, coc_max, options.layer_spacing_px, options.max_layers);
  // The uncovered remainder is nothing: a layer of its own behind every sample, so that it never
  // shares a layer's coverage with a surface (within a layer coverage averages, and a black
  // backdrop of another blur would thin an element's rim).
  double backdrop_coc = 0.0;
  if (backdrop) {
    result.spacing.coc_min_px -= result.spacing.spacing_px;
    ++result.spacing.count;
    backdrop_coc = result.spacing.coc_min_px + 0.5 * result.spacing.spacing_px;
  }

  // Pass 2: per pixel, a source per piece. Within a layer footprints average (layer_compositing.h),
  // so the pieces of one pixel that share a layer are weighted by what the group's nearer pieces let
  // through (front over back, as the composite would), each keeping its own depth: a small bright
  // light in front of a wall a layer's width behind keeps its own blur.
  ScatterSources& sources = result.sources;
  sources.reserve(deep.sample_count() + static_cast<std::size_t>(w) * h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      pixel_pieces(deep.pixel(x, y), camera, options.max_blur_px, clamped, slabs, pieces);
      double transmitted = 1.0;  // through the layers of this pixel made so far
      std::size_t i = 0;
      while (i < pieces.size()) {
        const int layer = result.spacing.layer_at(pieces[i].coc_px);
        double alpha = 0.0;  // of the group so far
        for (; i < pieces.size() && result.spacing.layer_at(pieces[i].coc_px) == layer; ++i) {
          const Piece& p = pieces[i];
          const double through = 1.0 - alpha;  // what the group's nearer pieces let through
          const double coverage = through * p.alpha;
          alpha += coverage;
          // Light without coverage (an emissive sample of alpha 0: a glow) is kept.
          if (!(coverage > 0.0) && through * (p.rgb[0] + p.rgb[1] + p.rgb[2]) <= 0.0) continue;
          ScatterSource s;
          s.x = x;
          s.y = y;
          s.coverage = static_cast<float>(std::min(1.0, coverage));
          s.hidden = static_cast<float>(std::min(1.0, coverage) * (1.0 - transmitted));
          s.rgb = {static_cast<float>(through * p.rgb[0]), static_cast<float>(through * p.rgb[1]), static_cast<float>(through * p.rgb[2])};
          s.inverse_depth_per_mm = p.inverse_depth_per_mm;
          s.coc_px = p.coc_px;
          sources.push_back(s);
        }
        transmitted *= 1.0 - std::min(1.0, alpha);
      }
      if (transmitted > kOpaqueRemainder) {
        // The rest of the pixel: nothing, infinitely far (black, as a transparent pixel's
        // premultiplied colour is; the alpha channel says how much is there).
        ScatterSource s;
        s.x = x;
        s.y = y;
        s.coverage = 1.0f;
        s.hidden = static_cast<float>(1.0 - transmitted);
        s.inverse_depth_per_mm = backdrop_w;
        s.coc_px = backdrop_coc;  // its layer's; the footprint is mapped from its depth
        sources.push_back(s);
      }
    }
  }
  result.samples = deep.sample_count();
  result.volume_slabs = slabs;
  stats.source_pixels = static_cast<std::size_t>(w) * h;
  stats.clamped_depths = clamped;
  double most = 0.0;
  for (const ScatterSource& s : sources) most = std::max(most, std::abs(s.coc_px));
  stats.max_abs_coc_px = most;
  return result;
}

}  // namespace lensmith::render_detail

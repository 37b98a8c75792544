#include "lensmith/render/bokeh_renderer.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <sstream>
#include <vector>

#include "lensmith/color/spectral_quadrature.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/units.h"

namespace lensmith {

namespace {

// A pixel to scatter: where it is, what it sends, how far it is.
struct Source {
  int x = 0;
  int y = 0;
  std::array<float, 3> rgb{};
  double inverse_depth_per_mm = 0.0;
  double coc_px = 0.0;  // signed, reference wavelength
};

// What phase 1 decided for a source of the current layer.
struct Plan {
  float y_min = 0.0f;  // footprint rows it may touch (px, with margin)
  float y_max = 0.0f;
  int groups = 1;      // wavelength groups
  int mesh = -1;       // index into the mesh table, or -1 for the single-polygon path
  int outline = 0;     // index into the outline table (single-polygon path)
};

// Wavelength groups for each possible count G: the quadrature nodes split into G runs; each run
// carries its light at one wavelength with RGB out = M * RGB in, and the M of all runs sum to the
// identity (the quadrature's calibration), so grey stays grey.
struct SpectralGroup {
  double wavelength_nm = 0.0;
  std::array<std::array<float, 3>, 3> m{};
  float alpha = 1.0f;
};

// Polar pupil meshes and outlines are chosen from fixed size steps so they can be built once.
constexpr std::array<int, 9> kSectorSteps{8, 12, 16, 24, 32, 48, 64, 96, 128};
constexpr std::array<int, 8> kRingSteps{1, 2, 3, 4, 6, 8, 12, 16};
constexpr std::array<int, 5> kGridSteps{4, 8, 16, 32, 64};

template <std::size_t N>
int step_index(const std::array<int, N>& steps, double wanted) {
  for (std::size_t i = 0; i < N; ++i) {
    if (steps[i] >= wanted) return static_cast<int>(i);
  }
  return static_cast<int>(N) - 1;
}

// Footprint heights (px, with margins) from which half and a quarter of the sub-rows are used.
constexpr float kMediumFootprintPx = 20.0f;
// Footprints narrower than this (px) are deposited as points: the 2 px tent hides their shape.
constexpr double kPointFootprintPx = 0.2;
constexpr int kPointPath = -2;
// Pixels covered at least this much are known colour for filling the gaps of others (coverage of
// a tiling of distorted footprints wanders a few per cent around 1; a pixel whose own light spread
// away is far below).
constexpr double kKnownCoverage = 0.9;
constexpr float kTallFootprintPx = 68.0f;

// Sectors so a polygon inscribed in a circle of diameter d px departs from it by < 0.1 px.
double sectors_for(double diameter_px) { return kPi * std::sqrt(2.5 * std::max(diameter_px, 0.0)); }

// Push-pull interpolation (Gortler, Grzeszczuk, Szeliski & Cohen, "The Lumigraph", SIGGRAPH 1996):
// `cells` holds, per pixel, four weighted sums and their weight (0 = unknown). Pull sums 2 x 2
// blocks down to one cell; push gives every unknown cell its parent's normalised value. On return
// every cell holds normalised values and weight 1 (all zero if no cell was known).
void push_pull(int w, int h, std::vector<std::array<double, 5>>& cells) {
  std::vector<std::vector<std::array<double, 5>>> levels;
  std::vector<std::pair<int, int>> sizes{{w, h}};
  while (sizes.back().first > 1 || sizes.back().second > 1) {
    const auto [fw, fh] = sizes.back();
    const std::vector<std::array<double, 5>>& f = levels.empty() ? cells : levels.back();
    const int cw = (fw + 1) / 2, ch = (fh + 1) / 2;
    std::vector<std::array<double, 5>> c(static_cast<std::size_t>(cw) * ch, std::array<double, 5>{});
    for (int y = 0; y < fh; ++y) {
      for (int x = 0; x < fw; ++x) {
        auto& dst = c[static_cast<std::size_t>(y / 2) * cw + x / 2];
        const auto& src = f[static_cast<std::size_t>(y) * fw + x];
        for (int k = 0; k < 5; ++k) dst[k] += src[k];
      }
    }
    levels.push_back(std::move(c));
    sizes.push_back({cw, ch});
  }
  auto normalise = [](std::array<double, 5>& v) {
    if (v[4] > 0.0) {
      for (int k = 0; k < 4; ++k) v[k] /= v[4];
      v[4] = 1.0;
    }
  };
  if (!levels.empty()) normalise(levels.back()[0]);
  // Push from the coarsest level to the finest (level index l - 1; cells themselves at the end).
  for (std::size_t l = levels.size(); l-- > 0;) {
    std::vector<std::array<double, 5>>& f = l == 0 ? cells : levels[l - 1];
    const std::vector<std::array<double, 5>>& c = levels[l];
    const auto [fw, fh] = sizes[l];
    const int cw = sizes[l + 1].first;
    for (int y = 0; y < fh; ++y) {
      for (int x = 0; x < fw; ++x) {
        auto& v = f[static_cast<std::size_t>(y) * fw + x];
        if (v[4] > 0.0) {
          normalise(v);
        } else {
          v = c[static_cast<std::size_t>(y / 2) * cw + x / 2];
        }
      }
    }
  }
}

// A polar mesh mapped without folds deposits as nested rings: annulus k (between mapped rings k-1
// and k) carries its share of the pupil, (2k - 1) / R^2, spread evenly over its mapped area. As the
// scatter is linear, annulus k is ring polygon k at density d_k minus ring polygon k-1 at d_k, so
// ring polygon k is deposited once with area * (d_k - d_(k+1)): R polygons at O(height) each
// instead of 2 R S small triangles. The radial light distribution (spherical aberration's bright
// or dark rims) is kept; light varying around a ring (coma's flare) is averaged over each annulus.
// Returns false, depositing nothing, when a ray is lost or the rings are not nested (a fold or
// caustic): the caller then uses the triangles.
bool deposit_ring_polygons(const PupilMesh& mesh, const std::vector<SensorHit>& hits, const std::vector<Point2f>& points,
                           const std::array<float, 4>& value, SplatBuffer& buffer, std::vector<double>& areas) {
  for (const SensorHit& h : hits) {
    if (!h.ok) return false;
  }
  const int rings = mesh.rings, sectors = mesh.sectors;
  areas.assign(static_cast<std::size_t>(rings) + 1, 0.0);
  double orientation = 0.0;
  for (int k = 1; k <= rings; ++k) {
    const std::span<const Point2f> ring(points.data() + 1 + static_cast<std::size_t>(k - 1) * sectors, static_cast<std::size_t>(sectors));
    double twice = 0.0;
    for (int j = 0; j < sectors; ++j) {
      const Point2f& a = ring[static_cast<std::size_t>(j)];
      const Point2f& b = ring[static_cast<std::size_t>((j + 1) % sectors)];
      twice += static_cast<double>(a.x) * b.y - static_cast<double>(b.x) * a.y;
    }
    if (k == 1) orientation = twice < 0.0 ? -1.0 : 1.0;
    const double area = 0.5 * twice * orientation;
    // Nested: each ring encloses clearly more than the one inside it.
    if (!(area > areas[static_cast<std::size_t>(k) - 1] + 1e-3 * std::max(area, 1e-9))) return false;
    areas[static_cast<std::size_t>(k)] = area;
  }
  // Densities d_k per unit of value, then one deposit per ring polygon.
  auto density = [&](int k) {
    if (k > rings) return 0.0;
    const double share = static_cast<double>(2 * k - 1) / (static_cast<double>(rings) * rings);
    return share / (areas[static_cast<std::size_t>(k)] - areas[static_cast<std::size_t>(k) - 1]);
  };
  for (int k = 1; k <= rings; ++k) {
    const double factor = areas[static_cast<std::size_t>(k)] * (density(k) - density(k + 1));
    const std::span<const Point2f> ring(points.data() + 1 + static_cast<std::size_t>(k - 1) * sectors, static_cast<std::size_t>(sectors));
    const auto f = static_cast<float>(factor);
    buffer.add_polygon(ring, {value[0] * f, value[1] * f, value[2] * f, value[3] * f});
  }
  return true;
}

class Renderer {
 public:
  Renderer(const Image& image, const DepthMap& depth, const RayModel& model, const Aperture& aperture,
           const BokehOptions& options)
      : image_(image), depth_(depth), model_(model), camera_(model.camera()), aperture_(aperture), options_(options) {
    threads_ = options.threads > 0 ? options.threads : omp_get_max_threads();
    build_spectral_groups();
    build_meshes();
    // The probe: the pupil centre and 8 points on the aperture's edge, from the top anticlockwise.
    probe_[0] = {0.0, 0.0};
    for (int k = 0; k < 8; ++k) {
      const double a = kPi / 2.0 + 2.0 * kPi * k / 8.0;
      const double r = aperture_.kind() == Aperture::Kind::Mask ? 1.0 : aperture_.edge_radius(a);
      probe_[static_cast<std::size_t>(k) + 1] = {r * std::cos(a), r * std::sin(a)};
    }
  }

  Image run(BokehStatistics& stats);

 private:
  void build_spectral_groups();
  void build_meshes();
  Source make_source(int x, int y, double inverse_depth_per_mm, const std::array<float, 3>& rgb, BokehStatistics& stats) const;
  double clamp_inverse_depth(double w, std::size_t& clamped) const;
  Plan plan(const Source& s, std::vector<PupilPoint>& pupil, std::vector<SensorHit>& hits) const;
  // `buffer` takes footprint-sized polygons, `fine` the small triangles of a mesh (all sub-rows).
  void scatter(const Source& s, const Plan& p, SplatBuffer& buffer, SplatBuffer& fine, std::vector<SensorHit>& hits,
               std::vector<Point2f>& points, std::size_t& triangles) const;
  std::vector<Source> extend_layer(const std::vector<int>& layer_of, int layer, double reach_px) const;
  bool deposit_rings(const PupilMesh& mesh, const std::vector<SensorHit>& hits, const std::vector<Point2f>& points,
                     const std::array<float, 4>& value, SplatBuffer& buffer) const {
    thread_local std::vector<double> areas;
    return deposit_ring_polygons(mesh, hits, points, value, buffer, areas);
  }
  // The splat options with the sub-row count divided by `divisor` (at least 1).
  SplatOptions subrow_options(int divisor) const {
    SplatOptions o = options_.splat;
    o.subrows = std::max(1, o.subrows / divisor);
    return o;
  }

  const Image& image_;
  const DepthMap& depth_;
  const RayModel& model_;
  const Camera& camera_;
  const Aperture& aperture_;
  const BokehOptions& options_;
  int threads_ = 1;
  std::vector<std::vector<SpectralGroup>> groups_;  // groups_[G - 1]
  double lambda_lo_ = 0.0, lambda_hi_ = 0.0;         // extreme nodes, for the chromatic probe
  std::vector<PupilMesh> meshes_;                    // polar: ring step * sectors + sector step; masks: grid steps
  std::vector<std::vector<PupilPoint>> outlines_;    // per sector step (blades: corners only)
  std::array<PupilPoint, 9> probe_{};
};

void Renderer::build_spectral_groups() {
  const double reference = camera_.reference_wavelength_nm();
  SpectralGroup white;
  white.wavelength_nm = reference;
  for (int c = 0; c < 3; ++c) white.m[c][c] = 1.0f;
  if (!options_.spectral) {
    groups_ = {{white}};
    lambda_lo_ = lambda_hi_ = reference;
    return;
  }
  SpectralQuadratureOptions q;
  q.sample_count = options_.spectral_samples;
  q.min_wavelength_nm = 380.0;
  q.max_wavelength_nm = 780.0;
  const SpectralQuadrature quadrature(q);
  const std::size_t n = quadrature.size();
  lambda_lo_ = quadrature.wavelengths_nm().front();
  lambda_hi_ = quadrature.wavelengths_nm().back();
  groups_.assign(n, {});
  groups_[0] = {white};
  for (std::size_t count = 2; count <= n; ++count) {
    for (std::size_t g = 0; g < count; ++g) {
      const std::size_t begin = g * n / count, end = (g + 1) * n / count;
      SpectralGroup group;
      group.wavelength_nm = quadrature.wavelengths_nm()[(begin + end - 1) / 2];
      group.alpha = static_cast<float>(static_cast<double>(end - begin) / static_cast<double>(n));
      std::array<std::array<double, 3>, 3> m{};
      for (std::size_t i = begin; i < end; ++i) {
        const Rgb weight = quadrature.rgb_weights(i);
        const Rgb basis = quadrature.basis().basis_values(quadrature.wavelengths_nm()[i]);
        for (int out = 0; out < 3; ++out) {
          for (int in = 0; in < 3; ++in) m[out][in] += weight[out] * basis[in];
        }
      }
      for (int out = 0; out < 3; ++out) {
        for (int in = 0; in < 3; ++in) group.m[out][in] = static_cast<float>(m[out][in]);
      }
      groups_[count - 1].push_back(group);
    }
  }
}

void Renderer::build_meshes() {
  if (aperture_.kind() == Aperture::Kind::Mask) {
    for (int cells : kGridSteps) meshes_.push_back(aperture_.mesh(cells, 4));
    return;
  }
  for (int rings : kRingSteps) {
    for (int sectors : kSectorSteps) meshes_.push_back(aperture_.mesh(rings, sectors));
  }
  for (int sectors : kSectorSteps) {
    outlines_.push_back(aperture_.outline(aperture_.kind() == Aperture::Kind::Blades ? aperture_.blade_count() : sectors));
  }
}

double Renderer::clamp_inverse_depth(double w, std::size_t& clamped) const {
  // In front of the lens: the object must lie at least 1 mm before surface 1.
  const double nearest_mm = std::max(camera_.z_perspective_mm(), 0.0) + 1.0;
  if (w > 1.0 / nearest_mm) {
    w = 1.0 / nearest_mm;
    ++clamped;
  }
  const double limit = options_.max_blur_px;
  if (std::abs(camera_.signed_coc_px(w)) <= limit) return w;
  // Bisect between the focus plane (no blur) and w for the depth whose blur is the limit.
  const double focus_w = std::isinf(camera_.focus_distance_mm()) ? 0.0 : 1.0 / camera_.focus_distance_mm();
  double in = focus_w, out = w;
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (in + out);
    (std::abs(camera_.signed_coc_px(mid)) <= limit ? in : out) = mid;
  }
  ++clamped;
  return in;
}

Plan Renderer::plan(const Source& s, std::vector<PupilPoint>& pupil, std::vector<SensorHit>& hits) const {
  const PixelPoint centre{s.x + 0.5, s.y + 0.5};
  const Tangents t = camera_.frame().tangents_at(centre);
  const ScenePoint point{t.x, t.y, s.inverse_depth_per_mm};
  Plan p;
  const bool affine = model_.affine_in_pupil() && aperture_.is_uniform_convex();
  // Probe: the pupil centre and its edge (8 points) at the extreme wavelengths and the reference.
  pupil.assign(probe_.begin(), probe_.end());
  hits.resize(pupil.size());
  const std::array<double, 3> lambdas{camera_.reference_wavelength_nm(), lambda_lo_, lambda_hi_};
  std::array<std::array<PixelPoint, 9>, 3> px{};
  std::array<std::array<bool, 9>, 3> ok{};
  double x_min = kInfinity, x_max = -kInfinity, y_min = kInfinity, y_max = -kInfinity;
  // Without dispersion (a thin lens, or colour off) one wavelength tells all.
  const std::size_t wavelengths = camera_.is_thin_lens() || !options_.spectral ? 1 : 3;
  for (std::size_t l = 0; l < wavelengths; ++l) {
    model_.map(point, lambdas[l], pupil, hits);
    for (std::size_t i = 0; i < 9; ++i) {
      ok[l][i] = hits[i].ok;
      if (!hits[i].ok) continue;
      px[l][i] = camera_.output_pixel(hits[i].x_mm, hits[i].y_mm);
      x_min = std::min(x_min, px[l][i].x);
      x_max = std::max(x_max, px[l][i].x);
      y_min = std::min(y_min, px[l][i].y);
      y_max = std::max(y_max, px[l][i].y);
    }
  }
  if (!(y_min <= y_max)) {
    // No probe ray got through (the exact model, fully vignetted): plan a small mesh around the
    // pixel so the rays that do pass are still found.
    x_min = x_max = centre.x;
    y_min = y_max = centre.y;
  }
  // Nearly affine? Fit the reference-wavelength probe by the affine map through its centre and
  // two edge points; if no probe point departs from it by more than a quarter pixel, the
  // aberrations are invisible in this footprint and the single polygon is exact enough.
  bool near_affine = affine;
  if (!affine && aperture_.is_uniform_convex() && std::all_of(ok[0].begin(), ok[0].end(), [](bool b) { return b; })) {
    // Pupil points 1 and 3 are (r1, 90 deg) and (r3, 180 deg): solve for the map's columns.
    const double r1 = pupil[1].y, r3 = -pupil[3].x;
    const double ax = (px[0][3].x - px[0][0].x) / -r3, ay = (px[0][3].y - px[0][0].y) / -r3;
    const double bx = (px[0][1].x - px[0][0].x) / r1, by = (px[0][1].y - px[0][0].y) / r1;
    double worst = 0.0;
    for (std::size_t i = 0; i < 9; ++i) {
      const double fx = px[0][0].x + ax * pupil[i].x + bx * pupil[i].y;
      const double fy = px[0][0].y + ay * pupil[i].x + by * pupil[i].y;
      worst = std::max(worst, std::hypot(px[0][i].x - fx, px[0][i].y - fy));
    }
    near_affine = worst < 0.25;
  }
  double spread = 0.0;
  for (std::size_t i = 0; i < 9; ++i) {
    if (ok[1][i] && ok[2][i]) spread = std::max(spread, std::hypot(px[1][i].x - px[2][i].x, px[1][i].y - px[2][i].y));
  }
  const double size = std::max(x_max - x_min, y_max - y_min);
  const int max_groups = static_cast<int>(groups_.size());
  p.groups = std::clamp(static_cast<int>(std::ceil(spread / options_.chromatic_tolerance_px)), 1, max_groups);
  const double margin = near_affine ? 2.0 : 2.0 + 0.25 * size;
  p.y_min = static_cast<float>(y_min - margin);
  p.y_max = static_cast<float>(y_max + margin);
  const int sector_step = step_index(kSectorSteps, sectors_for(size));
  const bool all_pass = std::all_of(ok[0].begin(), ok[0].end(), [](bool b) { return b; });
  if (size < kPointFootprintPx && all_pass) {
    p.outline = kPointPath;
  } else if (near_affine) {
    p.outline = sector_step;
  } else if (aperture_.kind() == Aperture::Kind::Mask) {
    p.mesh = step_index(kGridSteps, size / 1.5);
  } else {
    // Models that clip at the real clear apertures (exact, poly) need rings fine enough for the edges
    // of a vignetted beam.
    const bool clips = model_.kind() == RayModelKind::Exact || model_.kind() == RayModelKind::Poly;
    const double rings = clips ? std::max(4.0, size / 6.0) : size / 16.0;
    p.mesh = step_index(kRingSteps, rings) * static_cast<int>(kSectorSteps.size()) + sector_step;
  }
  return p;
}

void Renderer::scatter(const Source& s, const Plan& p, SplatBuffer& buffer, SplatBuffer& fine, std::vector<SensorHit>& hits,
                       std::vector<Point2f>& points, std::size_t& triangles) const {
  const Tangents t = camera_.frame().tangents_at({s.x + 0.5, s.y + 0.5});
  const ScenePoint point{t.x, t.y, s.inverse_depth_per_mm};
  for (const SpectralGroup& g : groups_[static_cast<std::size_t>(p.groups - 1)]) {
    std::array<float, 4> value{};
    for (int c = 0; c < 3; ++c) value[c] = g.m[c][0] * s.rgb[0] + g.m[c][1] * s.rgb[1] + g.m[c][2] * s.rgb[2];
    value[3] = g.alpha;
    if (p.outline == kPointPath) {
      static constexpr std::array<PupilPoint, 1> kCentre{{{0.0, 0.0}}};
      hits.resize(1);
      model_.map(point, g.wavelength_nm, kCentre, std::span<SensorHit>(hits.data(), 1));
      if (!hits[0].ok) continue;
      const PixelPoint c = camera_.output_pixel(hits[0].x_mm, hits[0].y_mm);
      buffer.add_point({static_cast<float>(c.x), static_cast<float>(c.y)}, value);
      continue;
    }
    if (p.mesh < 0) {
      // Affine model, uniform convex aperture: the outline mapped by the affine map of three rays.
      static constexpr std::array<PupilPoint, 3> kBasis{{{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}}};
      hits.resize(3);
      model_.map(point, g.wavelength_nm, kBasis, std::span<SensorHit>(hits.data(), 3));
      const PixelPoint o = camera_.output_pixel(hits[0].x_mm, hits[0].y_mm);
      const PixelPoint ex = camera_.output_pixel(hits[1].x_mm, hits[1].y_mm);
      const PixelPoint ey = camera_.output_pixel(hits[2].x_mm, hits[2].y_mm);
      const std::vector<PupilPoint>& outline = outlines_[static_cast<std::size_t>(p.outline)];
      points.resize(outline.size());
      for (std::size_t i = 0; i < outline.size(); ++i) {
        points[i] = {static_cast<float>(o.x + (ex.x - o.x) * outline[i].x + (ey.x - o.x) * outline[i].y),
                     static_cast<float>(o.y + (ex.y - o.y) * outline[i].x + (ey.y - o.y) * outline[i].y)};
      }
      buffer.add_polygon(points, value);
      continue;
    }
    const PupilMesh& mesh = meshes_[static_cast<std::size_t>(p.mesh)];
    hits.resize(mesh.points.size());
    model_.map(point, g.wavelength_nm, mesh.points, hits);
    points.resize(mesh.points.size());
    for (std::size_t i = 0; i < mesh.points.size(); ++i) {
      if (!hits[i].unclipped && !hits[i].ok) continue;
      const PixelPoint q = camera_.output_pixel(hits[i].x_mm, hits[i].y_mm);
      points[i] = {static_cast<float>(q.x), static_cast<float>(q.y)};
    }
    if (mesh.sectors > 0 && deposit_rings(mesh, hits, points, value, buffer)) continue;
    // A triangle whose corners a clear aperture partly stops (the exact model) passes the fraction
    // of its corners that get through, in place: the beam's edge falls inside it, to first order.
    auto passing = [&hits](const PupilTriangle& tri) {
      if (!(hits[tri.a].ok || hits[tri.a].unclipped) || !(hits[tri.b].ok || hits[tri.b].unclipped) ||
          !(hits[tri.c].ok || hits[tri.c].unclipped)) {
        return 0.0;
      }
      return ((hits[tri.a].ok ? 1.0 : 0.0) + (hits[tri.b].ok ? 1.0 : 0.0) + (hits[tri.c].ok ? 1.0 : 0.0)) / 3.0;
    };
    // Colour carries the transmitted fraction (vignetting darkens); coverage is normalised over the
    // light that passes, so a vignetted point is still an opaque surface.
    double passed = 0.0;
    for (const PupilTriangle& tri : mesh.triangles) passed += tri.weight * passing(tri);
    if (!(passed > 0.0)) continue;
    for (const PupilTriangle& tri : mesh.triangles) {
      const double fraction = passing(tri);
      if (fraction == 0.0) continue;
      const auto w = static_cast<float>(tri.weight * fraction);
      fine.add_triangle(points[tri.a], points[tri.b], points[tri.c],
                          {value[0] * w, value[1] * w, value[2] * w, static_cast<float>(value[3] * tri.weight * fraction / passed)});
      ++triangles;
    }
  }
}

// The layer's own colours and inverse depths interpolated (push-pull) into the nearer pixels within
// reach of it: the surface the layer is assumed to continue as behind them.
std::vector<Source> Renderer::extend_layer(const std::vector<int>& layer_of, int layer, double reach_px) const {
  const int w = image_.width, h = image_.height;
  // Nearer pixels within a (2 reach + 1)-pixel square of a pixel of the layer: a separable
  // dilation, rows then columns, each line independent (threads).
  const int reach = static_cast<int>(reach_px);
  const int far = std::numeric_limits<int>::max() / 4;
  std::vector<int> row_distance(static_cast<std::size_t>(w) * h);
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (int y = 0; y < h; ++y) {
    int* d = row_distance.data() + static_cast<std::size_t>(y) * w;
    const int* l = layer_of.data() + static_cast<std::size_t>(y) * w;
    int last = far;
    for (int x = 0; x < w; ++x) d[x] = l[x] == layer ? (last = 0) : (last = std::min(far, last + 1));
    last = far;
    for (int x = w - 1; x >= 0; --x) d[x] = std::min(d[x], l[x] == layer ? (last = 0) : (last = std::min(far, last + 1)));
  }
  std::vector<std::uint8_t> within(static_cast<std::size_t>(w) * h, 0);
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (int x = 0; x < w; ++x) {
    int last = far;
    for (int y = 0; y < h; ++y) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      last = row_distance[i] <= reach ? 0 : std::min(far, last + 1);
      within[i] = last <= reach ? 1 : 0;
    }
    last = far;
    for (int y = h - 1; y >= 0; --y) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      last = row_distance[i] <= reach ? 0 : std::min(far, last + 1);
      within[i] = (within[i] || last <= reach) ? 1 : 0;
    }
  }
  std::vector<std::size_t> targets;
  int x0 = w, x1 = -1, y0 = h, y1 = -1;
  for (std::size_t i = 0; i < within.size(); ++i) {
    if (layer_of[i] > layer && within[i]) {
      targets.push_back(i);
      const int x = static_cast<int>(i % static_cast<std::size_t>(w)), y = static_cast<int>(i / static_cast<std::size_t>(w));
      x0 = std::min(x0, x);
      x1 = std::max(x1, x);
      y0 = std::min(y0, y);
      y1 = std::max(y1, y);
    }
  }
  if (targets.empty()) return {};
  // Push-pull over the window of the targets widened by the reach, where the layer's pixels that
  // feed them lie.
  x0 = std::max(0, x0 - reach);
  y0 = std::max(0, y0 - reach);
  x1 = std::min(w - 1, x1 + reach);
  y1 = std::min(h - 1, y1 + reach);
  const int ww = x1 - x0 + 1, wh = y1 - y0 + 1;
  std::vector<std::array<double, 5>> cells(static_cast<std::size_t>(ww) * wh, std::array<double, 5>{});
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      if (layer_of[i] != layer) continue;
      const double z = depth_.at(x, y);
      // Interpolated as x / (1 + x), so a few HDR highlights do not flood the invented surface.
      auto tone = [](float v) { return static_cast<double>(v) / (1.0 + static_cast<double>(v)); };
      cells[static_cast<std::size_t>(y - y0) * ww + (x - x0)] = {tone(image_.at(x, y, 0)), tone(image_.at(x, y, 1)),
                                                                  tone(image_.at(x, y, 2)),
                                                                  std::isinf(z) ? 0.0 : 1.0 / mm_from_m(z), 1.0};
    }
  }
  push_pull(ww, wh, cells);
  std::vector<Source> out;
  out.reserve(targets.size());
  for (std::size_t i : targets) {
    const std::size_t wx = i % static_cast<std::size_t>(w) - static_cast<std::size_t>(x0);
    const std::size_t wy = i / static_cast<std::size_t>(w) - static_cast<std::size_t>(y0);
    const auto& v = cells[wy * static_cast<std::size_t>(ww) + wx];
    Source s;
    s.x = static_cast<int>(i % static_cast<std::size_t>(w));
    s.y = static_cast<int>(i / static_cast<std::size_t>(w));
    auto untone = [](double t) { return static_cast<float>(std::min(t, 0.999) / (1.0 - std::min(t, 0.999))); };
    s.rgb = {untone(v[0]), untone(v[1]), untone(v[2])};
    s.inverse_depth_per_mm = v[3];
    s.coc_px = camera_.signed_coc_px(v[3]);
    out.push_back(s);
  }
  return out;
}

Image Renderer::run(BokehStatistics& stats) {
  const int w = image_.width, h = image_.height;
  // Sources and their signed blur.
  std::vector<Source> sources(static_cast<std::size_t>(w) * h);
  std::size_t clamped = 0;
  double coc_min = kInfinity, coc_max = -kInfinity;
#pragma omp parallel for num_threads(threads_) schedule(static) reduction(+ : clamped) reduction(min : coc_min) reduction(max : coc_max)
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double z = depth_.at(x, y);
      Source& s = sources[static_cast<std::size_t>(y) * w + x];
      s.x = x;
      s.y = y;
      s.rgb = {image_.at(x, y, 0), image_.at(x, y, 1), image_.at(x, y, 2)};
      s.inverse_depth_per_mm = clamp_inverse_depth(std::isinf(z) ? 0.0 : 1.0 / mm_from_m(z), clamped);
      s.coc_px = camera_.signed_coc_px(s.inverse_depth_per_mm);
      coc_min = std::min(coc_min, s.coc_px);
      coc_max = std::max(coc_max, s.coc_px);
    }
  }
  stats.source_pixels = sources.size();
  stats.clamped_depths = clamped;
  stats.max_abs_coc_px = std::max(std::abs(coc_min), std::abs(coc_max));

  // Layers evenly spaced in signed CoC, far (most negative) first.
  const double spacing = std::max(options_.layer_spacing_px, (coc_max - coc_min) / options_.max_layers);
  const int layer_count = std::max(1, static_cast<int>(std::floor((coc_max - coc_min) / spacing)) + 1);
  std::vector<int> layer_of(sources.size());
  std::vector<std::vector<int>> members(static_cast<std::size_t>(layer_count));
  std::vector<double> layer_max_blur(static_cast<std::size_t>(layer_count), 0.0);
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const int l = std::min(layer_count - 1, static_cast<int>(std::floor((sources[i].coc_px - coc_min) / spacing)));
    layer_of[i] = l;
    members[static_cast<std::size_t>(l)].push_back(static_cast<int>(i));
    layer_max_blur[static_cast<std::size_t>(l)] = std::max(layer_max_blur[static_cast<std::size_t>(l)], std::abs(sources[i].coc_px));
  }
  // Reach of the blur of every layer nearer than l (for Extend).
  std::vector<double> nearer_blur(static_cast<std::size_t>(layer_count), 0.0);
  for (int l = layer_count - 2; l >= 0; --l) {
    nearer_blur[static_cast<std::size_t>(l)] = std::max(nearer_blur[static_cast<std::size_t>(l) + 1], layer_max_blur[static_cast<std::size_t>(l) + 1]);
  }
  stats.layer_spacing_px = spacing;

  std::vector<float> layer_rgba(static_cast<std::size_t>(w) * h * 4);
  std::vector<double> result(static_cast<std::size_t>(w) * h * 4, 0.0);  // premultiplied RGB + coverage
  const int bands = std::max(1, std::min(h, threads_ * 4));
  std::size_t done = 0;
  std::atomic<std::size_t> footprints{0}, triangles{0};

  for (int l = 0; l < layer_count; ++l) {
    std::vector<Source> layer;
    layer.reserve(members[static_cast<std::size_t>(l)].size());
    for (int i : members[static_cast<std::size_t>(l)]) layer.push_back(sources[static_cast<std::size_t>(i)]);
    if (options_.hidden == HiddenSurfaces::Extend && !layer.empty() && nearer_blur[static_cast<std::size_t>(l)] >= 1.0) {
      const double reach = std::min(0.5 * nearer_blur[static_cast<std::size_t>(l)] + 2.0, 0.5 * (w + h));
      std::vector<Source> extra = extend_layer(layer_of, l, reach);
      stats.extended_pixels += extra.size();
      layer.insert(layer.end(), extra.begin(), extra.end());
    }
    if (layer.empty()) continue;
    ++stats.layers;

    // Phase 1: footprint extents and sample counts.
    std::vector<Plan> plans(layer.size());
#pragma omp parallel num_threads(threads_)
    {
      std::vector<PupilPoint> pupil;
      std::vector<SensorHit> hits;
#pragma omp for schedule(dynamic, 256)
      for (std::size_t i = 0; i < layer.size(); ++i) plans[i] = plan(layer[i], pupil, hits);
    }

    // Phase 2: each band of rows scatters the footprints that reach it, then composites its rows
    // of this layer under the nearer ones already... (back to front: this layer over the result).
#pragma omp parallel num_threads(threads_)
    {
      std::vector<SensorHit> hits;
      std::vector<Point2f> points;
      std::size_t local_footprints = 0, local_triangles = 0;
#pragma omp for schedule(dynamic, 1)
      for (int b = 0; b < bands; ++b) {
        const int row_begin = b * h / bands, row_end = (b + 1) * h / bands;
        if (row_begin == row_end) continue;
        // Tall footprints need fewer sub-rows: only their top and bottom rows see the y sampling.
        // A buffer is made only for the classes this band meets in this layer.
        std::array<std::optional<SplatBuffer>, 3> buffers;
        for (std::size_t i = 0; i < layer.size(); ++i) {
          if (plans[i].y_max < static_cast<float>(row_begin) - 1.0f || plans[i].y_min > static_cast<float>(row_end) + 1.0f) continue;
          const float height = plans[i].y_max - plans[i].y_min;
          const int kind = height < kMediumFootprintPx ? 0 : height < kTallFootprintPx ? 1 : 2;
          std::optional<SplatBuffer>& buffer = buffers[static_cast<std::size_t>(kind)];
          if (!buffer) buffer.emplace(w, row_begin, row_end, subrow_options(1 << kind));
          std::optional<SplatBuffer>& fine = buffers[0];
          if (plans[i].mesh >= 0 && !fine) fine.emplace(w, row_begin, row_end, subrow_options(1));
          scatter(layer[i], plans[i], *buffer, plans[i].mesh >= 0 ? *fine : *buffer, hits, points, local_triangles);
          local_footprints += static_cast<std::size_t>(plans[i].groups);
        }
        float* rows = layer_rgba.data() + static_cast<std::size_t>(row_begin) * w * 4;
        std::fill(rows, rows + static_cast<std::size_t>(row_end - row_begin) * w * 4, 0.0f);
        bool any = false;
        for (const std::optional<SplatBuffer>& buffer : buffers) {
          if (!buffer) continue;
          buffer->resolve_into(layer_rgba.data());
          any = true;
        }
        if (!any) continue;  // nothing of this layer reaches these rows: the result is unchanged
        // Within a layer, overlapping footprints of one surface average; its coverage is at most 1.
        for (std::size_t k = static_cast<std::size_t>(row_begin) * w; k < static_cast<std::size_t>(row_end) * w; ++k) {
          double c[4] = {layer_rgba[4 * k], layer_rgba[4 * k + 1], layer_rgba[4 * k + 2], layer_rgba[4 * k + 3]};
          if (c[3] > 1.0) {
            for (double& v : c) v /= c[3];
          } else if (c[3] < 0.0) {
            continue;  // rounding of an empty region
          }
          const double keep = 1.0 - c[3];
          for (int ch = 0; ch < 4; ++ch) result[4 * k + ch] = c[ch] + keep * result[4 * k + ch];
        }
      }
      footprints += local_footprints;
      triangles += local_triangles;
    }
    done += members[static_cast<std::size_t>(l)].size();
    if (options_.progress) options_.progress(static_cast<double>(done) / static_cast<double>(sources.size()));
  }
  stats.footprints = footprints;
  stats.triangles = triangles;

  // Where no layer covers fully (image borders, seams between layers, a pixel whose own light
  // spread away with nothing behind it), fill the rest with the colour of the (nearly) fully
  // covered pixels around, by push-pull: a flat image stays flat, and a pixel that lost most of its
  // coverage takes its neighbours' colour rather than its own amplified light.
  std::vector<std::array<double, 5>> fill(static_cast<std::size_t>(w) * h, std::array<double, 5>{});
  bool any_gap = false;
  for (std::size_t k = 0; k < fill.size(); ++k) {
    const double coverage = result[4 * k + 3];
    any_gap = any_gap || coverage < 1.0 - 1e-9;
    if (coverage >= kKnownCoverage) fill[k] = {result[4 * k], result[4 * k + 1], result[4 * k + 2], 0.0, coverage};
  }
  if (any_gap) push_pull(w, h, fill);
  Image out(w, h, 3);
  for (std::size_t k = 0; k < out.pixel_count(); ++k) {
    const double gap = std::max(0.0, 1.0 - result[4 * k + 3]);
    for (int c = 0; c < 3; ++c) {
      out.data[3 * k + c] = static_cast<float>(std::max(0.0, result[4 * k + c] + (gap > 0.0 ? gap * fill[k][c] : 0.0)));
    }
  }
  return out;
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
     << chromatic_tolerance_px << " px, max blur " << max_blur_px << " px)";
  return os.str();
}

std::string BokehStatistics::to_string() const {
  std::ostringstream os;
  os << "BokehStatistics(" << layers << " layers at " << layer_spacing_px << " px, " << source_pixels << " pixels, "
     << extended_pixels << " extended, " << footprints << " footprints, " << triangles << " triangles, "
     << clamped_depths << " clamped depths, max |CoC| " << max_abs_coc_px << " px)";
  return os.str();
}

Image render_bokeh(const Image& image, const DepthMap& depth, const RayModel& model, const Aperture& aperture,
                   const BokehOptions& options, BokehStatistics* statistics) {
  options.validate();
  if (image.channels != 3) throw OptionsError("the bokeh renderer takes a 3-channel linear RGB image, got " + image.to_string());
  const PinholeFrame& frame = model.camera().frame();
  if (image.width != depth.width || image.height != depth.height) {
    throw OptionsError("image is " + std::to_string(image.width) + " x " + std::to_string(image.height) +
                       " but depth is " + std::to_string(depth.width) + " x " + std::to_string(depth.height));
  }
  if (image.width != frame.width_px() || image.height != frame.height_px()) {
    throw OptionsError("the camera was framed for " + std::to_string(frame.width_px()) + " x " +
                       std::to_string(frame.height_px()) + " but the image is " + std::to_string(image.width) + " x " +
                       std::to_string(image.height));
  }
  for (std::size_t i = 0; i < depth.z_m.size(); ++i) {
    if (!(depth.z_m[i] > 0.0f)) {
      throw OptionsError("depth at pixel (" + std::to_string(i % static_cast<std::size_t>(depth.width)) + ", " +
                         std::to_string(i / static_cast<std::size_t>(depth.width)) + ") is " +
                         format_number(depth.z_m[i]) + " m: the renderer needs depths > 0");
    }
  }
  BokehStatistics local;
  Renderer renderer(image, depth, model, aperture, options);
  Image out = renderer.run(statistics ? *statistics : local);
  return out;
}

}  // namespace lensmith

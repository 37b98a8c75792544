#include "footprint.h"

#include <algorithm>
#include <cmath>
#include <span>

#include "lensmith/core/units.h"

namespace lensmith::render_detail {

namespace {

// Footprints narrower than this (px) are deposited as points: the 2 px tent hides their shape.
constexpr double kPointFootprintPx = 0.2;
// A model is treated as affine over a footprint when no probe ray departs from the affine map
// through three of them by more than this (px).
constexpr double kAffineTolerancePx = 0.25;
// Margin (px) added around the probed footprint: the 2 px tent; meshes add a quarter of their size
// for the parts between probe rays.
constexpr double kTentMarginPx = 2.0;
constexpr double kMeshMarginFraction = 0.25;
// Rings of a polar mesh per pixel of footprint size: models that clip at real clear apertures
// (exact, poly) need rings fine enough for a vignetted beam's edge (at least 4, one per 6 px);
// the others one ring per 16 px carries the radial light distribution.
constexpr double kMinClippingRings = 4.0;
constexpr double kPxPerClippingRing = 6.0;
constexpr double kPxPerRing = 16.0;
// Grid cells of an aperture-picture mesh per pixel of footprint size.
constexpr double kPxPerGridCell = 1.5;

// A polar mesh mapped without folds deposits as nested rings: annulus k (between mapped rings k-1
// and k) carries its share of the pupil, (2k - 1) / R^2, spread evenly over its mapped area. As the
// scatter is linear, annulus k is ring polygon k at density d_k minus ring polygon k-1 at d_k, so
// ring polygon k is deposited once with area * (d_k - d_(k+1)): R polygons at O(height) each
// instead of 2 R S small triangles. The radial light distribution (spherical aberration's bright
// or dark rims) is kept; light varying around a ring (coma's flare) is averaged over each annulus.
// Returns false, depositing nothing, when a ray is lost or the rings are not nested (a fold or
// caustic): the caller then uses the triangles.
bool deposit_ring_polygons(const PupilMesh& mesh, const std::vector<SensorHit>& hits, const std::vector<Point2f>& points,
                           const std::array<float, 4>& value, bool weighted, SplatBuffer& buffer, std::vector<double>& areas) {
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
  // The mean radiometric weight of the rays bounding each annulus (the centre ray for the first).
  auto ring_weight = [&](int k) {
    if (k == 0) return hits[0].weight;
    double sum = 0.0;
    for (int j = 0; j < sectors; ++j) sum += hits[1 + static_cast<std::size_t>(k - 1) * sectors + static_cast<std::size_t>(j)].weight;
    return sum / sectors;
  };
  // Light densities d_k per unit of value and coverage densities c_k (the annulus's share of the
  // pupil, without the weights), then one deposit per ring polygon.
  auto share = [&](int k) { return static_cast<double>(2 * k - 1) / (static_cast<double>(rings) * rings); };
  auto area = [&](int k) { return areas[static_cast<std::size_t>(k)] - areas[static_cast<std::size_t>(k) - 1]; };
  auto light = [&](int k) {
    if (k > rings) return 0.0;
    const double weight = weighted ? 0.5 * (ring_weight(k - 1) + ring_weight(k)) : 1.0;
    return share(k) * weight / area(k);
  };
  auto coverage = [&](int k) { return k > rings ? 0.0 : share(k) / area(k); };
  for (int k = 1; k <= rings; ++k) {
    const auto f = static_cast<float>(areas[static_cast<std::size_t>(k)] * (light(k) - light(k + 1)));
    const auto c = static_cast<float>(areas[static_cast<std::size_t>(k)] * (coverage(k) - coverage(k + 1)));
    const std::span<const Point2f> ring(points.data() + 1 + static_cast<std::size_t>(k - 1) * sectors, static_cast<std::size_t>(sectors));
    buffer.add_polygon(ring, {value[0] * f, value[1] * f, value[2] * f, value[3] * c});
  }
  return true;
}

// The share of a triangle's area where a function linear over it, with values a, b, c at the
// corners, is >= 0: with one corner on the positive side the small triangle cut off there has the
// share p^2 / ((p - q)(p - r)) of the area (similar triangles along its two edges).
double positive_share(double a, double b, double c) {
  const int positive = (a >= 0.0) + (b >= 0.0) + (c >= 0.0);
  if (positive == 3) return 1.0;
  if (positive == 0) return 0.0;
  // Order so that `lone` is the corner alone on its side.
  double lone = a, u = b, v = c;
  const bool lone_positive = positive == 1;
  if ((b >= 0.0) == lone_positive) {
    lone = b, u = a, v = c;
  } else if ((c >= 0.0) == lone_positive) {
    lone = c, u = a, v = b;
  }
  const double corner = lone * lone / ((lone - u) * (lone - v));
  return lone_positive ? corner : 1.0 - corner;
}

}  // namespace

double FootprintScatter::passing_share(FootprintScratch& scratch) const {
  // The finest outline: a coarse one would misjudge how much of the circle a disc cuts off.
  const std::vector<PupilPoint>& outline = meshes_.outline(PupilMeshTable::kFinestOutline);
  clip_pupil_polygon(outline, scratch.discs, scratch.clipped, scratch.clip_work);
  return scratch.clipped.size() < 3 ? 0.0 : pupil_polygon_area(scratch.clipped) / pupil_polygon_area(outline);
}

std::array<float, 4> FootprintScatter::lit(const std::array<float, 4>& value, double weight) const {
  if (!options_.vignetting) return value;
  const auto w = static_cast<float>(weight);
  return {value[0] * w, value[1] * w, value[2] * w, value[3]};
}

FootprintScatter::FootprintScatter(const RayModel& model, const Aperture& aperture, const SpectralGroups& groups,
                                   const PupilMeshTable& meshes, const BokehOptions& options)
    : model_(model), camera_(model.camera()), aperture_(aperture), groups_(groups), meshes_(meshes), options_(options) {
  probe_[0] = {0.0, 0.0};
  for (int k = 0; k < 8; ++k) {
    const double a = kPi / 2.0 + 2.0 * kPi * k / 8.0;
    const double r = aperture_.kind() == Aperture::Kind::Mask ? 1.0 : aperture_.edge_radius(a);
    probe_[static_cast<std::size_t>(k) + 1] = {r * std::cos(a), r * std::sin(a)};
  }
}

FootprintPlan FootprintScatter::plan(const ScatterSource& s, FootprintScratch& scratch) const {
  std::vector<PupilPoint>& pupil = scratch.pupil;
  std::vector<SensorHit>& hits = scratch.hits;
  const PixelPoint centre{s.x + 0.5, s.y + 0.5};
  const Tangents t = camera_.frame().tangents_at(centre);
  const ScenePoint point{t.x, t.y, s.inverse_depth_per_mm};
  FootprintPlan p;
  const bool affine = model_.affine_in_pupil() && aperture_.is_uniform_convex();
  // Probe: the pupil centre and its edge (8 points) at the extreme wavelengths and the reference.
  pupil.assign(probe_.begin(), probe_.end());
  hits.resize(pupil.size());
  const std::array<double, 3> lambdas{camera_.reference_wavelength_nm(), groups_.lowest_nm(), groups_.highest_nm()};
  std::array<std::array<PixelPoint, 9>, 3> px{};
  std::array<std::array<bool, 9>, 3> ok{};  // where the ray lands is known (it passes, or would)
  bool any_clipped = false;
  double x_min = kInfinity, x_max = -kInfinity, y_min = kInfinity, y_max = -kInfinity;
  // Without dispersion (a thin lens, or colour off) one wavelength tells all.
  const std::size_t wavelengths = camera_.is_thin_lens() || !options_.spectral ? 1 : 3;
  for (std::size_t l = 0; l < wavelengths; ++l) {
    model_.map(point, lambdas[l], pupil, hits);
    for (std::size_t i = 0; i < 9; ++i) {
      ok[l][i] = hits[i].ok || hits[i].unclipped;
      any_clipped = any_clipped || !hits[i].ok;
      if (!ok[l][i]) continue;
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
    near_affine = worst < kAffineTolerancePx;
  }
  // A clipped beam is one polygon only where the model describes its clipping as pupil discs.
  model_.clip_discs(point, scratch.discs);
  if (any_clipped && scratch.discs.empty()) near_affine = false;
  double spread = 0.0;
  for (std::size_t i = 0; i < 9; ++i) {
    if (ok[1][i] && ok[2][i]) spread = std::max(spread, std::hypot(px[1][i].x - px[2][i].x, px[1][i].y - px[2][i].y));
  }
  const double size = std::max(x_max - x_min, y_max - y_min);
  // Coverage has no colour: one group carries it.
  p.groups = s.coverage_only ? 1 : std::clamp(static_cast<int>(std::ceil(spread / options_.chromatic_tolerance_px)), 1, groups_.max_count());
  const double margin = near_affine ? kTentMarginPx : kTentMarginPx + kMeshMarginFraction * size;
  p.y_min = static_cast<float>(y_min - margin);
  p.y_max = static_cast<float>(y_max + margin);
  const int sector_step = PupilMeshTable::sector_step(size);
  const bool all_pass = !any_clipped;
  if (size < kPointFootprintPx && all_pass) {
    p.outline = FootprintPlan::kPoint;
  } else if (near_affine) {
    p.outline = sector_step;
  } else if (aperture_.kind() == Aperture::Kind::Mask) {
    p.mesh = PupilMeshTable::grid_mesh(size / kPxPerGridCell);
  } else {
    const bool clips = any_clipped || model_.kind() == RayModelKind::Exact || model_.kind() == RayModelKind::Poly;
    const double rings = clips ? std::max(kMinClippingRings, size / kPxPerClippingRing) : size / kPxPerRing;
    p.mesh = PupilMeshTable::polar_mesh(rings, sector_step);
  }
  return p;
}

void FootprintScatter::deposit(const ScatterSource& s, const FootprintPlan& p, SplatBuffer& buffer, SplatBuffer& fine,
                               FootprintScratch& scratch, std::size_t& triangles) const {
  std::vector<SensorHit>& hits = scratch.hits;
  std::vector<Point2f>& points = scratch.points;
  const Tangents t = camera_.frame().tangents_at({s.x + 0.5, s.y + 0.5});
  const ScenePoint point{t.x, t.y, s.inverse_depth_per_mm};
  model_.clip_discs(point, scratch.discs);
  for (const SpectralGroup& g : groups_.split(p.groups)) {
    std::array<float, 4> value{};
    for (std::size_t c = 0; c < 3; ++c) value[c] = g.m[c][0] * s.rgb[0] + g.m[c][1] * s.rgb[1] + g.m[c][2] * s.rgb[2];
    value[3] = g.alpha * s.coverage;
    if (p.outline == FootprintPlan::kPoint) {
      static constexpr std::array<PupilPoint, 1> kCentre{{{0.0, 0.0}}};
      hits.resize(1);
      model_.map(point, g.wavelength_nm, kCentre, std::span<SensorHit>(hits.data(), 1));
      if (!hits[0].ok) continue;
      const PixelPoint c = camera_.output_pixel(hits[0].x_mm, hits[0].y_mm);
      buffer.add_point({static_cast<float>(c.x), static_cast<float>(c.y)}, lit(value, hits[0].weight));
      continue;
    }
    if (p.mesh < 0) {
      // Affine model, uniform convex aperture: the outline, less what first-order vignetting cuts
      // off, mapped by the affine map of three rays; it keeps the share of the light that passes.
      static constexpr std::array<PupilPoint, 3> kBasis{{{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}}};
      hits.resize(3);
      model_.map(point, g.wavelength_nm, kBasis, std::span<SensorHit>(hits.data(), 3));
      const PixelPoint o = camera_.output_pixel(hits[0].x_mm, hits[0].y_mm);
      const PixelPoint ex = camera_.output_pixel(hits[1].x_mm, hits[1].y_mm);
      const PixelPoint ey = camera_.output_pixel(hits[2].x_mm, hits[2].y_mm);
      const std::vector<PupilPoint>* outline = &meshes_.outline(p.outline);
      double passing = 1.0;
      if (!scratch.discs.empty()) {
        passing = passing_share(scratch);
        clip_pupil_polygon(*outline, scratch.discs, scratch.clipped, scratch.clip_work);
        if (scratch.clipped.size() < 3 || !(passing > 0.0)) continue;  // the whole beam is stopped
        outline = &scratch.clipped;
      }
      points.resize(outline->size());
      for (std::size_t i = 0; i < outline->size(); ++i) {
        const PupilPoint& q = (*outline)[i];
        points[i] = {static_cast<float>(o.x + (ex.x - o.x) * q.x + (ey.x - o.x) * q.y),
                     static_cast<float>(o.y + (ex.y - o.y) * q.x + (ey.y - o.y) * q.y)};
      }
      std::array<float, 4> v = lit(value, hits[0].weight);
      const auto light = static_cast<float>(options_.vignetting ? passing : 1.0);
      for (std::size_t c = 0; c < 3; ++c) v[c] *= light;
      buffer.add_polygon(points, v);
      continue;
    }
    const PupilMesh& mesh = meshes_.mesh(p.mesh);
    hits.resize(mesh.points.size());
    model_.map(point, g.wavelength_nm, mesh.points, hits);
    points.resize(mesh.points.size());
    for (std::size_t i = 0; i < mesh.points.size(); ++i) {
      if (!hits[i].unclipped && !hits[i].ok) continue;
      const PixelPoint q = camera_.output_pixel(hits[i].x_mm, hits[i].y_mm);
      points[i] = {static_cast<float>(q.x), static_cast<float>(q.y)};
    }
    if (mesh.sectors > 0 && deposit_ring_polygons(mesh, hits, points, value, options_.vignetting, buffer, scratch.areas)) continue;
    // A triangle whose corners a clear aperture partly stops (exact, poly) passes the part of its
    // area where the linear interpolation of their clearances is >= 0, in place: the beam's edge
    // falls inside it, to first order.
    auto passing = [&hits](const PupilTriangle& tri) {
      const SensorHit& a = hits[static_cast<std::size_t>(tri.a)];
      const SensorHit& b = hits[static_cast<std::size_t>(tri.b)];
      const SensorHit& c = hits[static_cast<std::size_t>(tri.c)];
      if (!(a.ok || a.unclipped) || !(b.ok || b.unclipped) || !(c.ok || c.unclipped)) return 0.0;
      return positive_share(a.clearance, b.clearance, c.clearance);
    };
    // Colour carries the transmitted fraction and the rays' radiometric weights (vignetting darkens);
    // coverage is normalised over the light that passes, so a vignetted point is still an opaque
    // surface. Without vignetting the colour is normalised the same way.
    double passed = 0.0;
    for (const PupilTriangle& tri : mesh.triangles) passed += tri.weight * passing(tri);
    if (!(passed > 0.0)) continue;
    // Where the model describes its clipping as discs, the light that passes is known exactly (the
    // outline less the discs); the triangles' linear interpolation only distributes it.
    const double exact_share = !scratch.discs.empty() && aperture_.is_uniform_convex() ? passing_share(scratch) : passed;
    const double unlit = options_.vignetting ? exact_share / passed : 1.0 / passed;
    for (const PupilTriangle& tri : mesh.triangles) {
      const double fraction = passing(tri);
      if (fraction == 0.0) continue;
      const double ray_weight = options_.vignetting ? (hits[tri.a].weight + hits[tri.b].weight + hits[tri.c].weight) / 3.0 : 1.0;
      const auto w = static_cast<float>(tri.weight * fraction * ray_weight * unlit);
      fine.add_triangle(points[static_cast<std::size_t>(tri.a)], points[static_cast<std::size_t>(tri.b)],
                        points[static_cast<std::size_t>(tri.c)],
                        {value[0] * w, value[1] * w, value[2] * w, static_cast<float>(value[3] * tri.weight * fraction / passed)});
      ++triangles;
    }
  }
}

}  // namespace lensmith::render_detail

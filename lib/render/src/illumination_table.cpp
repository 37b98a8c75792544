#include "illumination_table.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

#include "lensmith/camera/lens_camera.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "mapped_pupil_table.h"

namespace lensmith::render_detail {

namespace {

// The discs' radius factor is looked for up to this (beyond it the first-order discs are too far off
// to say where the real beam passes) and to this precision.
constexpr double kMaxDiscScale = 4.0;
constexpr int kBisections = 24;
// The real lens's nodes span this many times the model's field.
constexpr double kRealReach = 2.0;
// Below this share of the axis's light the model passes nothing worth scaling (its discs stop the
// beam, which it then draws as an opaque point that sends no light).
constexpr double kNothing = 1e-6;
// The discs are widened where they pass less than this share of what the real lens passes, fully
// where less than the second. Widened wherever they pass less at all (the Canon 35 mm's corners: 4-8 %
// in radius), a flat defocused wall there rippled by 3.3 % from pixel to pixel (0.19 % without, 0.30 %
// with these); from 0.5 (fully at 0.25), the retrofocus's disc edge swept through faster than the
// widening began, and a flat wall showed a ring of +-4 % at 40 deg (1 % with these).
constexpr double kWiden = 0.8;
constexpr double kWidenFully = 0.4;
// A share the widest discs cannot reach is approached to this fraction of their most.
constexpr double kReachable = 0.999;
// The real lens's brightness is measured at this many output radii from the frame's centre to
// kSensorReach times its corner's (with the margin), each on kPupilRings x kPupilSectors points of
// equal area on the pupil disc LensCamera samples: 147,456 rays, about 20 ms on two threads (the
// README job). On lentil 0004 at f/2.8 the curve is within 0.1 % of one on 96 x 256 points (24 x 64:
// 0.3 %, 10 ms).
constexpr int kSensorRadii = 48;
constexpr double kSensorReach = 1.05;
constexpr double kGoldenFraction = 0.6180339887498949;
constexpr int kPupilRings = 32, kPupilSectors = 96;

// What a node measures of one model: where the chief ray lands (output px), and of a uniform
// surface's point the light it sends through the pupil (the mean over the unit pupil of the rays'
// weights where they pass) and the share of the pupil that passes; or lands = false.
struct Beam {
  bool lands = false;
  double x_px = 0.0, y_px = 0.0;
  double light = 0.0;
  double share = 0.0;
  // Where its light lands on average (output px; the chief ray's where none passes).
  double light_x_px = 0.0, light_y_px = 0.0;
};

// A node's rays on the fine mesh, and the discs that clip them (first-order models).
struct NodeRays {
  std::vector<SensorHit> hits;
  std::vector<double> clearance;  // with the discs at the scale last applied
  std::vector<PupilDisc> discs;
};

// The rays' clearances with the discs' radii scaled by `scale`: min of their own (traced apertures)
// and 1 - |p - c| / (scale R) of each disc.
void apply_discs(const PupilMesh& fine, double scale, NodeRays& n) {
  n.clearance.resize(n.hits.size());
  for (std::size_t i = 0; i < n.hits.size(); ++i) {
    n.clearance[i] = std::min(n.hits[i].clearance, disc_clearance(fine.points[i], n.discs, scale));
  }
}

// Each triangle passes the share where the linear interpolation of its corners' clearance is >= 0
// (MappedPupilTable::passing_light measures the same way), at its corners' mean weight for the light;
// a corner that lands nowhere loses its triangle.
void measure(const Camera& camera, const PupilMesh& fine, const NodeRays& n, Beam& beam) {
  beam.light = beam.share = 0.0;
  double total = 0.0, x_mm = 0.0, y_mm = 0.0;
  for (const PupilTriangle& t : fine.triangles) {
    total += t.weight;
    const auto a = static_cast<std::size_t>(t.a), b = static_cast<std::size_t>(t.b), c = static_cast<std::size_t>(t.c);
    const SensorHit& ha = n.hits[a];
    const SensorHit& hb = n.hits[b];
    const SensorHit& hc = n.hits[c];
    if (!(ha.ok || ha.unclipped) || !(hb.ok || hb.unclipped) || !(hc.ok || hc.unclipped)) continue;
    const double passing = t.weight * passing_share(n.clearance[a], n.clearance[b], n.clearance[c]);
    const double light = passing * (ha.weight + hb.weight + hc.weight) / 3.0;
    beam.share += passing;
    beam.light += light;
    x_mm += light * (ha.x_mm + hb.x_mm + hc.x_mm) / 3.0;
    y_mm += light * (ha.y_mm + hb.y_mm + hc.y_mm) / 3.0;
  }
  if (total > 0.0) beam.share /= total;
  beam.light_x_px = beam.x_px;
  beam.light_y_px = beam.y_px;
  if (beam.light > 0.0) {
    const PixelPoint q = camera.output_pixel(x_mm / beam.light, y_mm / beam.light);
    if (std::isfinite(q.x) && std::isfinite(q.y)) {
      beam.light_x_px = q.x;
      beam.light_y_px = q.y;
    }
  }
}

// Where `point`'s chief ray lands (output px), passing or stopped; nothing where it lands nowhere.
std::optional<PixelPoint> chief_landing(const RayModel& model, const ScenePoint& point, double wavelength_nm) {
  std::array<SensorHit, 1> chief;
  const std::array<PupilPoint, 1> centre{PupilPoint{0.0, 0.0}};
  model.map(point, wavelength_nm, centre, chief);
  if (!(chief[0].ok || chief[0].unclipped)) return std::nullopt;
  return model.camera().output_pixel(chief[0].x_mm, chief[0].y_mm);
}

// The chief ray's landing and the fine mesh's rays of `point`, the discs at scale 1.
Beam trace(const RayModel& model, const ScenePoint& point, double wavelength_nm, const PupilMesh& fine, NodeRays& n) {
  Beam beam;
  const std::optional<PixelPoint> q = chief_landing(model, point, wavelength_nm);
  if (!q) return beam;
  beam.lands = true;
  beam.x_px = q->x;
  beam.y_px = q->y;
  model.clip_discs(point, n.discs);
  n.hits.resize(fine.points.size());
  // The traced apertures' clearances (exact, poly); the first-order models' discs are applied here.
  model.map_passing(point, wavelength_nm, fine.points, n.hits);
  apply_discs(fine, 1.0, n);
  measure(model.camera(), fine, n, beam);
  return beam;
}

// Linear interpolation of ys over increasing xs at x, clamped to the ends.
double interpolate(const std::vector<double>& xs, const std::vector<double>& ys, double x) {
  if (xs.size() == 1 || x <= xs.front()) return ys.front();
  if (x >= xs.back()) return ys.back();
  const auto it = std::upper_bound(xs.begin(), xs.end(), x);
  const auto k = static_cast<std::size_t>(it - xs.begin());
  const double t = (x - xs[k - 1]) / (xs[k] - xs[k - 1]);
  return ys[k - 1] + t * (ys[k] - ys[k - 1]);
}

// The nodes' values at fractional node index f (0 .. kFieldNodes - 1), linearly.
double interpolated(const std::vector<double>& v, double f) {
  const auto i = std::min(static_cast<std::size_t>(f), v.size() - 2);
  const double t = f - static_cast<double>(i);
  return v[i] + t * (v[i + 1] - v[i]);
}

}  // namespace

bool IlluminationTable::applies(const RayModel& model, const Aperture& aperture, bool vignetting, bool exact_too) {
  const RayModelKind kind = model.kind();
  // A thin model stands for a real lens only where it was made for one (Camera::real_lens).
  const Camera& real = model.camera().real_lens() != nullptr ? *model.camera().real_lens() : model.camera();
  return vignetting &&
         (kind == RayModelKind::Thin || kind == RayModelKind::Paraxial || kind == RayModelKind::Seidel || kind == RayModelKind::Poly ||
          (exact_too && kind == RayModelKind::Exact)) &&
         aperture.kind() != Aperture::Kind::Mask && MappedPupilTable::round_lens(real);
}

IlluminationTable IlluminationTable::where_applies(const RayModel& model, const Aperture& aperture, bool vignetting, int margin_px,
                                                   double w_min, double w_max, int threads, bool thin_only, bool exact_too) {
  if ((thin_only && model.kind() != RayModelKind::Thin) || !applies(model, aperture, vignetting, exact_too)) return {};
  const PupilMeshTable meshes(aperture);
  const ImageAreaTable areas(model, margin_px, w_min, w_max, threads);
  return IlluminationTable(model, meshes.mesh(PupilMeshTable::light_mesh()), areas, margin_px, w_min, w_max, threads);
}

IlluminationTable::IlluminationTable(const RayModel& model, const PupilMesh& fine, const ImageAreaTable& areas, int margin_px,
                                     double w_min, double w_max, int threads) {
  const Camera& camera = model.camera();
  // The real lens's rays: for the disc-widening of the first-order models. The exact model has no
  // discs to widen (its rays are the real lens's).
  const bool own_rays = model.kind() == RayModelKind::Exact;
  const std::unique_ptr<RayModel> exact =
      own_rays ? nullptr : make_ray_model(RayModelKind::Exact, camera.real_lens() != nullptr ? *camera.real_lens() : camera);
  const PinholeFrame& frame = camera.frame();
  const double centre_x = 0.5 * frame.width_px(), centre_y = 0.5 * frame.height_px();
  const double reach_px = std::hypot(centre_x + margin_px, centre_y + margin_px);
  step_ = reach_px / frame.focal_length_px() / (kFieldNodes - 1);
  const int depth_nodes = w_max > w_min ? kDepthNodes : 1;
  w0_ = w_min;
  dw_ = depth_nodes > 1 ? (w_max - w_min) / (depth_nodes - 1) : 1.0;
  const double wavelength_nm = camera.reference_wavelength_nm();
  const auto nodes = static_cast<std::size_t>(depth_nodes) * kFieldNodes;
  // Node n at kRealReach times the model's field step for the real lens (its share of the pupil, for
  // the discs' widening).
  auto point_of = [&](std::size_t n, double reach) {
    return ScenePoint{static_cast<double>(n % kFieldNodes) * reach * step_, 0.0, w0_ + static_cast<double>(n / kFieldNodes) * dw_};
  };
  // Node n's image area is read at its field radius along the middle row while the area table reaches
  // that far, then up the table's side (the lens is round: the area depends on the radius alone). Read
  // along the row to the end, the frame's corner nodes took the area at the row's end: through
  // lentil's Biotar at f/2.8 the poly model's wall came out up to 0.034 of the centre too bright in a
  // 48 x 32 mm frame's corners (0.004 now; 0.033 -> 0.009 at f/1.4).
  // (Read along the diagonal instead, the Seidel model's area, which changes fast where its
  // polynomial nears the field it was made for, came out 0.026 off at a 50 deg retrofocus strip's end.)
  const double side_x = centre_x + margin_px, side_y = centre_y + margin_px;
  auto pixel_of = [&](std::size_t n) {
    const double rho = static_cast<double>(n % kFieldNodes) * step_ * frame.focal_length_px();
    const double dx = std::min(rho, side_x);
    return PixelPoint{centre_x + dx, centre_y + std::min(side_y, std::sqrt(std::max(0.0, rho * rho - dx * dx)))};
  };
  // The real lens's share of the pupil is read (the discs' widening) out to the model's own field,
  // the real lens's node past it.
  const auto own_field = static_cast<std::size_t>(std::ceil((kFieldNodes - 1) / kRealReach)) + 1;
  // The real lens at its nodes, the model on the axis (its share there is what the real lens's
  // relative share scales), then the model at every node with its discs widened to that share.
  std::vector<Beam> model_beam(nodes), real_beam(nodes);
  std::vector<double> model_area(nodes, 1.0), scale(nodes, 1.0);
#pragma omp parallel num_threads(threads)
  {
    NodeRays rays;
#pragma omp for schedule(dynamic, 1)
    for (std::size_t n = 0; n < nodes; ++n) {
      if (n % kFieldNodes == 0) model_beam[n] = trace(model, point_of(n, 1.0), wavelength_nm, fine, rays);
      if (own_rays || n % kFieldNodes > own_field) continue;  // lands = false: beyond what is read
      real_beam[n] = trace(*exact, point_of(n, kRealReach), wavelength_nm, fine, rays);
    }
#pragma omp for schedule(dynamic, 1)
    for (std::size_t n = 0; n < nodes; ++n) {
      const std::size_t axis = n - n % kFieldNodes;
      const PixelPoint pixel = pixel_of(n);
      model_area[n] = areas.at(pixel.x, pixel.y, point_of(n, 1.0).inverse_depth_per_mm);
      if (n == axis) continue;
      model_beam[n] = trace(model, point_of(n, 1.0), wavelength_nm, fine, rays);
      if (rays.discs.empty() || !model_beam[n].lands || !(real_beam[axis].share > 0.0)) continue;
      // The real lens's share at this field (its nodes are kRealReach times as far apart).
      const double real_f = static_cast<double>(n - axis) / kRealReach;
      const auto real_i = static_cast<std::size_t>(real_f);
      const Beam& r0 = real_beam[axis + real_i];
      const Beam& r1 = real_beam[axis + std::min(real_i + 1, static_cast<std::size_t>(kFieldNodes - 1))];
      if (!r0.lands || !r1.lands) continue;
      const double real_share = r0.share + (real_f - static_cast<double>(real_i)) * (r1.share - r0.share);
      const double target = model_beam[axis].share * real_share / real_beam[axis].share;
      // Only where the discs are far off (they pass less than kWiden of the real share), fully below
      // kWidenFully (see there).
      const double ratio = model_beam[n].share / target;
      if (!(ratio < kWiden)) continue;
      const double blend = std::min(1.0, (kWiden - ratio) / (kWiden - kWidenFully));
      // Bisection on the radius factor: the share grows with it.
      double lo = 1.0, hi = kMaxDiscScale;
      Beam b;
      apply_discs(fine, hi, rays);
      measure(camera, fine, rays, b);
      // A target the widest discs cannot reach (the real lens's share grows off axis beyond the
      // first-order discs' most): as near it as they come, not wider than needed.
      const double reachable = std::min(target, kReachable * b.share);
      if (b.share > reachable) {
        for (int k = 0; k < kBisections; ++k) {
          const double mid = 0.5 * (lo + hi);
          apply_discs(fine, mid, rays);
          measure(camera, fine, rays, b);
          (b.share < reachable ? lo : hi) = mid;
        }
      }
      scale[n] = 1.0 + blend * (hi - 1.0);
      apply_discs(fine, scale[n], rays);
      measure(camera, fine, rays, model_beam[n]);
    }
  }
  // The real lens's brightness at the film, as `lensmith scene render --lens` measures it: a film
  // point's irradiance from a uniform surface is the mean over the pupil of its rays' weights where
  // they pass (LensCamera: cos^4 / D^2 over the sampled disc, pbrt-v4's RealisticCamera). Taken at
  // the film rather than from the object side (a point's light over the image area its pixel maps
  // to), it needs no image areas and holds at every depth (every ray that reaches a film point from a
  // uniform surface brings the same radiance, however far the surface). The object side's estimate,
  // the beams' light over the chief rays' image area stretched to where their light lands, left the
  // first-order models 0.011-0.033 of the centre brighter than the truth at the frame's edge on
  // lentil 0001, 0009 and 0010 wide open, where the exact model is within 0.012: its stretch moved
  // with a light centroid that a 0.1 px error at the frame's edge turns into 1-2 %.
  real_rho_px_.assign(kSensorRadii, 0.0);
  real_relative_.assign(kSensorRadii, 0.0);  // the film's mean ray weight, then relative to the centre's
  std::optional<LensCamera> film;
  try {
    film.emplace(camera.real_lens() != nullptr ? *camera.real_lens() : camera, std::span<const double>(&wavelength_nm, 1));
  } catch (const ComputationError&) {
    return;  // empty: no ray from the film's centre passes the lens
  }
  const double sensor_step_px = kSensorReach * reach_px / (kSensorRadii - 1);
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
  for (int k = 0; k < kSensorRadii; ++k) {
    const double rho = k * sensor_step_px;
    const std::array<double, 2> at = film->film_point_mm(centre_x + rho, centre_y);
    double sum = 0.0;
    for (int j = 0; j < kPupilSectors; ++j) {
      // Each sector's rings offset by the golden ratio's multiples: rings at the same radii in every
      // sector counted a stop concentric with them by whole rings (0.6 % off on the axis at 96 rings).
      const double offset = std::fmod((j + 0.5) * kGoldenFraction, 1.0);
      for (int i = 0; i < kPupilRings; ++i) {
        const CameraRaySample ray = film->sample_ray(at[0], at[1], (i + offset) / kPupilRings, (j + 0.5) / kPupilSectors, wavelength_nm);
        if (ray.ok()) sum += ray.ray.weight;
      }
    }
    real_rho_px_[static_cast<std::size_t>(k)] = rho;
    real_relative_[static_cast<std::size_t>(k)] = sum / (kPupilRings * kPupilSectors);
  }
  const double centre_light = real_relative_[0];
  if (!(centre_light > 0.0)) return;
  for (double& light : real_relative_) light /= centre_light;
  std::vector<Depth> depths(static_cast<std::size_t>(depth_nodes));
  for (int d = 0; d < depth_nodes; ++d) {
    const std::size_t first = static_cast<std::size_t>(d) * kFieldNodes;
    const Beam& model_axis = model_beam[first];
    const Beam& real_axis = real_beam[first];
    if (!model_axis.lands || (!own_rays && !real_axis.lands) || !(model_axis.light > 0.0)) return;  // empty: nothing to scale against
    // The model's brightness B = L / A relative to the axis's.
    const double model_axis_b = model_axis.light / model_area[first];
    Depth& depth = depths[static_cast<std::size_t>(d)];
    double rho_before = -1.0;
    for (std::size_t i = 0; i < kFieldNodes; ++i) {
      const Beam& m = model_beam[first + i];
      depth.disc_scale.push_back(scale[first + i]);
      depth.model_share.push_back(m.share);
      depth.model_relative.push_back(m.lands && model_area[first + i] > 0.0 ? m.light / model_area[first + i] / model_axis_b : -1.0);
      const double rho = std::hypot(m.x_px - model_axis.x_px, m.y_px - model_axis.y_px);
      depth.model_rho_px.push_back(m.lands ? std::hypot(m.light_x_px - model_axis.x_px, m.light_y_px - model_axis.y_px) : 0.0);
      if (m.lands && rho > rho_before && depth.unfolded + 1 == i) depth.unfolded = i;
      rho_before = m.lands ? rho : kInfinity;
    }
    // The factor is kept per node (a source's interpolated between them: no search per footprint).
    for (std::size_t i = 0; i < kFieldNodes; ++i) depth.factor.push_back(node_factor(depth, i));
    widened_ = widened_ || std::any_of(depth.disc_scale.begin(), depth.disc_scale.end(), [](double k) { return k != 1.0; });
  }
  depths_ = std::move(depths);
}

double IlluminationTable::node_factor(const Depth& d, std::size_t i) const {
  const double model = d.model_relative[i];
  if (model < 0.0) return 1.0;             // the model's chief ray lands nowhere: its own light stays
  if (!(model > kNothing)) return 1.0;     // the model passes nothing here (an opaque point that sends no light)
  return std::clamp(interpolate(real_rho_px_, real_relative_, d.model_rho_px[i]) / model, 0.0, kMaxFactor);
}

template <typename Of>
double IlluminationTable::at(const ScenePoint& point, Of&& of) const {
  const double f = std::clamp(std::sqrt(point.tan_x * point.tan_x + point.tan_y * point.tan_y) / step_, 0.0, static_cast<double>(kFieldNodes - 1));
  if (depths_.size() == 1) return of(depths_[0], f);
  const double fd = std::clamp((point.inverse_depth_per_mm - w0_) / dw_, 0.0, static_cast<double>(depths_.size() - 1));
  const std::size_t id = std::min(static_cast<std::size_t>(fd), depths_.size() - 2);
  const double td = fd - static_cast<double>(id);
  return (1.0 - td) * of(depths_[id], f) + td * of(depths_[id + 1], f);
}

float IlluminationTable::factor(const ScenePoint& point) const {
  if (depths_.empty()) return 1.0f;
  return static_cast<float>(at(point, [](const Depth& d, double f) { return interpolated(d.factor, f); }));
}

bool IlluminationTable::unfolded(const ScenePoint& point) const {
  if (depths_.empty()) return false;
  const double f = std::sqrt(point.tan_x * point.tan_x + point.tan_y * point.tan_y) / step_;
  return std::all_of(depths_.begin(), depths_.end(), [f](const Depth& d) { return f <= static_cast<double>(d.unfolded); });
}

double IlluminationTable::widened_share(const ScenePoint& point) const {
  if (!widened_) return 0.0;
  const double scale = at(point, [](const Depth& d, double f) { return interpolated(d.disc_scale, f); });
  if (scale == 1.0) return 0.0;
  return at(point, [](const Depth& d, double f) { return interpolated(d.model_share, f); });
}

bool IlluminationTable::widen(const ScenePoint& point, std::vector<PupilDisc>& discs) const {
  if (!widened_ || discs.empty()) return false;
  const double scale = at(point, [](const Depth& d, double f) { return interpolated(d.disc_scale, f); });
  if (scale == 1.0) return false;
  for (PupilDisc& d : discs) d.radius *= scale;
  return true;
}

}  // namespace lensmith::render_detail

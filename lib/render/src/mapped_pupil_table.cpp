#include "mapped_pupil_table.h"

#include <algorithm>
#include <cmath>

#include "lensmith/core/errors.h"

namespace lensmith::render_detail {

namespace {

// A node's hit, packed: a sensor position in float is within 3e-6 mm of the model's over a 36 mm
// frame (a ten-thousandth of a 1920-pixel frame's pixel).
struct PackedHit {
  float x_mm = 0.0f, y_mm = 0.0f, clearance = 0.0f, weight = 0.0f;
};
// Where a node's ray lands: lost (no landing known), stopped by a clear aperture (landing known), passing.
constexpr std::uint8_t kLost = 0, kLands = 1;

// A thread's cache of nodes, by a hash of key and wavelength (its top kCacheBits bits). A footprint
// looks up four nodes for each of its sets (mesh, probe, light) at each of its wavelength groups'
// wavelengths: with 64 slots the exact model's render of the 480 x 270 bench scene spent 5.5 % of
// its time in the table's lock (perf), with 1024 (24 KiB a thread) 2.2 %; at 1080p, drawn from
// light images (the render's other costs gone), 10 % with 1024 (with the images' cache), none
// found with 16384 (384 KiB a thread, kept from layer to layer).
constexpr int kCacheBits = 14;
// A point within this (in node steps) of a node is on it (Cell).
constexpr double kOnNode = 1e-9;

std::uint64_t pack_key(int set, std::int64_t field_index, std::int64_t depth_index) {
  // set < 2^16, field index < 2^20, depth index within +-2^27.
  return (static_cast<std::uint64_t>(set) << 48) | (static_cast<std::uint64_t>(field_index) << 28) |
         static_cast<std::uint64_t>(depth_index + (std::int64_t{1} << 27));
}

}  // namespace

struct MappedPupilTable::Node {
  std::vector<PackedHit> hits;
  std::vector<std::uint8_t> lands;  // kLost or kLands
  double light = 0.0;               // kLightSet's
};

bool MappedPupilTable::round_lens(const Camera& camera) {
  if (camera.lens() == nullptr || camera.exact_model_only() || camera.squeeze() != 1.0) return false;
  // Round surfaces may still have clear apertures that are not (a rectangle, an ellipse, a decentred
  // circle, as a Zemax file can give them): those clip a beam differently at each azimuth.
  return std::all_of(camera.lens()->surfaces.begin(), camera.lens()->surfaces.end(), [](const Surface& s) {
    return !s.aperture || (s.aperture->shape == SurfaceAperture::Shape::Circular && s.aperture->decenter_x_mm == 0.0 &&
                           s.aperture->decenter_y_mm == 0.0);
  });
}

bool MappedPupilTable::applies(const RayModel& model, const Aperture& aperture) {
  return (model.kind() == RayModelKind::Exact || model.kind() == RayModelKind::Poly) && aperture.kind() == Aperture::Kind::Circular &&
         round_lens(model.camera());
}

MappedPupilTable::MappedPupilTable(const RayModel& model) : model_(model), nodes_(kCacheBits) {
  const Camera& camera = model.camera();
  // At most kFieldStepPx, and at most 1/kFieldNodes of the frame's half-diagonal: a small frame's
  // pixel spans more of the field, and the clear apertures' edges move across a beam with the field.
  const double half_diagonal_px = 0.5 * std::hypot(camera.frame().width_px(), camera.frame().height_px());
  field_step_ = std::min(kFieldStepPx, half_diagonal_px / kFieldNodes) / camera.frame().focal_length_px();
  // The blur diameter is, to first order, proportional to the inverse depth's distance from the focus
  // plane's: its slope there (px per 1/mm) sets the step.
  const double w_focus = std::isfinite(camera.focus_distance_mm()) ? 1.0 / camera.focus_distance_mm() : 0.0;
  const double dw = 1e-3 * std::max(w_focus, 1e-4);
  const double slope = std::abs(camera.signed_coc_px(w_focus + dw) - camera.signed_coc_px(w_focus)) / dw;
  if (!(slope > 0.0) || !std::isfinite(slope)) throw ComputationError("the lens's blur does not change with depth: no mapped-pupil table");
  depth_step_ = kBlurStepPx / slope;
}

MappedPupilTable::~MappedPupilTable() = default;

const MappedPupilTable::Node& MappedPupilTable::node(int set, double wavelength_nm, std::int64_t field_index, std::int64_t depth_index,
                                                     std::span<const PupilPoint> pupil, Cache& cache, const PupilMesh* fine) const {
  return nodes_.get(pack_key(set, field_index, depth_index), wavelength_nm, cache, [&] {
    Node made;
    std::vector<SensorHit> hits(pupil.size());
    const ScenePoint point = point_at(static_cast<double>(field_index), static_cast<double>(depth_index));
    model_.map(point, wavelength_nm, pupil, hits);
    if (fine != nullptr) {
      // The light that passes: each triangle's pupil share where its interpolated clearance is >= 0,
      // times its corners' mean weight (a lost corner loses the triangle).
      for (const PupilTriangle& t : fine->triangles) {
        const SensorHit& ha = hits[static_cast<std::size_t>(t.a)];
        const SensorHit& hb = hits[static_cast<std::size_t>(t.b)];
        const SensorHit& hc = hits[static_cast<std::size_t>(t.c)];
        if (!(ha.ok || ha.unclipped) || !(hb.ok || hb.unclipped) || !(hc.ok || hc.unclipped)) continue;
        made.light += t.weight * passing_share(ha.clearance, hb.clearance, hc.clearance) * (ha.weight + hb.weight + hc.weight) / 3.0;
      }
      hits.clear();
    }
    made.hits.resize(hits.size());
    made.lands.resize(hits.size());
    for (std::size_t i = 0; i < hits.size(); ++i) {
      const SensorHit& h = hits[i];
      const bool lands = h.ok || h.unclipped;
      made.lands[i] = lands ? kLands : kLost;
      made.hits[i] = {static_cast<float>(h.x_mm), static_cast<float>(h.y_mm), static_cast<float>(h.clearance), static_cast<float>(h.weight)};
    }
    return made;
  });
}

MappedPupilTable::Cell MappedPupilTable::cell(const ScenePoint& point) const {
  Cell cell;
  const double r = std::sqrt(point.tan_x * point.tan_x + point.tan_y * point.tan_y);
  // The azimuth's cosine and sine (the x axis on the axis itself, where every azimuth is alike).
  if (r > 0.0) {
    cell.cos_azimuth = point.tan_x / r;
    cell.sin_azimuth = point.tan_y / r;
  }
  double fi = r / field_step_, fj = point.inverse_depth_per_mm / depth_step_;
  // A point on a node (the light images' are, in field) lies on it exactly, so that the nodes beyond
  // it, of weight 0, are not mapped for it (map, passing_light).
  if (std::abs(fi - std::round(fi)) < kOnNode) fi = std::round(fi);
  if (std::abs(fj - std::round(fj)) < kOnNode) fj = std::round(fj);
  const double i0 = std::floor(fi), j0 = std::floor(fj);
  cell.a = fi - i0;
  cell.b = fj - j0;
  cell.i = static_cast<std::int64_t>(i0);
  cell.j = static_cast<std::int64_t>(j0);
  return cell;
}

MappedPupilTable::Place MappedPupilTable::place(const ScenePoint& point) const {
  const Cell q = cell(point);
  return {q.a < 0.5 ? q.i : q.i + 1, static_cast<double>(q.j) + q.b, q.cos_azimuth, q.sin_azimuth};
}

double MappedPupilTable::passing_light(const ScenePoint& point, double wavelength_nm, const PupilMesh& fine, Cache& cache) const {
  const Cell q = cell(point);
  const std::span<const PupilPoint> pupil(fine.points);
  const double l00 = node(kLightSet, wavelength_nm, q.i, q.j, pupil, cache, &fine).light;
  const double l10 = q.a != 0.0 ? node(kLightSet, wavelength_nm, q.i + 1, q.j, pupil, cache, &fine).light : 0.0;
  const double l01 = q.b != 0.0 ? node(kLightSet, wavelength_nm, q.i, q.j + 1, pupil, cache, &fine).light : 0.0;
  const double l11 = q.a != 0.0 && q.b != 0.0 ? node(kLightSet, wavelength_nm, q.i + 1, q.j + 1, pupil, cache, &fine).light : 0.0;
  return (1.0 - q.a) * (1.0 - q.b) * l00 + q.a * (1.0 - q.b) * l10 + (1.0 - q.a) * q.b * l01 + q.a * q.b * l11;
}

void MappedPupilTable::map(const ScenePoint& point, double wavelength_nm, int set, std::span<const PupilPoint> pupil,
                           std::span<SensorHit> hits, Cache& cache) const {
  const Cell q = cell(point);
  const double a = q.a, b = q.b, c = q.cos_azimuth, s = q.sin_azimuth;
  const std::int64_t i = q.i, j = q.j;
  // A node of weight 0 (a point on a node's field or depth) is not needed: its neighbour stands in.
  const Node& n00 = node(set, wavelength_nm, i, j, pupil, cache);
  const Node& n10 = a != 0.0 ? node(set, wavelength_nm, i + 1, j, pupil, cache) : n00;
  const Node& n01 = b != 0.0 ? node(set, wavelength_nm, i, j + 1, pupil, cache) : n00;
  const Node& n11 = a != 0.0 && b != 0.0 ? node(set, wavelength_nm, i + 1, j + 1, pupil, cache) : a != 0.0 ? n10 : n01;
  const auto w00 = static_cast<float>((1.0 - a) * (1.0 - b)), w10 = static_cast<float>(a * (1.0 - b));
  const auto w01 = static_cast<float>((1.0 - a) * b), w11 = static_cast<float>(a * b);
  for (std::size_t k = 0; k < hits.size(); ++k) {
    SensorHit& h = hits[k];
    if ((n00.lands[k] & n10.lands[k] & n01.lands[k] & n11.lands[k]) == kLost) {
      h = SensorHit{};  // lost at a node: lost (neither passing nor with a landing)
      h.weight = 0.0;
      continue;
    }
    const PackedHit& p00 = n00.hits[k];
    const PackedHit& p10 = n10.hits[k];
    const PackedHit& p01 = n01.hits[k];
    const PackedHit& p11 = n11.hits[k];
    const double x = w00 * p00.x_mm + w10 * p10.x_mm + w01 * p01.x_mm + w11 * p11.x_mm;
    const double y = w00 * p00.y_mm + w10 * p10.y_mm + w01 * p01.y_mm + w11 * p11.y_mm;
    h.x_mm = c * x - s * y;
    h.y_mm = s * x + c * y;
    h.clearance = w00 * p00.clearance + w10 * p10.clearance + w01 * p01.clearance + w11 * p11.clearance;
    h.weight = w00 * p00.weight + w10 * p10.weight + w01 * p01.weight + w11 * p11.weight;
    h.ok = h.clearance >= 0.0;
    h.unclipped = true;
  }
}

}  // namespace lensmith::render_detail

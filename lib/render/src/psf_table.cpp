// The lens's blur tabulated over the frame and depth (psf_table.h).
#include "psf_table.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <optional>

#include "illumination_table.h"
#include "image_area_table.h"
#include "pupil_mesh_table.h"
#include "lensmith/core/units.h"

namespace lensmith::render_detail {

namespace {

// The table: field points across the frame (edge to edge), pupil points per moment (32 rings
// of equal area x 16 spokes: the second moment of a disc exact), depth samples per 8 px of blur
// (the Cholesky factor is signed so that it is linear in inverse depth for pure defocus; at 2 px
// per sample the table took 2 s of a 1080p render at 128 px of blur through the Seidel model).
// The rings resolve where clear apertures clip the beam: pbrt's double Gauss at f/2 clips 6 % of
// even the axial beam, beyond radius 0.97; with 8 rings the centre of a wall came out 4 % bright,
// with 16 a blurred wall's 2.3 % dark against the scatter method's exact discs, with 32 within 1 %.
constexpr int kGridX = 33, kGridY = 19, kRings = 32, kSpokes = 16;
constexpr double kDepthStepPx = 8.0;
constexpr int kMaxDepthSamples = 32;

// Signed Cholesky factor of `v`, times `sign`.
PsfEntry factor(const Variance& v, double sign) {
  PsfEntry e;
  const double l11 = std::sqrt(std::max(v.xx, 0.0));
  const double l21 = l11 > 0.0 ? v.xy / l11 : 0.0;
  const double l22 = std::sqrt(std::max(v.yy - l21 * l21, 0.0));
  e.l11 = static_cast<float>(sign * l11);
  e.l21 = static_cast<float>(sign * l21);
  e.l22 = static_cast<float>(sign * l22);
  return e;
}

}  // namespace

PsfTable::PsfTable(const RayModel& model, const Aperture& aperture, double w_min, double w_max, int margin_px,
                   const PsfTableOptions& options, int threads)
    : camera_(model.camera()), options_(options), margin_(margin_px) {
  options_.lens_psf = options.lens_psf && !model.camera().is_thin_lens();
  const int margin = margin_px;
  // A thin lens's blur is the uniform disc of its CoC, centred, unvignetted; the thin model of a
  // real lens has that lens's brightness.
  if (!options_.lens_psf) {
    thin_illumination_ = IlluminationTable::where_applies(model, aperture, options_.vignetting, margin, w_min, w_max, threads, true);
    return;
  }
  const int w = camera_.frame().width_px(), h = camera_.frame().height_px();
  cell_x_ = static_cast<double>(w + 2 * margin) / (kGridX - 1);
  cell_y_ = static_cast<double>(h + 2 * margin) / (kGridY - 1);
  const double blur_range = std::abs(camera_.signed_coc_px(w_max) - camera_.signed_coc_px(w_min));
  depths_ = std::clamp(static_cast<int>(std::ceil(blur_range / kDepthStepPx)) + 1, 2, kMaxDepthSamples);
  w0_ = w_min;
  dw_ = w_max > w_min ? (w_max - w_min) / (depths_ - 1) : 1e-12;
  // Pupil points: the centres of equal-area cells of rings and spokes, stretched to the iris's
  // edge, each weighted by its share of the area (edge^2).
  std::vector<PupilPoint> pupil;
  std::vector<double> area, ring_width;
  for (int i = 0; i < kRings; ++i) {
    const double r = std::sqrt((i + 0.5) / kRings);
    for (int j = 0; j < kSpokes; ++j) {
      const double theta = 2.0 * kPi * (j + 0.5 * (i % 2) + 0.25) / kSpokes;
      const double edge = aperture.edge_radius(theta);
      pupil.push_back({r * edge * std::cos(theta), r * edge * std::sin(theta)});
      area.push_back(edge * edge);
      ring_width.push_back(edge * (std::sqrt((i + 1.0) / kRings) - std::sqrt(static_cast<double>(i) / kRings)));
    }
  }
  double total_area = 0.0;
  for (double a : area) total_area += a;
  const double wavelength = camera_.reference_wavelength_nm();
  // The real lens's brightness and clipped share for the models that only approximate them
  // (illumination_table.h): their throughput scaled to it, their discs widened where far too tight;
  // and the exact model's, whose light lands about its vignetted beams' centroids while the
  // throughput is spread over the chief rays' image area.
  const IlluminationTable illumination =
      IlluminationTable::where_applies(model, aperture, options_.vignetting, margin, w_min, w_max, threads, false, true);
  entries_.resize(static_cast<std::size_t>(kGridX) * kGridY * depths_);
#pragma omp parallel num_threads(threads)
  {
    std::vector<SensorHit> hits(pupil.size());
    std::vector<PupilDisc> discs;
    std::vector<double> inside(pupil.size());
#pragma omp for schedule(dynamic, 1) collapse(2)
    for (int d = 0; d < depths_; ++d) {
      for (int gy = 0; gy < kGridY; ++gy) {
        const double inverse = w0_ + d * dw_;
        const double sign = camera_.signed_coc_px(inverse) < 0.0 ? -1.0 : 1.0;
        for (int gx = 0; gx < kGridX; ++gx) {
          const PixelPoint at{gx * cell_x_ - margin_, gy * cell_y_ - margin_};
          const Tangents t = camera_.frame().tangents_at(at);
          const ScenePoint point{t.x, t.y, inverse};
          // First-order models clip by discs of the pupil: each point's share of its cell inside every
          // disc, across a disc's edge linear over the cell's width (map() stops the rays outside the
          // model's own discs; widened ones are applied here alone).
          model.clip_discs(point, discs);
          if (illumination.widen(point, discs)) {
            model.map_passing(point, wavelength, pupil, hits);
          } else {
            model.map(point, wavelength, pupil, hits);
          }
          std::fill(inside.begin(), inside.end(), 1.0);
          for (std::size_t k = 0; k < hits.size() && !discs.empty(); ++k) {
            for (const PupilDisc& disc : discs) {
              const double depth_in = disc.radius - std::hypot(pupil[k].x - disc.x, pupil[k].y - disc.y);
              inside[k] *= std::clamp(0.5 + depth_in / ring_width[k], 0.0, 1.0);
            }
          }
          double light = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0, syy = 0.0;
          for (std::size_t k = 0; k < hits.size(); ++k) {
            if (!hits[k].ok || !(inside[k] > 0.0)) continue;
            const double weight = area[k] * inside[k] * (options_.vignetting ? hits[k].weight : 1.0);
            const PixelPoint q = camera_.output_pixel(hits[k].x_mm, hits[k].y_mm);
            light += weight;
            sx += weight * q.x;
            sy += weight * q.y;
            sxx += weight * q.x * q.x;
            sxy += weight * q.x * q.y;
            syy += weight * q.y * q.y;
          }
          PsfEntry e;
          if (light > 0.0) {
            const double mx = sx / light, my = sy / light;
            const Variance v{options_.variance_scale * (sxx / light - mx * mx), options_.variance_scale * (sxy / light - mx * my),
                             options_.variance_scale * (syy / light - my * my)};
            e = factor(v, sign);
            e.dx = static_cast<float>(mx - at.x);
            e.dy = static_cast<float>(my - at.y);
          }
          // Without vignetting, the light of the rays that pass as the whole beam's.
          e.throughput = options_.vignetting ? static_cast<float>(light / total_area * illumination.factor(point)) : 1.0f;
          entries_[index(gx, gy, d)] = e;
        }
      }
    }
  }
  // The area a picture's pixel maps to: the determinant of the centroids' Jacobian (central
  // differences over the grid, one-sided at its edges), where the lens magnifies or compresses
  // the pinhole's picture (focus breathing, distortion). A point's light spreads over it.
  for (int d = 0; d < depths_; ++d) {
    for (int gy = 0; gy < kGridY; ++gy) {
      for (int gx = 0; gx < kGridX; ++gx) {
        const int xa = std::max(gx - 1, 0), xb = std::min(gx + 1, kGridX - 1);
        const int ya = std::max(gy - 1, 0), yb = std::min(gy + 1, kGridY - 1);
        const PsfEntry& l = entries_[index(xa, gy, d)];
        const PsfEntry& r = entries_[index(xb, gy, d)];
        const PsfEntry& u = entries_[index(gx, ya, d)];
        const PsfEntry& v = entries_[index(gx, yb, d)];
        const double hx = (xb - xa) * cell_x_, hy = (yb - ya) * cell_y_;
        const double jxx = 1.0 + (r.dx - l.dx) / hx, jyx = (r.dy - l.dy) / hx;
        const double jxy = (v.dx - u.dx) / hy, jyy = 1.0 + (v.dy - u.dy) / hy;
        entries_[index(gx, gy, d)].area = static_cast<float>(std::max(0.05, jxx * jyy - jxy * jyx));
      }
    }
  }
  // Where the lens compresses the picture (barrel distortion) each output pixel takes in more of the
  // scene, and its irradiance is higher by as much; where it stretches it, lower. So the throughput
  // (light per unit of output area) is divided by the image area of a pixel there (ImageAreaTable:
  // its chief rays' area relative to the frame centre's), as the scatter method weighs a footprint's
  // coverage (FootprintPlan::area). (The centroids' Jacobian above put the corners of a wall through
  // pbrt's 50 mm double Gauss 4.6 % bright against the ground truth, the chief rays' 3.9 %; without
  // either, lentil's 14 mm Canon retrofocus came out 0.14 of the centre at its frame's edge against
  // the truth's 0.27.) Natural vignetting off: a flat picture stays flat.
  if (options_.vignetting && ImageAreaTable::needed(model)) {
    const ImageAreaTable areas(model, margin_, w_min, w_max, threads);
    for (int d = 0; d < depths_; ++d) {
      for (int gy = 0; gy < kGridY; ++gy) {
        for (int gx = 0; gx < kGridX; ++gx) {
          entries_[index(gx, gy, d)].throughput /= areas.at(gx * cell_x_ - margin_, gy * cell_y_ - margin_, w0_ + d * dw_);
        }
      }
    }
  }
}

PsfEntry PsfTable::at(double x, double y, double w) const {
  if (!options_.lens_psf) {
    // A centred disc of radius R (the CoC's): variance R^2 / 4 times the scale.
    const double radius = 0.5 * camera_.signed_coc_px(w);
    PsfEntry e;
    e.l11 = e.l22 = static_cast<float>(radius * std::sqrt(options_.variance_scale / 4.0));
    if (!thin_illumination_.empty()) {
      const Tangents t = camera_.frame().tangents_at(PixelPoint{x, y});
      e.throughput = thin_illumination_.factor(ScenePoint{t.x, t.y, w});
    }
    return e;
  }
  const double fx = std::clamp((x + margin_) / cell_x_, 0.0, static_cast<double>(kGridX - 1));
  const double fy = std::clamp((y + margin_) / cell_y_, 0.0, static_cast<double>(kGridY - 1));
  const double fd = std::clamp((w - w0_) / dw_, 0.0, static_cast<double>(depths_ - 1));
  const int x0 = std::min(static_cast<int>(fx), kGridX - 2), y0 = std::min(static_cast<int>(fy), kGridY - 2);
  const int d0 = std::min(static_cast<int>(fd), depths_ - 2);
  const double tx = fx - x0, ty = fy - y0, td = fd - d0;
  std::array<double, 7> sum{};
  for (int c = 0; c < 8; ++c) {
    const int i = c & 1, j = (c >> 1) & 1, k = c >> 2;
    const double weight = (i ? tx : 1.0 - tx) * (j ? ty : 1.0 - ty) * (k ? td : 1.0 - td);
    const PsfEntry& e = entries_[index(x0 + i, y0 + j, d0 + k)];
    sum[0] += weight * e.dx;
    sum[1] += weight * e.dy;
    sum[2] += weight * e.l11;
    sum[3] += weight * e.l21;
    sum[4] += weight * e.l22;
    sum[5] += weight * e.throughput;
    sum[6] += weight * e.area;
  }
  PsfEntry e;
  e.dx = static_cast<float>(sum[0]);
  e.dy = static_cast<float>(sum[1]);
  e.l11 = static_cast<float>(sum[2]);
  e.l21 = static_cast<float>(sum[3]);
  e.l22 = static_cast<float>(sum[4]);
  e.throughput = static_cast<float>(sum[5]);
  e.area = static_cast<float>(sum[6]);
  return e;
}

std::size_t PsfTable::index(int gx, int gy, int d) const {
  return (static_cast<std::size_t>(d) * kGridY + static_cast<std::size_t>(gy)) * kGridX + static_cast<std::size_t>(gx);
}

}  // namespace lensmith::render_detail

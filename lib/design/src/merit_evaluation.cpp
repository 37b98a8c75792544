// The merit function evaluated on one lens: each operand measured with the library's one home for it
// (ParaxialSystem, SeidelAnalysis, AnalysisContext's traced rays, compute_wavefront, compute_distortion).
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "lensmith/analysis/distortion_curve.h"
#include "lensmith/analysis/pupil_sampling.h"
#include "lensmith/analysis/wavefront.h"
#include "lensmith/core/errors.h"
#include "lensmith/design/optimizer.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "lensmith/seidel/seidel_analysis.h"

namespace lensmith {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The field angle the Seidel sums S1 and C1 are computed with when neither the lens nor the merit function
// has a field: they do not depend on the chief ray, but SeidelAnalysis traces one.
constexpr double kUnusedFieldAngleDeg = 1.0;

// The lens the operands see: no clipping at clear semi-diameters or explicit clear apertures (the beams
// decide the semi-diameters, as OpticStudio's optimisation with automatic semi-diameters does; the
// RayHeight operand limits them), central obscurations kept.
Prescription unclipped(const Prescription& lens) {
  Prescription copy = lens;
  for (Surface& s : copy.surfaces) {
    s.clips_rays = false;
    if (s.aperture && !s.aperture->obscuration) s.aperture.reset();
  }
  return copy;
}

AnalysisOptions analysis_options(const Operand& o, const MeritFunction& merit) {
  AnalysisOptions options;
  options.relative_fields = o.relative_fields;
  options.wavelengths_nm = o.wavelengths_nm;
  options.max_field_angle_deg = merit.field_angle_deg;
  return options;
}

// How a scalar operand misses its goal (0 inside its limits).
double miss(const Operand& o, double value) {
  if (o.target) return value - *o.target;
  if (o.min && value < *o.min) return value - *o.min;
  if (o.max && value > *o.max) return value - *o.max;
  return 0.0;
}

double seidel_term(const SeidelSums& s, const std::string& term) {
  if (term == "S1") return s.S1;
  if (term == "S2") return s.S2;
  if (term == "S3") return s.S3;
  if (term == "S4") return s.S4;
  if (term == "S5") return s.S5;
  if (term == "C1") return s.C1;
  return s.C2;
}

// A traced ray that died is not a number the least squares can use: the evaluation fails, and the optimiser
// steps back (a trust region that shrinks) rather than step into lenses that lose rays.
void require(const TracedRay& ray, const std::string& what) {
  if (!ray.ok()) {
    throw ComputationError(what + ": a ray dies at surface " + std::to_string(ray.surface) + " (" + std::string(to_string(ray.status)) + ")");
  }
}

// The weight of each (field, wavelength) pair, normalised to sum 1: the product of the operand's field and
// wavelength weights (equal where not given).
std::vector<double> pair_shares(const Operand& o, std::size_t fields, std::size_t wavelengths) {
  std::vector<double> shares;
  double sum = 0.0;
  for (std::size_t f = 0; f < fields; ++f) {
    for (std::size_t w = 0; w < wavelengths; ++w) {
      const double fw = o.field_weights.empty() ? 1.0 : o.field_weights[f];
      const double ww = o.wavelength_weights.empty() ? 1.0 : o.wavelength_weights[w];
      shares.push_back(fw * ww);
      sum += fw * ww;
    }
  }
  for (double& s : shares) s /= sum;
  return shares;
}

// Per-ray residuals of the RMS spot: each landing point's offset from its field's reference, x and y, times
// sqrt(weight x its pair's share / the pair's rays), so that their squares sum to weight x the weighted mean
// square radius. The centroid reference is the field's centroid over its wavelengths, weighted alike.
double spot_rms(const Prescription& lens, const Operand& o, const MeritFunction& merit, std::vector<double>& residuals) {
  const AnalysisContext context(lens, analysis_options(o, merit));
  PupilSampling sampling;
  sampling.rings = o.rings;
  const std::vector<PupilCoordinate> pupil = sampling.samples();
  const std::size_t waves = context.wavelengths_nm().size();
  const std::vector<double> shares = pair_shares(o, o.relative_fields.size(), waves);
  std::vector<double> dx, dy, ray_share;
  for (std::size_t f = 0; f < o.relative_fields.size(); ++f) {
    const double relative = o.relative_fields[f];
    const FieldPoint field = context.field_at(relative);
    const std::size_t first = dx.size();
    double sx = 0.0, sy = 0.0, sw = 0.0;
    for (std::size_t w = 0; w < waves; ++w) {
      const double share = shares[f * waves + w];
      for (const PupilCoordinate& p : pupil) {
        const TracedRay ray = context.trace(field, p, context.wavelengths_nm()[w]);
        require(ray, "spot at field " + std::to_string(relative));
        dx.push_back(ray.image_ray.position_mm.x());
        dy.push_back(ray.image_ray.position_mm.y());
        ray_share.push_back(share / static_cast<double>(pupil.size()));
        sx += share * dx.back();
        sy += share * dy.back();
        sw += share;
      }
    }
    double cx = 0.0, cy = 0.0;
    if (o.centroid_reference) {
      if (sw > 0.0) {
        cx = sx / sw;
        cy = sy / sw;
      } else {  // a field of weight 0: its rays count for nothing, whatever they are measured from
        cx = dx[first];
        cy = dy[first];
      }
    } else {
      const Eigen::Vector3d chief = context.reference_ray(field, context.reference_wavelength_nm()).image_ray.position_mm;
      cx = chief.x();
      cy = chief.y();
    }
    for (std::size_t i = first; i < dx.size(); ++i) {
      dx[i] -= cx;
      dy[i] -= cy;
    }
  }
  double sum = 0.0;
  for (std::size_t i = 0; i < dx.size(); ++i) {
    const double scale = std::sqrt(o.weight * ray_share[i]);
    residuals.push_back(scale * dx[i]);
    residuals.push_back(scale * dy[i]);
    sum += ray_share[i] * (dx[i] * dx[i] + dy[i] * dy[i]);
  }
  return std::sqrt(sum);
}

// Per-point residuals of the RMS wavefront error: every map's OPD less its mean (piston), over the grid's
// points inside the unit pupil, times sqrt(weight x the map's share / its points).
double wavefront_rms(const Prescription& lens, const Operand& o, const MeritFunction& merit, std::vector<double>& residuals) {
  const AnalysisContext context(lens, analysis_options(o, merit));
  WavefrontOptions options;
  options.grid = o.grid;
  options.fan_samples = 3;
  options.zernike_terms = 1;
  const Wavefront wavefront = compute_wavefront(context, options);
  const std::vector<double> shares = pair_shares(o, o.relative_fields.size(), wavefront.wavelengths_nm.size());
  double sum = 0.0;
  for (std::size_t k = 0; k < wavefront.maps.size(); ++k) {
    const WavefrontMap& map = wavefront.maps[k];
    std::vector<double> opd;
    double total = 0.0;
    for (const OpdSample& s : map.map) {
      if (s.px * s.px + s.py * s.py > 1.0) continue;
      if (s.status != RayStatus::Ok || !std::isfinite(s.opd_waves)) {
        throw ComputationError("wavefront at field " + std::to_string(map.relative_field) + ": a ray dies (" + std::string(to_string(s.status)) + ")");
      }
      opd.push_back(s.opd_waves);
      total += s.opd_waves;
    }
    if (opd.empty()) throw ComputationError("wavefront: no pupil point on the grid");
    const double mean = total / static_cast<double>(opd.size());
    const double point_share = shares[k] / static_cast<double>(opd.size());
    const double scale = std::sqrt(o.weight * point_share);
    for (double w : opd) {
      residuals.push_back(scale * (w - mean));
      sum += point_share * (w - mean) * (w - mean);
    }
  }
  return std::sqrt(sum);
}

// The largest distance from the axis at `surface` of the chief ray and the four marginal rays of each field.
double ray_height(const Prescription& lens, const Operand& o, const MeritFunction& merit) {
  const AnalysisContext context(lens, analysis_options(o, merit));
  static const PupilCoordinate kRays[] = {{0.0, 0.0}, {0.0, 1.0}, {0.0, -1.0}, {1.0, 0.0}, {-1.0, 0.0}};
  double largest = 0.0;
  std::vector<SurfaceHit> path;
  for (double relative : o.relative_fields) {
    const FieldPoint field = context.field_at(relative);
    for (double wavelength : context.wavelengths_nm()) {
      for (const PupilCoordinate& p : kRays) {
        path.clear();
        const TracedRay ray = context.trace(field, p, wavelength, &path);
        require(ray, "ray height at field " + std::to_string(relative));
        for (const SurfaceHit& hit : path) {
          if (hit.surface == o.surface) largest = std::max(largest, std::hypot(hit.point_mm.x(), hit.point_mm.y()));
        }
      }
    }
  }
  return largest;
}

double edge_thickness(const Prescription& lens, const Operand& o) {
  const Surface& a = lens.surfaces.at(static_cast<std::size_t>(o.surface - 1));
  const Surface& b = lens.surfaces.at(static_cast<std::size_t>(o.surface));
  double h = 0.0;
  if (o.height_mm) {
    h = *o.height_mm;
  } else {
    h = std::min(a.semi_diameter_mm.value_or(std::numeric_limits<double>::infinity()),
                 b.semi_diameter_mm.value_or(std::numeric_limits<double>::infinity()));
  }
  const double t = a.thickness_mm + b.sag_mm(h) - a.sag_mm(h);
  if (!std::isfinite(t)) {
    throw ComputationError("edge thickness after surface " + std::to_string(o.surface) + ": a surface's sag is undefined at " + std::to_string(h) + " mm");
  }
  return t;
}

}  // namespace

bool MeritEvaluation::ok() const {
  return std::all_of(operands.begin(), operands.end(), [](const OperandValue& v) { return v.failure.empty(); });
}

MeritEvaluation evaluate_merit(const Prescription& start, const MeritFunction& merit) {
  const Prescription lens = unclipped(start);
  MeritEvaluation out;
  std::optional<ParaxialSystem> paraxial;
  std::optional<SeidelAnalysis> seidel;
  for (const Operand& o : merit.operands) {
    MeritEvaluation::OperandValue v;
    const std::size_t first = out.residuals.size();
    try {
      using K = Operand::Kind;
      const bool first_order = o.kind == K::Efl || o.kind == K::FNumber || o.kind == K::WorkingFNumber || o.kind == K::Bfl ||
                               o.kind == K::TotalTrack || o.kind == K::ImageDistance;
      if (first_order && !paraxial) paraxial.emplace(lens);
      double value = kNaN;
      switch (o.kind) {
        case K::Efl: value = paraxial->efl_mm(); break;
        case K::FNumber: value = paraxial->f_number(); break;
        case K::WorkingFNumber: value = paraxial->working_f_number(); break;
        case K::Bfl: value = paraxial->bfl_mm(); break;
        case K::TotalTrack: value = lens.last_vertex_z_mm() + paraxial->image_plane_distance_mm(); break;
        case K::ImageDistance: value = paraxial->image_plane_distance_mm() - paraxial->image_distance_mm(); break;
        case K::Seidel: {
          if (!seidel) {
            SeidelOptions options;
            if (merit.field_angle_deg) {
              options.field_angle_deg = merit.field_angle_deg;
            } else if (!lens.field) {
              options.field_angle_deg = kUnusedFieldAngleDeg;
            }
            seidel.emplace(lens, options);
          }
          value = seidel_term(seidel->sums(), o.term);
          break;
        }
        case K::SpotRms: value = spot_rms(lens, o, merit, out.residuals); break;
        case K::WavefrontRms: value = wavefront_rms(lens, o, merit, out.residuals); break;
        case K::Distortion: {
          const AnalysisContext context(lens, analysis_options(o, merit));
          DistortionOptions options;
          options.relative_fields = o.relative_fields;
          value = compute_distortion(context, options).points.front().distortion_percent;
          break;
        }
        case K::CentreThickness: value = lens.surfaces.at(static_cast<std::size_t>(o.surface - 1)).thickness_mm; break;
        case K::EdgeThickness: value = edge_thickness(lens, o); break;
        case K::RayHeight: value = ray_height(lens, o, merit); break;
      }
      if (!std::isfinite(value)) throw ComputationError("not a finite number");
      v.value = value;
      if (o.is_minimised()) {
        v.contribution = o.weight * value * value;
      } else {
        const double r = std::sqrt(o.weight) * miss(o, value);
        out.residuals.push_back(r);
        v.contribution = r * r;
      }
    } catch (const Error& e) {
      out.residuals.resize(first);
      v.value = kNaN;
      v.contribution = kNaN;
      v.failure = e.what();
    }
    out.merit += v.contribution;
    out.operands.push_back(std::move(v));
  }
  return out;
}

}  // namespace lensmith

#include "lensmith/validate/psf_comparison.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"

namespace lensmith {

namespace {

void finish_statistics(PointSpread& p) {
  const std::size_t n = p.x_mm.size();
  if (n == 0) return;
  double sx = 0.0, sy = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sx += p.x_mm[i];
    sy += p.y_mm[i];
  }
  p.centroid_x_mm = sx / static_cast<double>(n);
  p.centroid_y_mm = sy / static_cast<double>(n);
  double s2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) s2 += std::pow(p.x_mm[i] - p.centroid_x_mm, 2) + std::pow(p.y_mm[i] - p.centroid_y_mm, 2);
  p.rms_radius_mm = std::sqrt(s2 / static_cast<double>(n));
}

}  // namespace

std::string PointSpread::to_string() const {
  std::ostringstream os;
  os.precision(6);
  os << "PointSpread(" << x_mm.size() << " of " << traced << " rays, centroid (" << centroid_x_mm << ", "
     << centroid_y_mm << ") mm, RMS radius " << um_from_mm(rms_radius_mm) << " um)";
  return os.str();
}

PointSpread trace_point_spread(const RayModel& model, const ScenePoint& point, double wavelength_nm,
                               const Aperture& aperture, int samples_per_axis) {
  if (samples_per_axis < 2) throw OptionsError("a PSF needs at least 2 x 2 pupil samples");
  // Stratified: one point per grid cell, jittered inside it by a fixed hash of the cell, so the
  // PSF is deterministic and a binned PSF shows no moire between the pupil grid and the bins.
  auto jitter = [](std::uint32_t v) {
    v ^= v >> 16;
    v *= 0x7feb352dU;
    v ^= v >> 15;
    v *= 0x846ca68bU;
    v ^= v >> 16;
    return (v & 0xffffffU) / 16777216.0;
  };
  std::vector<PupilPoint> pupil;
  for (int j = 0; j < samples_per_axis; ++j) {
    for (int i = 0; i < samples_per_axis; ++i) {
      const auto cell = static_cast<std::uint32_t>(j * samples_per_axis + i);
      const PupilPoint p{-1.0 + (i + jitter(2 * cell)) * 2.0 / samples_per_axis,
                         -1.0 + (j + jitter(2 * cell + 1)) * 2.0 / samples_per_axis};
      if (aperture.transmission(p) > 0.0) pupil.push_back(p);
    }
  }
  std::vector<SensorHit> hits(pupil.size());
  model.map(point, wavelength_nm, pupil, hits);
  PointSpread out;
  out.traced = pupil.size();
  for (const SensorHit& h : hits) {
    if (!h.ok) continue;
    out.x_mm.push_back(h.x_mm);
    out.y_mm.push_back(h.y_mm);
  }
  finish_statistics(out);
  return out;
}

double comparison_half_width_mm(const PointSpread& reference, const PointSpread& model, double min_half_width_mm) {
  // Wide enough for both spots: the farthest ray of either from the reference centroid, plus a margin.
  double reach = 0.0;
  for (const PointSpread* p : {&reference, &model}) {
    for (std::size_t i = 0; i < p->x_mm.size(); ++i) {
      reach = std::max(reach, std::max(std::abs(p->x_mm[i] - reference.centroid_x_mm), std::abs(p->y_mm[i] - reference.centroid_y_mm)));
    }
  }
  return std::max({1.05 * reach, min_half_width_mm, 1e-4});  // never below 0.1 um
}

Image bin_point_spread(const PointSpread& psf, double centre_x_mm, double centre_y_mm, double half_width_mm, int bins) {
  Image out(bins, bins, 1, 0.0f);
  if (psf.x_mm.empty()) return out;
  const double scale = bins / (2.0 * half_width_mm);
  const float w = 1.0f / static_cast<float>(psf.x_mm.size());
  for (std::size_t i = 0; i < psf.x_mm.size(); ++i) {
    const int bx = static_cast<int>(std::floor((psf.x_mm[i] - centre_x_mm + half_width_mm) * scale));
    // Rows run down the picture, sensor y up: row 0 is the top (largest y).
    const int by = static_cast<int>(std::floor((centre_y_mm + half_width_mm - psf.y_mm[i]) * scale));
    if (bx < 0 || by < 0 || bx >= bins || by >= bins) continue;
    out.at(bx, by, 0) += w;
  }
  return out;
}

PsfComparison compare_point_spreads(const PointSpread& reference, const PointSpread& model, int bins,
                                    double min_half_width_mm) {
  if (reference.x_mm.empty() || model.x_mm.empty()) {
    throw ComputationError("cannot compare point spreads: " + std::string(reference.x_mm.empty() ? "the reference" : "the model") +
                           " has no ray reaching the sensor");
  }
  if (bins < 2) throw OptionsError("PSF comparison needs at least 2 x 2 bins");
  PsfComparison c;
  c.centroid_offset_um =
      um_from_mm(std::hypot(model.centroid_x_mm - reference.centroid_x_mm, model.centroid_y_mm - reference.centroid_y_mm));
  c.rms_radius_ratio = reference.rms_radius_mm > 0.0 ? model.rms_radius_mm / reference.rms_radius_mm
                                                     : std::numeric_limits<double>::quiet_NaN();
  const double half = comparison_half_width_mm(reference, model, min_half_width_mm);
  const Image a = bin_point_spread(reference, reference.centroid_x_mm, reference.centroid_y_mm, half, bins);
  const Image b = bin_point_spread(model, reference.centroid_x_mm, reference.centroid_y_mm, half, bins);
  double l1 = 0.0;
  for (std::size_t i = 0; i < a.data.size(); ++i) l1 += std::abs(static_cast<double>(a.data[i]) - b.data[i]);
  c.overlap = 1.0 - 0.5 * l1;
  return c;
}

std::string PsfComparison::to_string() const {
  std::ostringstream os;
  os.precision(4);
  os << "PsfComparison(centroid offset " << centroid_offset_um << " um, RMS radius ratio " << rms_radius_ratio
     << ", overlap " << overlap << ")";
  return os.str();
}

}  // namespace lensmith

// Footprints that are the aperture's outline scaled about their pixel's centre, deposited from
// stamps recorded once per render and scale step (SplatBuffer::record / add_stamp) instead of
// being scan-converted one by one. That is every footprint of the thin lens: a point's blur is the
// aperture's shape scaled by its circle of confusion (the aperture's plane and the sensor are
// parallel) and centred on its chief ray, which passes the lens's centre undeviated and lands on
// the point's own pixel centre. Kosloff, Tao & Barsky (Graphics Interface 2009) spread each
// footprint as precomputed first differences in the same way; their footprints are rectangles,
// these the deposit add_polygon makes of the aperture's outline, at more sub-rows than the polygon
// path can afford per footprint (docs/bokeh.md, "How a pixel becomes bokeh").
#pragma once

#include <memory>
#include <mutex>
#include <vector>

#include "lensmith/render/splat_buffer.h"
#include "pupil_mesh_table.h"

namespace lensmith::render_detail {

class FootprintStamps {
 public:
  // Scale steps per px: a footprint is drawn from the stamp of its scale rounded to the nearest
  // step, so its outline is at most 1 / (2 kStepsPerPx) px from where its own scale puts it (its
  // light is its own: a stamp deposits exactly the value it is given).
  static constexpr int kStepsPerPx = 64;
  // Sub-rows per pixel a stamp is recorded at: a near-horizontal edge placed to 1/16 px, where the
  // polygon path's 4 (2 for footprints over 20 px) place it to 1/8 (1/4).
  static constexpr int kSubrows = 8;

  // Stamps for outlines scaled by up to max_scale_px px (per unit of pupil coordinate) along x and y.
  FootprintStamps(const PupilMeshTable& meshes, double max_scale_px);

  // The stamp of the outline scaled by (scale_x_px, scale_y_px) about the anchor pixel's centre
  // (signed: the image of the pupil's (1, 0) lies scale_x_px to the right of the centre, of (0, 1)
  // scale_y_px below it), recorded on first use (thread-safe); nullptr where the two scales differ
  // in size by more than 1e-6 px or exceed max_scale_px.
  const DifferenceStamp* find(double scale_x_px, double scale_y_px) const;

 private:
  const PupilMeshTable& meshes_;
  int steps_ = 0;  // scale steps per sign combination, 0 .. max_scale_px * kStepsPerPx
  // Per slot (scale step and signs): recorded once, on first use.
  mutable std::unique_ptr<std::once_flag[]> built_;
  mutable std::unique_ptr<std::unique_ptr<DifferenceStamp>[]> stamps_;
};

}  // namespace lensmith::render_detail

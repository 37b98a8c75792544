// The lens layout picture: the meridional section of lensmith/analysis/lens_layout.h drawn at equal
// scales on both axes, glass elements filled, the stop as two bars, the image plane, a ray bundle
// per field in its own colour, and a scale bar in mm.
#pragma once

#include "lensmith/analysis/lens_layout.h"
#include "lensmith/plot/analysis_plots.h"
#include "lensmith/plot/canvas.h"

namespace lensmith::plot {

// Where the section's lengths land in the picture: the mapping the drawing used, for tests.
struct LayoutFrame {
  double left_px = 0.0;      // x of z_min_mm
  double axis_y_px = 0.0;    // y of the optical axis
  double px_per_mm = 1.0;    // the same along both axes
  double z_min_mm = 0.0;
  Point2 to_pixel(double z_mm, double y_mm) const { return {left_px + (z_mm - z_min_mm) * px_per_mm, axis_y_px - y_mm * px_per_mm}; }
};

// Colours of the ray bundles, one per field in order (distinct for up to 8 fields, then repeating).
Rgb field_colour(std::size_t field_index);

// Draws `layout`; `frame`, when given, receives the mapping from mm to pixels.
Canvas plot_lens_layout(const LensLayout& layout, const PlotOptions& options = {}, LayoutFrame* frame = nullptr);

}  // namespace lensmith::plot

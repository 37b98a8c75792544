// One plot panel on a Canvas: a data rectangle mapped to a pixel rectangle, a frame with light grid
// lines, ticks at "nice" 1-2-5 steps with labels, axis titles with units, and curves clipped to the
// panel (Liang-Barsky) and broken where a value is NaN (a ray that died is a gap, not a zero).
#pragma once

#include <span>
#include <string>
#include <vector>

#include "lensmith/plot/canvas.h"

namespace lensmith::plot {

struct AxisRange {
  double min = 0.0;
  double max = 1.0;
};

// Tick values at 1, 2 or 5 times a power of ten covering [lo, hi] with about `target` ticks.
std::vector<double> nice_ticks(double lo, double hi, int target = 5);
// [lo, hi] widened to the enclosing ticks; a degenerate range becomes a small one around it.
AxisRange nice_range(double lo, double hi, int target = 5);
// A tick label with as many decimals as the tick step needs ("0.25", "-10", "0").
std::string tick_label(double value, double step);

struct AxesText {
  std::string title;    // above the panel
  std::string x_label;  // below, with the unit: "py (normalised)"
  std::string y_label;  // left, vertical: "ey (µm)"
  double font_px = 14.0;
  bool x_grid = true;        // vertical grid lines at the x ticks
  bool x_tick_marks = true;  // tick marks (and labels) along x; false: the caller draws its own
};

class PlotAxes {
 public:
  // `area` is the pixel rectangle of the data region (ticks and labels are drawn outside it).
  PlotAxes(Canvas& canvas, Point2 top_left, Point2 bottom_right, AxisRange x, AxisRange y);

  Point2 to_pixel(double x, double y) const;
  const AxisRange& x_range() const { return x_; }
  const AxisRange& y_range() const { return y_; }
  Point2 top_left() const { return top_left_; }
  Point2 bottom_right() const { return bottom_right_; }

  // Grid, frame, ticks and their labels (`tick_labels_x/y` false: marks only), titles.
  void draw_frame(const AxesText& text, bool tick_labels_x = true, bool tick_labels_y = true, int x_ticks = 5, int y_ticks = 5);
  // A line through the data origin along x (y = 0) and/or y (x = 0), when inside the range.
  void draw_zero_lines(bool horizontal, bool vertical);
  // Points (xs[i], ys[i]) joined, clipped to the panel; NaN breaks the curve.
  void curve(std::span<const double> xs, std::span<const double> ys, const LineStyle& style);
  void dot(double x, double y, double radius_px, Rgb colour);  // skipped outside the panel

 private:
  Canvas& canvas_;
  Point2 top_left_, bottom_right_;
  AxisRange x_, y_;
};

}  // namespace lensmith::plot

// Parts every lensmith picture shares (private to lib/plot): the header with the analysis and lens
// names, legends, number formats and the text colours.
#pragma once

#include <string>
#include <vector>

#include "lensmith/plot/analysis_plots.h"
#include "lensmith/plot/canvas.h"

namespace lensmith::plot::detail {

inline constexpr Rgb kText{0.1f, 0.1f, 0.1f};
inline constexpr Rgb kNote{0.35f, 0.35f, 0.35f};
inline constexpr Rgb kWarning{0.75f, 0.15f, 0.1f};

// `value` with `decimals` digits after the point.
std::string fixed(double value, int decimals);
// A length given in mm, written in micrometres with three significant digits ("12.3 µm").
std::string micrometres(double mm);
Rgb mix(Rgb a, Rgb b, float t);
// A white canvas with the options' font; validates the options.
Canvas make_canvas(int width, int height, const PlotOptions& options);
// Height reserved for the header: the title, the lens name and up to two lines of details.
double header_height(const PlotOptions& o);
// The analysis name, the lens name below it, then the details in grey (wrapped to two lines).
void header(Canvas& canvas, const std::string& title, const std::string& lens, const std::string& details, const PlotOptions& o);

struct LegendEntry {
  std::string label;
  LineStyle style;
  bool dot = false;
};
// Legend entries in a row: a short line sample and its label, starting at `at`.
void legend_row(Canvas& canvas, Point2 at, const std::vector<LegendEntry>& entries, const PlotOptions& o);
std::string wavelength_label(double nm);

}  // namespace lensmith::plot::detail

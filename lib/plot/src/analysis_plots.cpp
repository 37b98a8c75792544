// Analysis pictures: layouts of PlotAxes panels with legends and the key numbers of each analysis.
#include "lensmith/plot/analysis_plots.h"
#include "lensmith/plot/layout_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "lensmith/plot/plot_axes.h"
#include "figure_parts.h"

namespace lensmith::plot {

namespace detail {


std::string fixed(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

// A length in micrometres with three significant digits.
std::string micrometres(double mm) {
  if (!std::isfinite(mm)) return "-";
  const double um = um_from_mm(mm);
  const int decimals = um >= 100.0 ? 0 : um >= 10.0 ? 1 : um >= 1.0 ? 2 : 3;
  return fixed(um, decimals) + " \xC2\xB5m";
}

Rgb mix(Rgb a, Rgb b, float t) { return {a.r + (b.r - a.r) * t, a.g + (b.g - a.g) * t, a.b + (b.b - a.b) * t}; }

Canvas make_canvas(int width, int height, const PlotOptions& options) {
  options.validate();
  Canvas canvas(width, height);
  canvas.set_font(options.font_path);
  return canvas;
}

// Height reserved for the header: the title, the lens name and up to two lines of details.
double header_height(const PlotOptions& o) { return 34.0 + 4.4 * o.font_px; }

// Splits `text` into at most `max_lines` lines no wider than `width` px, breaking between words.
std::vector<std::string> wrap(const Canvas& canvas, const std::string& text, double size, double width, std::size_t max_lines) {
  std::vector<std::string> lines;
  std::string line;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find(' ', start);
    if (end == std::string::npos) end = text.size();
    const std::string word = text.substr(start, end - start);
    const std::string candidate = line.empty() ? word : line + " " + word;
    if (!line.empty() && canvas.text_width(candidate, size) > width) {
      lines.push_back(line);
      line = word;
    } else {
      line = candidate;
    }
    start = end + 1;
  }
  if (!line.empty()) lines.push_back(line);
  if (lines.size() > max_lines) {
    lines.resize(max_lines);
    lines.back() += " ...";
  }
  return lines;
}

// The analysis name, the lens name below it, then the details in grey (wrapped to two lines).
void header(Canvas& canvas, const std::string& title, const std::string& lens, const std::string& details, const PlotOptions& o) {
  double y = 14.0;
  canvas.text({20.0, y}, title, o.font_px * 1.3, kText, HAlign::Left, VAlign::Top);
  y += 1.55 * o.font_px;
  canvas.text({20.0, y}, lens, o.font_px * 1.0, kText, HAlign::Left, VAlign::Top);
  y += 1.35 * o.font_px;
  for (const std::string& line : wrap(canvas, details, o.font_px * 0.9, canvas.width() - 40.0, 2)) {
    canvas.text({20.0, y}, line, o.font_px * 0.9, kNote, HAlign::Left, VAlign::Top);
    y += 1.15 * o.font_px;
  }
}

void legend_row(Canvas& canvas, Point2 at, const std::vector<LegendEntry>& entries, const PlotOptions& o) {
  double x = at.x;
  for (const auto& e : entries) {
    if (e.dot) {
      canvas.fill_disc({x + 12.0, at.y}, 4.0, e.style.colour);
    } else {
      LineStyle s = e.style;
      s.width_px = std::max(s.width_px, 2.0);
      canvas.line({x, at.y}, {x + 26.0, at.y}, s);
    }
    canvas.text({x + 32.0, at.y}, e.label, o.font_px * 0.9, kText, HAlign::Left, VAlign::Middle);
    x += 32.0 + canvas.text_width(e.label, o.font_px * 0.9) + 26.0;
  }
}

std::string wavelength_label(double nm) { return fixed(nm, 1) + " nm"; }

// Smallest nice half-width covering `extent` (a positive length).
double nice_half_width(double extent) {
  const AxisRange r = nice_range(0.0, extent, 4);
  return r.max > 0.0 ? r.max : extent;
}

}  // namespace detail

using namespace detail;

void PlotOptions::validate() const {
  if (!(font_px >= 8.0 && font_px <= 48.0)) throw OptionsError("PlotOptions::font_px = " + fixed(font_px, 2) + ": must be 8 to 48");
}

std::vector<Rgb> wavelength_colours(const std::vector<double>& wavelengths_nm) {
  const Rgb blue{0.08f, 0.25f, 0.88f}, green{0.0f, 0.58f, 0.12f}, red{0.85f, 0.08f, 0.08f};
  std::vector<std::size_t> order(wavelengths_nm.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return wavelengths_nm[a] < wavelengths_nm[b]; });
  std::vector<Rgb> colours(wavelengths_nm.size(), blue);
  if (wavelengths_nm.size() <= 1) return colours;
  for (std::size_t rank = 0; rank < order.size(); ++rank) {
    const float t = static_cast<float>(rank) / static_cast<float>(order.size() - 1);
    colours[order[rank]] = t <= 0.5f ? mix(blue, green, 2.0f * t) : mix(green, red, 2.0f * t - 1.0f);
  }
  return colours;
}

Canvas plot_spot_diagram(const SpotDiagram& spots, const PlotOptions& o) {
  o.validate();
  const std::size_t waves = spots.wavelengths_nm.size();
  const int columns = static_cast<int>(waves > 1 ? waves + 1 : waves);
  const int rows = static_cast<int>(spots.fields.size());
  const std::vector<Rgb> colours = wavelength_colours(spots.wavelengths_nm);
  const bool has_airy = std::isfinite(spots.working_f_number) && spots.working_f_number > 0.0;
  const double airy_primary_mm = has_airy ? spots.airy_radius_mm(spots.reference_wavelength_nm) : 0.0;

  // One scale for every panel: the largest distance of a ray from the chief ray, or the largest Airy
  // circle when the spots are smaller than it.
  double extent = 0.0;
  for (const auto& f : spots.fields) {
    for (const auto& s : f.spots) {
      if (std::isfinite(s.stats.geo_radius_chief_mm)) extent = std::max(extent, s.stats.geo_radius_chief_mm);
    }
  }
  if (has_airy) {
    for (double nm : spots.wavelengths_nm) extent = std::max(extent, spots.airy_radius_mm(nm));
  }
  const double half_um = nice_half_width(std::max(um_from_mm(extent) * 1.02, 0.1));  // at least 0.1 um
  const std::vector<double> ticks = nice_ticks(-half_um, half_um, 4);
  const double step_um = ticks.size() > 1 ? ticks[1] - ticks[0] : half_um;

  // Measure the labels before laying out: neighbouring panels sit far enough apart that their tick
  // labels never meet, and the row labels clear the widest y tick label.
  Canvas ruler(1, 1);
  ruler.set_font(o.font_path);
  double widest_tick = 0.0;
  for (double t : ticks) widest_tick = std::max(widest_tick, ruler.text_width(tick_label(t, step_um), o.font_px * 0.85));
  const double panel = 230.0;
  const double gap_x = std::max(30.0, widest_tick + 16.0);
  const double note = 0.85 * o.font_px;                 // size of the numbers under each panel
  const double note_lines = 3.0;                        // RMS / GEO, rays lost, why
  const double note_height = note_lines * 1.3 * note + 6.0;
  const double gap_y = 14.0 + note_height;
  const double row_label = 1.3 * o.font_px;             // two vertical lines: the field, the image height
  const double left = 24.0 + 2.0 * row_label + 28.0 + widest_tick + 1.6 * o.font_px;
  const double top = header_height(o) + 1.5 * o.font_px + 1.6 * o.font_px + 12.0;
  const double last_row_axis = 16.0 + 2.2 * o.font_px;  // x tick labels and the axis title under the last row
  const int width = std::max(760, static_cast<int>(left + columns * panel + (columns - 1) * gap_x + 40.0 + 0.5 * widest_tick));
  const int height = static_cast<int>(top + rows * panel + (rows - 1) * gap_y + last_row_axis + note_height + 50.0);
  Canvas canvas = make_canvas(width, height, o);

  header(canvas, "Spot diagram", spots.lens_name,
         spots.sampling.to_string() + "; reference: chief ray at " + wavelength_label(spots.reference_wavelength_nm) +
             "; image plane z = " + fixed(spots.image_plane_z_mm, 3) + " mm; RMS and GEO radii about the chief ray",
         o);
  if (has_airy) {
    canvas.circle({26.0, header_height(o) + 0.75 * o.font_px}, 6.0, LineStyle{kBlack, 1.2});
    canvas.text({38.0, header_height(o) + 0.75 * o.font_px},
                "Airy circle 1.22 \xCE\xBB N_w about the chief ray at each panel's wavelength: N_w = " + fixed(spots.working_f_number, 2) + ", radius " +
                    micrometres(airy_primary_mm) + " at " + wavelength_label(spots.reference_wavelength_nm) + " (all-wavelength panel)",
                o.font_px * 0.9, kText, HAlign::Left, VAlign::Middle);
  }

  for (int r = 0; r < rows; ++r) {
    const FieldSpot& f = spots.fields[static_cast<std::size_t>(r)];
    const double y0 = top + r * (panel + gap_y);
    canvas.text({24.0 + 0.5 * row_label, y0 + 0.5 * panel}, "Field " + f.field_label, o.font_px * 1.05, kText, HAlign::Centre, VAlign::Middle,
                true);
    canvas.text({24.0 + 1.5 * row_label, y0 + 0.5 * panel}, "image height " + fixed(f.chief.y_mm, 3) + " mm", o.font_px * 0.9, kNote,
                HAlign::Centre, VAlign::Middle, true);
    for (int c = 0; c < columns; ++c) {
      const double x0 = left + c * (panel + gap_x);
      PlotAxes axes(canvas, {x0, y0}, {x0 + panel, y0 + panel}, {-half_um, half_um}, {-half_um, half_um});
      const bool overlay = c == static_cast<int>(waves);
      AxesText text;
      text.font_px = o.font_px;
      if (r == 0) text.title = overlay ? "all wavelengths" : wavelength_label(spots.wavelengths_nm[static_cast<std::size_t>(c)]);
      if (r == rows - 1) text.x_label = "x - x chief (\xC2\xB5m)";
      if (c == 0) text.y_label = "y - y chief (\xC2\xB5m)";
      axes.draw_frame(text, r == rows - 1, c == 0, 4, 4);
      axes.draw_zero_lines(true, true);
      const double dot = 1.4;
      auto draw_spot = [&](const Spot& s, Rgb colour) {
        for (const ImagePoint& p : s.points) axes.dot(um_from_mm(p.x_mm - f.chief.x_mm), um_from_mm(p.y_mm - f.chief.y_mm), dot, colour);
      };
      const SpotStatistics* stats = nullptr;
      double airy_mm = airy_primary_mm;
      if (overlay) {
        // Longest wavelength first so the short ones stay visible on top.
        for (std::size_t w = f.spots.size(); w-- > 0;) draw_spot(f.spots[w], colours[w]);
        stats = &f.polychromatic;
      } else {
        draw_spot(f.spots[static_cast<std::size_t>(c)], colours[static_cast<std::size_t>(c)]);
        stats = &f.spots[static_cast<std::size_t>(c)].stats;
        if (has_airy) airy_mm = spots.airy_radius_mm(spots.wavelengths_nm[static_cast<std::size_t>(c)]);
      }
      if (has_airy) canvas.circle(axes.to_pixel(0.0, 0.0), um_from_mm(airy_mm) / (2.0 * half_um) * panel, LineStyle{kBlack, 1.1});
      if (stats->passed == 0) {
        canvas.text({x0 + 0.5 * panel, y0 + 0.5 * panel - 14.0}, "no ray reaches the image", o.font_px * 0.85, kWarning, HAlign::Centre,
                    VAlign::Middle);
      }
      double ty = y0 + panel + (r == rows - 1 ? last_row_axis : 8.0);
      canvas.text({x0 + 0.5 * panel, ty}, "RMS " + micrometres(stats->rms_radius_chief_mm) + "   GEO " + micrometres(stats->geo_radius_chief_mm),
                  note, kText, HAlign::Centre, VAlign::Top);
      if (stats->lost.total() > 0) {
        // Two short lines that fit under the panel, never into the next one.
        ty += 1.3 * note;
        canvas.text({x0 + 0.5 * panel, ty}, std::to_string(stats->lost.total()) + " of " + std::to_string(stats->traced) + " rays lost",
                    note * 0.95, kWarning, HAlign::Centre, VAlign::Top);
        ty += 1.3 * note;
        canvas.text({x0 + 0.5 * panel, ty}, stats->lost.total() == stats->lost.vignetted ? "(vignetted)" : "(vignetted, missed or TIR)",
                    note * 0.95, kWarning, HAlign::Centre, VAlign::Top);
      }
    }
  }
  // Scale bar: one tick step of the panels.
  const double bar_px = step_um / (2.0 * half_um) * panel;
  const double by = height - 26.0;
  canvas.line({left, by}, {left + bar_px, by}, LineStyle{kText, 2.5});
  canvas.line({left, by - 5.0}, {left, by + 5.0}, LineStyle{kText, 1.5});
  canvas.line({left + bar_px, by - 5.0}, {left + bar_px, by + 5.0}, LineStyle{kText, 1.5});
  canvas.text({left + bar_px + 10.0, by}, tick_label(step_um, step_um) + " \xC2\xB5m", o.font_px * 0.9, kText, HAlign::Left, VAlign::Middle);
  return canvas;
}

Canvas plot_ray_fan(const RayFan& fan, const PlotOptions& o) {
  const int rows = static_cast<int>(fan.fields.size());
  const double pw = 380.0, ph = 220.0, gap_x = 110.0, gap_y = 52.0 + 1.4 * o.font_px;
  const double left = 110.0, top = header_height(o) + 2.0 * o.font_px + 30.0, bottom = 50.0 + 2.0 * o.font_px;
  const int width = static_cast<int>(left + 2 * pw + gap_x + 40.0);
  const int height = static_cast<int>(top + rows * ph + (rows - 1) * gap_y + bottom);
  Canvas canvas = make_canvas(width, height, o);
  const std::vector<Rgb> colours = wavelength_colours(fan.wavelengths_nm);
  const double half_um = nice_half_width(std::max(um_from_mm(fan.max_abs_error_mm()) * 1.02, 0.1));
  header(canvas, "Ray fan", fan.lens_name,
         "transverse ray error on the image plane (z = " + fixed(fan.image_plane_z_mm, 3) + " mm) against the chief ray at " +
             wavelength_label(fan.reference_wavelength_nm) + "; scale \xC2\xB1" + tick_label(half_um, half_um / 4) + " \xC2\xB5m",
         o);
  std::vector<LegendEntry> legend;
  for (std::size_t w = 0; w < fan.wavelengths_nm.size(); ++w) legend.push_back({wavelength_label(fan.wavelengths_nm[w]), LineStyle{colours[w], 2.0}});
  legend_row(canvas, {20.0, header_height(o) + 0.4 * o.font_px}, legend, o);

  for (int r = 0; r < rows; ++r) {
    const FieldFan& f = fan.fields[static_cast<std::size_t>(r)];
    const double y0 = top + r * (ph + gap_y);
    for (int c = 0; c < 2; ++c) {
      const bool tangential = c == 0;
      const double x0 = left + c * (pw + gap_x);
      PlotAxes axes(canvas, {x0, y0}, {x0 + pw, y0 + ph}, {-1.0, 1.0}, {-half_um, half_um});
      AxesText text;
      text.font_px = o.font_px;
      text.title = std::string(tangential ? "Tangential" : "Sagittal") + ", field " + f.field_label;
      text.y_label = tangential ? "ey (\xC2\xB5m)" : "ex (\xC2\xB5m)";
      if (r == rows - 1) text.x_label = tangential ? "py (normalised pupil)" : "px (normalised pupil)";
      axes.draw_frame(text, true, true, 4, 4);
      axes.draw_zero_lines(true, true);
      bool any_ray = false;
      for (std::size_t w = 0; w < f.curves.size(); ++w) {
        const auto& samples = tangential ? f.curves[w].tangential : f.curves[w].sagittal;
        std::vector<double> xs, ys;
        for (const FanSample& s : samples) {
          xs.push_back(s.pupil);
          ys.push_back(s.ok() ? um_from_mm(s.error_mm) : std::nan(""));
          any_ray = any_ray || s.ok();
        }
        axes.curve(xs, ys, LineStyle{colours[w], 2.0});
      }
      if (!any_ray) {
        canvas.text({x0 + 0.5 * pw, y0 + 0.5 * ph - 12.0}, "no ray of this fan reaches the image", o.font_px * 0.9, kWarning, HAlign::Centre,
                    VAlign::Middle);
      }
    }
  }
  canvas.text({20.0, height - 22.0}, "A gap in a curve: rays that did not reach the image plane (vignetted, missed or TIR).",
              o.font_px * 0.85, kNote, HAlign::Left, VAlign::Middle);
  return canvas;
}

namespace {

// Size of the one-panel pictures (field or wavelength up the vertical axis, as OpticStudio draws them).
constexpr double kPanelLeft = 120.0;
constexpr double kPanelWidth = 560.0;
constexpr double kPanelHeight = 440.0;

double panel_top(const PlotOptions& o, bool legend) { return header_height(o) + (legend ? 2.0 * o.font_px : 0.0) + 34.0; }

Canvas one_panel_canvas(const PlotOptions& o, bool legend) {
  return make_canvas(static_cast<int>(kPanelLeft + kPanelWidth + 60.0), static_cast<int>(panel_top(o, legend) + kPanelHeight + 60.0 + 2.5 * o.font_px), o);
}

std::string field_axis_label(const std::string& unit) { return "field (" + std::string(unit == "deg" ? "\xC2\xB0" : "mm") + ")"; }

}  // namespace

Canvas plot_distortion(const DistortionCurve& d, const PlotOptions& o) {
  Canvas canvas = one_panel_canvas(o, false);
  const double top = panel_top(o, false);
  double lo = 0.0, hi = 0.0, fmax = 0.0;
  for (const auto& p : d.points) {
    lo = std::min(lo, p.distortion_percent);
    hi = std::max(hi, p.distortion_percent);
    fmax = std::max(fmax, p.field_value);
  }
  // Symmetric about 0 so barrel and pincushion read the same way; at least +/-0.01 %.
  const double span = std::max({std::abs(lo), std::abs(hi), 0.01});
  PlotAxes axes(canvas, {kPanelLeft, top}, {kPanelLeft + kPanelWidth, top + kPanelHeight}, nice_range(-span, span, 6),
                {0.0, fmax > 0.0 ? fmax : 1.0});
  header(canvas, "Distortion", d.lens_name,
         "real chief ray at " + wavelength_label(d.wavelength_nm) + " on the image plane against the paraxial height " + d.paraxial_reference +
             "; full field " + fixed(d.points.back().distortion_percent, 3) + " %",
         o);
  AxesText text;
  text.font_px = o.font_px;
  text.x_label = "distortion (%)";
  text.y_label = field_axis_label(d.field_unit);
  axes.draw_frame(text, true, true, 6, 6);
  axes.draw_zero_lines(false, true);
  std::vector<double> xs, ys;
  for (const auto& p : d.points) {
    xs.push_back(p.distortion_percent);
    ys.push_back(p.field_value);
  }
  axes.curve(xs, ys, LineStyle{Rgb{0.08f, 0.25f, 0.88f}, 2.5});
  return canvas;
}

Canvas plot_field_curves(const FieldCurves& fc, const PlotOptions& o) {
  Canvas canvas = one_panel_canvas(o, true);
  const double top = panel_top(o, true);
  std::vector<double> wavelengths;
  for (const auto& c : fc.curves) wavelengths.push_back(c.wavelength_nm);
  const std::vector<Rgb> colours = wavelength_colours(wavelengths);
  double lo = 0.0, hi = 0.0, fmax = 0.0;
  for (const auto& c : fc.curves) {
    for (const auto& p : c.points) {
      for (double v : {p.tangential_mm, p.sagittal_mm}) {
        if (std::isfinite(v)) {
          lo = std::min(lo, v);
          hi = std::max(hi, v);
        }
      }
      fmax = std::max(fmax, p.field_value);
    }
  }
  if (hi - lo < 1e-3) {  // flat curves: show at least +/-0.5 um around them
    lo -= 0.0005;
    hi += 0.0005;
  }
  PlotAxes axes(canvas, {kPanelLeft, top}, {kPanelLeft + kPanelWidth, top + kPanelHeight}, nice_range(lo, hi, 6),
                {0.0, fmax > 0.0 ? fmax : 1.0});
  header(canvas, "Field curves", fc.lens_name,
         "tangential and sagittal focus minus the image plane, along z (image plane z = " + fixed(fc.image_plane_z_mm, 3) +
             " mm, paraxial focus z = " + fixed(fc.paraxial_focus_z_mm, 3) + " mm)",
         o);
  std::vector<LegendEntry> legend{{"tangential", LineStyle{kText, 2.0}}, {"sagittal", LineStyle{kText, 2.0, 7.0, 5.0}}};
  for (std::size_t w = 0; w < wavelengths.size(); ++w) legend.push_back({wavelength_label(wavelengths[w]), LineStyle{colours[w], 2.0}});
  legend_row(canvas, {20.0, header_height(o) + 0.4 * o.font_px}, legend, o);
  AxesText text;
  text.font_px = o.font_px;
  text.x_label = "focus shift (mm)";
  text.y_label = field_axis_label(fc.field_unit);
  axes.draw_frame(text, true, true, 6, 6);
  axes.draw_zero_lines(false, true);
  for (std::size_t w = 0; w < fc.curves.size(); ++w) {
    std::vector<double> t, s, f;
    for (const auto& p : fc.curves[w].points) {
      t.push_back(p.tangential_mm);
      s.push_back(p.sagittal_mm);
      f.push_back(p.field_value);
    }
    axes.curve(t, f, LineStyle{colours[w], 2.2});
    axes.curve(s, f, LineStyle{colours[w], 2.2, 8.0, 5.0});
  }
  return canvas;
}

Canvas plot_mtf(const Mtf& mtf, const PlotOptions& o) {
  Canvas canvas = one_panel_canvas(o, true);
  const double top = panel_top(o, true);
  const double fmax = mtf.frequencies_per_mm.empty() ? 1.0 : std::max(1e-9, mtf.frequencies_per_mm.back());
  PlotAxes axes(canvas, {kPanelLeft, top}, {kPanelLeft + kPanelWidth, top + kPanelHeight}, {0.0, fmax}, {0.0, 1.0});
  std::string waves;
  for (double w : mtf.wavelengths_nm) waves += (waves.empty() ? "" : ", ") + fixed(w, 1);
  std::string strehl;
  for (const MtfCurve& c : mtf.fields) strehl += (strehl.empty() ? "" : ", ") + fixed(c.strehl, 3);
  header(canvas, "MTF (FFT)", mtf.lens_name,
         "polychromatic over " + waves + " nm, equal weights; diffraction cutoff " + fixed(mtf.cutoff_per_mm, 1) +
             " cycles/mm on axis; black: the diffraction limit" + (mtf.fields.empty() ? std::string() : " at " + mtf.fields.front().field_label) +
             "; Strehl ratios by field: " + strehl,
         o);
  std::vector<LegendEntry> legend{{"tangential", LineStyle{kText, 2.0}}, {"sagittal", LineStyle{kText, 2.0, 7.0, 5.0}}};
  for (std::size_t f = 0; f < mtf.fields.size(); ++f) legend.push_back({mtf.fields[f].field_label, LineStyle{field_colour(f), 2.0}});
  legend_row(canvas, {20.0, header_height(o) + 0.4 * o.font_px}, legend, o);
  AxesText text;
  text.font_px = o.font_px;
  text.x_label = "spatial frequency (cycles/mm)";
  text.y_label = "modulation";
  axes.draw_frame(text, true, true, 6, 5);
  if (!mtf.fields.empty()) axes.curve(mtf.frequencies_per_mm, mtf.fields.front().diffraction_limit, LineStyle{kText, 1.6});
  for (std::size_t f = 0; f < mtf.fields.size(); ++f) {
    axes.curve(mtf.frequencies_per_mm, mtf.fields[f].tangential, LineStyle{field_colour(f), 2.2});
    axes.curve(mtf.frequencies_per_mm, mtf.fields[f].sagittal, LineStyle{field_colour(f), 2.2, 8.0, 5.0});
  }
  return canvas;
}

Canvas plot_through_focus_mtf(const ThroughFocusMtf& mtf, const PlotOptions& o) {
  Canvas canvas = one_panel_canvas(o, true);
  const double top = panel_top(o, true);
  const double lo = mtf.focus_shifts_mm.empty() ? -1.0 : mtf.focus_shifts_mm.front();
  const double hi = mtf.focus_shifts_mm.empty() ? 1.0 : std::max(lo + 1e-9, mtf.focus_shifts_mm.back());
  PlotAxes axes(canvas, {kPanelLeft, top}, {kPanelLeft + kPanelWidth, top + kPanelHeight}, {lo, hi}, {0.0, 1.0});
  header(canvas, "Through-focus MTF (FFT)", mtf.lens_name,
         "at " + fixed(mtf.frequency_per_mm, 2) + " cycles/mm; image plane moved along the axis, + away from the lens", o);
  std::vector<LegendEntry> legend{{"tangential", LineStyle{kText, 2.0}}, {"sagittal", LineStyle{kText, 2.0, 7.0, 5.0}}};
  for (std::size_t f = 0; f < mtf.fields.size(); ++f) legend.push_back({mtf.fields[f].field_label, LineStyle{field_colour(f), 2.0}});
  legend_row(canvas, {20.0, header_height(o) + 0.4 * o.font_px}, legend, o);
  AxesText text;
  text.font_px = o.font_px;
  text.x_label = "focus shift (mm)";
  text.y_label = "modulation";
  axes.draw_frame(text, true, true, 6, 5);
  axes.draw_zero_lines(false, true);
  for (std::size_t f = 0; f < mtf.fields.size(); ++f) {
    axes.curve(mtf.focus_shifts_mm, mtf.fields[f].tangential, LineStyle{field_colour(f), 2.2});
    axes.curve(mtf.focus_shifts_mm, mtf.fields[f].sagittal, LineStyle{field_colour(f), 2.2, 8.0, 5.0});
  }
  return canvas;
}

Canvas plot_chromatic_focal_shift(const ChromaticFocalShift& c, const PlotOptions& o) {
  Canvas canvas = one_panel_canvas(o, false);
  const double top = panel_top(o, false);
  double lo = 0.0, hi = 0.0;
  bool extrapolated = false;
  for (const auto& p : c.points) {
    lo = std::min(lo, um_from_mm(p.shift_mm));
    hi = std::max(hi, um_from_mm(p.shift_mm));
    extrapolated = extrapolated || p.extrapolated;
  }
  if (hi - lo < 1e-3) {
    lo -= 0.5;
    hi += 0.5;
  }
  PlotAxes axes(canvas, {kPanelLeft, top}, {kPanelLeft + kPanelWidth, top + kPanelHeight}, nice_range(lo, hi, 6),
                {c.points.front().wavelength_nm, c.points.back().wavelength_nm});
  header(canvas, "Chromatic focal shift (paraxial)", c.lens_name,
         "paraxial focus at each wavelength minus the focus at " + wavelength_label(c.reference_wavelength_nm) + "; range " +
             micrometres(c.range_mm()) + (extrapolated ? "; some glasses evaluated outside their catalogue range" : ""),
         o);
  AxesText text;
  text.font_px = o.font_px;
  text.x_label = "focal shift (\xC2\xB5m)";
  text.y_label = "wavelength (nm)";
  axes.draw_frame(text, true, true, 6, 6);
  axes.draw_zero_lines(false, true);
  std::vector<double> xs, ys;
  for (const auto& p : c.points) {
    xs.push_back(um_from_mm(p.shift_mm));
    ys.push_back(p.wavelength_nm);
  }
  axes.curve(xs, ys, LineStyle{Rgb{0.08f, 0.25f, 0.88f}, 2.5});
  return canvas;
}

Canvas plot_relative_illumination(const RelativeIllumination& ri, const PlotOptions& o) {
  Canvas canvas = one_panel_canvas(o, true);
  const double top = panel_top(o, true);
  double fmax = 0.0;
  for (const auto& p : ri.points) fmax = std::max(fmax, p.field_value);
  PlotAxes axes(canvas, {kPanelLeft, top}, {kPanelLeft + kPanelWidth, top + kPanelHeight}, {0.0, fmax > 0.0 ? fmax : 1.0}, {0.0, 1.05});
  const IlluminationPoint& last = ri.points.back();
  header(canvas, "Relative illumination", ri.lens_name,
         wavelength_label(ri.wavelength_nm) + ", pupil grid " + std::to_string(ri.pupil_grid) + " x " + std::to_string(ri.pupil_grid) +
             "; full field: relative illumination " + fixed(last.relative_illumination, 3) + ", vignetting factor " +
             fixed(last.vignetting_factor, 3),
         o);
  const Rgb blue{0.08f, 0.25f, 0.88f}, green{0.0f, 0.55f, 0.12f}, grey{0.45f, 0.45f, 0.45f};
  legend_row(canvas, {20.0, header_height(o) + 0.4 * o.font_px},
             {{"relative illumination", LineStyle{blue, 2.5}},
              {"vignetting factor", LineStyle{green, 2.2, 8.0, 5.0}},
              {"vignetting x cos^4", LineStyle{grey, 2.0, 3.0, 4.0}}},
             o);
  AxesText text;
  text.font_px = o.font_px;
  text.x_label = field_axis_label(ri.field_unit);
  text.y_label = "relative value";
  axes.draw_frame(text, true, true, 6, 6);
  std::vector<double> f, r, v, c4;
  for (const auto& p : ri.points) {
    f.push_back(p.field_value);
    r.push_back(p.relative_illumination);
    v.push_back(p.vignetting_factor);
    c4.push_back(p.cos4_estimate);
  }
  axes.curve(f, c4, LineStyle{grey, 2.0, 3.0, 4.0});
  axes.curve(f, v, LineStyle{green, 2.2, 8.0, 5.0});
  axes.curve(f, r, LineStyle{blue, 2.5});
  return canvas;
}

Swatch surface_swatch(std::size_t rank) {
  // Twenty light colours that differ from each other and from the pupil's blue (Kelly's colours of
  // maximum contrast, lightened so the outline stays visible on them); then the same with hatching.
  static constexpr Rgb kColours[] = {
      {0.98f, 0.62f, 0.30f}, {0.99f, 0.86f, 0.35f}, {0.55f, 0.82f, 0.45f}, {0.72f, 0.55f, 0.88f}, {0.92f, 0.40f, 0.40f},
      {0.45f, 0.80f, 0.75f}, {0.97f, 0.65f, 0.85f}, {0.72f, 0.55f, 0.40f}, {0.75f, 0.75f, 0.30f}, {0.65f, 0.65f, 0.65f},
      {0.25f, 0.60f, 0.30f}, {0.85f, 0.30f, 0.75f}, {0.80f, 0.45f, 0.15f}, {0.45f, 0.30f, 0.65f}, {0.75f, 0.95f, 0.45f},
      {0.60f, 0.20f, 0.25f}, {0.40f, 0.90f, 0.95f}, {0.93f, 0.85f, 0.70f}, {0.10f, 0.50f, 0.55f}, {0.30f, 0.30f, 0.30f}};
  constexpr std::size_t kCount = std::size(kColours);
  return {kColours[rank % kCount], static_cast<int>(rank / kCount)};
}

void fill_swatch(Canvas& canvas, Point2 top_left, Point2 bottom_right, const Swatch& swatch) {
  canvas.fill_rect(top_left, bottom_right, swatch.colour);
  if (swatch.hatch == 0) return;
  // Hatching in canvas coordinates, so neighbouring cells continue each other's lines: 1 rising,
  // 2 falling, 3 crossed, 4 and up: dots of a spacing that grows with the number.
  const int x0 = static_cast<int>(std::floor(top_left.x)), x1 = static_cast<int>(std::ceil(bottom_right.x));
  const int y0 = static_cast<int>(std::floor(top_left.y)), y1 = static_cast<int>(std::ceil(bottom_right.y));
  const int period = 6 + swatch.hatch;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      const int rising = ((x + y) % period + period) % period, falling = ((x - y) % period + period) % period;
      bool mark = false;
      if (swatch.hatch == 1) mark = rising < 2;
      else if (swatch.hatch == 2) mark = falling < 2;
      else if (swatch.hatch == 3) mark = rising < 2 || falling < 2;
      else mark = (x % period) < 2 && (y % period) < 2;
      if (mark) canvas.fill_rect({static_cast<double>(x), static_cast<double>(y)}, {x + 1.0, y + 1.0}, kWhite);
    }
  }
}

Canvas plot_pupil_shape(const PupilShape& shape, const PlotOptions& o) {
  const int count = static_cast<int>(shape.fields.size());
  const int columns = std::min(count, 4);
  const int rows = (count + columns - 1) / columns;
  const double panel = 250.0, gap_x = 80.0, gap_y = 60.0 + 3.0 * o.font_px;
  const double left = 90.0, top = header_height(o) + 2.0 * o.font_px + 20.0;
  // A swatch per surface that stops rays, in surface order: never the same for two surfaces.
  std::map<int, Swatch> surface_swatches;
  for (const auto& f : shape.fields) {
    for (const auto& l : f.losses) surface_swatches.emplace(l.surface, Swatch{});
  }
  {
    std::size_t i = 0;
    for (auto& [surface, swatch] : surface_swatches) swatch = surface_swatch(i++);
  }
  const int legend_rows = std::max(1, static_cast<int>(surface_swatches.size() + 3) / 4);
  const int width = std::max(760, static_cast<int>(left + columns * panel + (columns - 1) * gap_x + 60.0));
  const int height = static_cast<int>(top + rows * panel + (rows - 1) * gap_y + 50.0 + 3.0 * o.font_px + legend_rows * 1.6 * o.font_px);
  Canvas canvas = make_canvas(width, height, o);
  header(canvas, "Unvignetted entrance pupil", shape.lens_name,
         wavelength_label(shape.wavelength_nm) + "; normalised entrance-pupil coordinates; blue: rays that reach the image plane; "
                                                 "other colours: where the rays were stopped",
         o);
  const Rgb pass{0.55f, 0.72f, 0.95f}, outline{0.05f, 0.15f, 0.55f};
  std::vector<double> ux, uy;
  for (int i = 0; i <= 180; ++i) {
    ux.push_back(std::cos(2.0 * kPi * i / 180));
    uy.push_back(std::sin(2.0 * kPi * i / 180));
  }
  for (int k = 0; k < count; ++k) {
    const FieldPupilShape& f = shape.fields[static_cast<std::size_t>(k)];
    const double x0 = left + (k % columns) * (panel + gap_x);
    const double y0 = top + (k / columns) * (panel + gap_y);
    PlotAxes axes(canvas, {x0, y0}, {x0 + panel, y0 + panel}, {-1.1, 1.1}, {-1.1, 1.1});
    AxesText text;
    text.font_px = o.font_px;
    text.title = "Field " + f.field_label;
    text.x_label = "px";
    text.y_label = "py";
    axes.draw_frame(text, true, true, 4, 4);
    // Cells snapped to whole pixels so neighbours meet without seams.
    const double cell = 2.0 / f.grid;
    for (int r = 0; r < f.grid; ++r) {
      for (int c = 0; c < f.grid; ++c) {
        const PupilCell& pc = f.cell(r, c);
        if (!pc.inside) continue;
        const PupilCoordinate p = FieldPupilShape::cell_centre(f.grid, r, c);
        const Point2 a = axes.to_pixel(p.px - 0.5 * cell, p.py + 0.5 * cell);
        const Point2 b = axes.to_pixel(p.px + 0.5 * cell, p.py - 0.5 * cell);
        const Point2 ra{std::round(a.x), std::round(a.y)}, rb{std::round(b.x), std::round(b.y)};
        if (pc.status == RayStatus::Ok) {
          canvas.fill_rect(ra, rb, pass);
        } else {
          fill_swatch(canvas, ra, rb, surface_swatches[pc.surface]);
        }
      }
    }
    axes.curve(ux, uy, LineStyle{kNote, 1.2, 5.0, 4.0});
    if (!f.outline.empty()) {
      std::vector<double> ox, oy;
      for (const auto& p : f.outline) {
        ox.push_back(p.px);
        oy.push_back(p.py);
      }
      ox.push_back(f.outline.front().px);
      oy.push_back(f.outline.front().py);
      axes.curve(ox, oy, LineStyle{outline, 2.2});
      const Point2 c = axes.to_pixel(f.centroid.px, f.centroid.py);
      canvas.line({c.x - 5.0, c.y}, {c.x + 5.0, c.y}, LineStyle{outline, 1.5});
      canvas.line({c.x, c.y - 5.0}, {c.x, c.y + 5.0}, LineStyle{outline, 1.5});
    }
    canvas.text({x0 + 0.5 * panel, y0 + panel + 20.0 + 2.2 * o.font_px}, "area fraction " + fixed(f.area_fraction, 3), o.font_px * 0.95,
                kText, HAlign::Centre, VAlign::Top);
  }
  // Legend: which surface stopped the rays of each colour.
  double lx = 20.0, ly = height - 16.0 - legend_rows * 1.6 * o.font_px + 0.8 * o.font_px;
  int n = 0;
  for (const auto& [surface, swatch] : surface_swatches) {
    fill_swatch(canvas, {lx, ly - 7.0}, {lx + 14.0, ly + 7.0}, swatch);
    canvas.text({lx + 20.0, ly}, "stopped at surface " + std::to_string(surface), o.font_px * 0.85, kText, HAlign::Left, VAlign::Middle);
    lx += 200.0;
    if (++n % 4 == 0) {
      lx = 20.0;
      ly += 1.6 * o.font_px;
    }
  }
  return canvas;
}

}  // namespace lensmith::plot

namespace lensmith::plot {

Canvas plot_seidel_diagram(const SeidelAnalysis& seidel, const std::string& lens_name, const PlotOptions& o) {
  o.validate();
  struct Term {
    const char* label;
    Rgb colour;
  };
  // The columns of `lensmith seidel`'s table, in its order and with its names.
  const Term terms[] = {{"S_I", Rgb{0.10f, 0.30f, 0.85f}},  {"S_II", Rgb{0.90f, 0.45f, 0.05f}}, {"S_III", Rgb{0.15f, 0.60f, 0.20f}},
                        {"S_IV", Rgb{0.80f, 0.15f, 0.15f}}, {"S_V", Rgb{0.50f, 0.30f, 0.70f}},  {"C_I", Rgb{0.45f, 0.45f, 0.45f}},
                        {"C_II", Rgb{0.85f, 0.55f, 0.78f}}};
  constexpr int kTerms = 7;
  // Welford's sums exactly as the text output prints them (mm, their own signs): no rescaling, so a
  // bar can be checked against the table.
  auto values = [](const SeidelSums& s) { return std::array<double, kTerms>{s.S1, s.S2, s.S3, s.S4, s.S5, s.C1, s.C2}; };
  std::vector<std::array<double, kTerms>> groups;
  for (const SeidelSums& s : seidel.surfaces()) groups.push_back(values(s));
  groups.push_back(values(seidel.sums()));
  double lo = 0.0, hi = 0.0;
  for (const auto& g : groups) {
    for (double v : g) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  if (hi - lo <= 0.0) hi = lo + 1e-6;

  // Surfaces side by side, then half a group of space and the sum on a light band.
  const double count = static_cast<double>(groups.size());
  const double group_px = std::clamp(700.0 / count, 40.0, 90.0);
  const double sum_gap_px = 0.5 * group_px;
  const double right = kPanelLeft + group_px * count + sum_gap_px;
  const double top = header_height(o) + 2.0 * o.font_px + 34.0;
  Canvas canvas = make_canvas(static_cast<int>(std::max(right + 60.0, 820.0)), static_cast<int>(top + kPanelHeight + 4.0 * o.font_px + 30.0), o);
  PlotAxes axes(canvas, {kPanelLeft, top}, {right, top + kPanelHeight}, {0.0, 1.0}, nice_range(lo, hi, 6));
  header(canvas, "Seidel diagram", lens_name,
         "Welford's Seidel sums per surface at " + wavelength_label(seidel.wavelength_nm()) +
             " (mm) as `lensmith seidel` prints them: S_I spherical (> 0 undercorrected), S_II coma, S_III astigmatism, "
             "S_IV Petzval, S_V distortion, C_I axial and C_II lateral colour",
         o);
  const double sum_x0 = kPanelLeft + group_px * (count - 1.0) + sum_gap_px;
  canvas.fill_rect({sum_x0, top}, {right, top + kPanelHeight}, Rgb{0.94f, 0.94f, 0.94f});
  AxesText text;
  text.font_px = o.font_px;
  text.y_label = "Seidel sum (mm)";
  text.x_grid = false;  // vertical lines between groups would read as element boundaries
  text.x_tick_marks = false;
  axes.draw_frame(text, false, true, 5, 6);
  const double bar = group_px * 0.8 / kTerms;
  const Point2 zero = axes.to_pixel(0.0, 0.0);
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const bool sum = g + 1 == groups.size();
    const double gx = sum ? sum_x0 : kPanelLeft + group_px * static_cast<double>(g);
    const double x0 = gx + group_px * 0.1;
    for (int t = 0; t < kTerms; ++t) {
      const Point2 end = axes.to_pixel(0.0, groups[g][static_cast<std::size_t>(t)]);
      const double xa = x0 + bar * t;
      canvas.fill_rect({xa, std::min(zero.y, end.y)}, {xa + bar * 0.9, std::max(zero.y, end.y)}, terms[t].colour);
    }
    // A tick mark under the group's centre, outside the frame: an axis tick, not a separator.
    const double cx = gx + 0.5 * group_px;
    canvas.line({cx, top + kPanelHeight}, {cx, top + kPanelHeight + 5.0}, LineStyle{kText, 1.2});
    canvas.text({cx, top + kPanelHeight + 8.0}, sum ? std::string("sum") : std::to_string(g + 1), o.font_px * 0.9, kText, HAlign::Centre,
                VAlign::Top);
  }
  canvas.line({kPanelLeft, zero.y}, {right, zero.y}, LineStyle{kText, 1.2});
  canvas.text({(kPanelLeft + right) / 2.0, top + kPanelHeight + 1.6 * o.font_px + 8.0}, "surface", o.font_px, kText, HAlign::Centre, VAlign::Top);
  std::vector<LegendEntry> legend;
  for (const Term& t : terms) legend.push_back({t.label, LineStyle{t.colour, 8.0}});
  legend_row(canvas, {kPanelLeft, top - 1.4 * o.font_px}, legend, o);
  return canvas;
}

}  // namespace lensmith::plot

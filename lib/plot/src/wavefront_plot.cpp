// The wavefront map picture: OpticStudio's Wavefront Map per field and wavelength, on one diverging
// colour scale (blue behind the reference sphere, red ahead of it, white on it) in waves.
#include <algorithm>
#include <cmath>

#include "figure_parts.h"
#include "lensmith/plot/analysis_plots.h"
#include "lensmith/plot/plot_axes.h"
#include "lensmith/core/units.h"

namespace lensmith::plot {

using namespace detail;

namespace {

// Diverging blue - white - red for t in [-1, 1].
Rgb diverging(double t) {
  const Rgb blue{0.13f, 0.32f, 0.72f}, white{0.97f, 0.97f, 0.97f}, red{0.75f, 0.12f, 0.12f};
  const float u = static_cast<float>(std::clamp(std::abs(t), 0.0, 1.0));
  return t < 0.0 ? mix(white, blue, u) : mix(white, red, u);
}

}  // namespace

Canvas plot_wavefront_map(const Wavefront& wavefront, const PlotOptions& o) {
  const std::size_t waves = std::max<std::size_t>(1, wavefront.wavelengths_nm.size());
  const int columns = static_cast<int>(waves);
  const int rows = static_cast<int>((wavefront.maps.size() + waves - 1) / waves);
  const double panel = 220.0, gap_x = 70.0, gap_y = 64.0 + 3.0 * o.font_px;
  const double left = 80.0, top = header_height(o) + 2.0 * o.font_px + 10.0, bar = 70.0 + 2.0 * o.font_px;
  const int width = std::max(640, static_cast<int>(left + columns * panel + (columns - 1) * gap_x + 40.0));
  const int height = static_cast<int>(top + rows * panel + (rows - 1) * gap_y + 40.0 + 2.5 * o.font_px + bar);
  Canvas canvas = make_canvas(width, height, o);
  header(canvas, "Wavefront map", wavefront.lens_name,
         "OPD against the reference sphere at the exit pupil, piston removed; red: the wavefront leads the sphere; "
         "normalised pupil coordinates",
         o);
  // One scale for every panel: the largest |OPD - mean| over them.
  double scale = 0.0;
  std::vector<double> means;
  for (const WavefrontMap& m : wavefront.maps) {
    double sum = 0.0;
    std::size_t n = 0;
    for (const OpdSample& s : m.map) {
      if (std::isfinite(s.opd_waves)) sum += s.opd_waves, ++n;
    }
    const double mean = n ? sum / static_cast<double>(n) : 0.0;
    means.push_back(mean);
    for (const OpdSample& s : m.map) {
      if (std::isfinite(s.opd_waves)) scale = std::max(scale, std::abs(s.opd_waves - mean));
    }
  }
  if (!(scale > 0.0)) scale = 1.0;
  const AxisRange symmetric = nice_range(-scale, scale, 4);
  scale = std::max(std::abs(symmetric.min), std::abs(symmetric.max));

  for (std::size_t k = 0; k < wavefront.maps.size(); ++k) {
    const WavefrontMap& m = wavefront.maps[k];
    const double x0 = left + static_cast<double>(k % waves) * (panel + gap_x);
    const double y0 = top + static_cast<double>(k / waves) * (panel + gap_y);
    PlotAxes axes(canvas, {x0, y0}, {x0 + panel, y0 + panel}, {-1.05, 1.05}, {-1.05, 1.05});
    const double cell = 2.0 / (m.grid - 1);
    for (const OpdSample& s : m.map) {
      if (!std::isfinite(s.opd_waves)) continue;
      const Point2 a = axes.to_pixel(s.px - 0.5 * cell, s.py + 0.5 * cell), b = axes.to_pixel(s.px + 0.5 * cell, s.py - 0.5 * cell);
      canvas.fill_rect({std::round(a.x), std::round(a.y)}, {std::round(b.x), std::round(b.y)}, diverging((s.opd_waves - means[k]) / scale));
    }
    AxesText text;
    text.font_px = o.font_px;
    text.title = "Field " + m.field_label + ", " + wavelength_label(m.wavelength_nm);
    text.x_label = "px";
    text.y_label = "py";
    axes.draw_frame(text, true, true, 4, 4);
    canvas.text({x0 + 0.5 * panel, y0 + panel + 16.0 + 2.2 * o.font_px},
                "RMS " + fixed(m.rms_waves, 4) + ", P-V " + fixed(m.pv_waves, 4) + " waves", o.font_px * 0.95, kText, HAlign::Centre,
                VAlign::Top);
  }
  // The colour bar.
  const double bx0 = 0.5 * width - 200.0, bx1 = 0.5 * width + 200.0, by = height - bar + 10.0;
  for (int i = 0; i < 400; ++i) {
    const double t = -1.0 + 2.0 * (i + 0.5) / 400.0;
    canvas.fill_rect({bx0 + i, by}, {bx0 + i + 1.0, by + 16.0}, diverging(t));
  }
  canvas.rect({bx0, by}, {bx1, by + 16.0}, LineStyle{kNote, 1.0});
  const std::vector<double> ticks = nice_ticks(-scale, scale, 5);
  const double step = ticks.size() > 1 ? ticks[1] - ticks[0] : scale;
  for (double v : ticks) {
    const double x = bx0 + (v + scale) / (2.0 * scale) * (bx1 - bx0);
    canvas.line({x, by + 16.0}, {x, by + 21.0}, LineStyle{kNote, 1.0});
    canvas.text({x, by + 24.0}, tick_label(v, step), o.font_px * 0.85, kText, HAlign::Centre, VAlign::Top);
  }
  canvas.text({0.5 * width, by + 26.0 + 1.2 * o.font_px}, "OPD, waves", o.font_px * 0.9, kText, HAlign::Centre, VAlign::Top);
  return canvas;
}

Canvas plot_psf(const Psf& psf, const PlotOptions& o) {
  const int count = static_cast<int>(psf.fields.size());
  const int columns = std::max(1, std::min(count, 3));
  const int rows = (count + columns - 1) / columns;
  const double panel = 240.0, gap_x = 80.0, gap_y = 64.0 + 3.0 * o.font_px;
  const double left = 80.0, top = header_height(o) + 1.0 * o.font_px + 10.0;
  const int width = std::max(640, static_cast<int>(left + columns * panel + (columns - 1) * gap_x + 40.0));
  const int height = static_cast<int>(top + rows * panel + (rows - 1) * gap_y + 40.0 + 2.5 * o.font_px);
  Canvas canvas = make_canvas(width, height, o);
  std::string waves;
  for (double w : psf.wavelengths_nm) waves += (waves.empty() ? "" : ", ") + fixed(w, 1);
  header(canvas, "PSF (FFT)", psf.lens_name,
         "polychromatic over " + waves + " nm, equal weights; grey, logarithmic over four decades of the aberration-free peak; "
         "micrometres about the reference chief ray",
         o);
  const double half_um = 0.5 * psf.size * um_from_mm(psf.spacing_mm);
  constexpr double kDecades = 4.0;
  for (int k = 0; k < count; ++k) {
    const FieldPsf& f = psf.fields[static_cast<std::size_t>(k)];
    const double x0 = left + (k % columns) * (panel + gap_x), y0 = top + (k / columns) * (panel + gap_y);
    PlotAxes axes(canvas, {x0, y0}, {x0 + panel, y0 + panel}, {-half_um, half_um}, {-half_um, half_um});
    const double cell = 2.0 * half_um / psf.size;
    for (int r = 0; r < psf.size; ++r) {
      for (int c = 0; c < psf.size; ++c) {
        const double v = f.intensity[static_cast<std::size_t>(r) * static_cast<std::size_t>(psf.size) + static_cast<std::size_t>(c)];
        const double level = std::clamp(1.0 + std::log10(std::max(v, 1e-12)) / kDecades, 0.0, 1.0);
        const double x = -half_um + c * cell, y = half_um - r * cell;
        const Point2 a = axes.to_pixel(x, y), b = axes.to_pixel(x + cell, y - cell);
        const float g = static_cast<float>(1.0 - level);
        canvas.fill_rect({std::round(a.x), std::round(a.y)}, {std::round(b.x), std::round(b.y)}, Rgb{g, g, g});
      }
    }
    AxesText text;
    text.font_px = o.font_px;
    text.title = "Field " + f.field_label;
    text.x_label = "x (um)";
    text.y_label = "y (um)";
    axes.draw_frame(text, true, true, 4, 4);
    canvas.text({x0 + 0.5 * panel, y0 + panel + 16.0 + 2.2 * o.font_px}, "Strehl ratio " + fixed(f.strehl, 4), o.font_px * 0.95, kText,
                HAlign::Centre, VAlign::Top);
  }
  return canvas;
}

}  // namespace lensmith::plot

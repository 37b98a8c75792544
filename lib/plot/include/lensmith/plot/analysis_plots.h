// Pictures of the real-ray analyses (lensmith/analysis), drawn the way OpticStudio and CODE V users
// read them: white background, one colour per wavelength (shortest blue, then green, longest red),
// labelled axes with units, the key numbers printed on the plot. Each function returns a Canvas;
// Canvas::write_png() saves it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "lensmith/analysis/chromatic_focal_shift.h"
#include "lensmith/analysis/distortion_curve.h"
#include "lensmith/analysis/field_curves.h"
#include "lensmith/analysis/mtf.h"
#include "lensmith/analysis/pupil_shape.h"
#include "lensmith/analysis/ray_fan.h"
#include "lensmith/analysis/relative_illumination.h"
#include "lensmith/analysis/spot_diagram.h"
#include "lensmith/analysis/wavefront.h"
#include "lensmith/plot/canvas.h"
#include "lensmith/seidel/seidel_analysis.h"

namespace lensmith::plot {

struct PlotOptions {
  // TrueType font for labels; empty: the picture is drawn without text.
  std::optional<std::string> font_path = Canvas::find_default_font();
  double font_px = 15.0;  // base text size, 8 to 48
  void validate() const;  // throws OptionsError
};

// Colours for wavelengths by rank: the shortest blue, the longest red, green between.
std::vector<Rgb> wavelength_colours(const std::vector<double>& wavelengths_nm);

// Fields (rows, labelled with the chief ray's image height) x wavelengths (columns, plus an overlay of
// all when there are several); every panel centred on the reference chief ray at one common scale in
// micrometres with the Airy circle (1.22 lambda N_w) about it, RMS and GEO radii and lost rays below.
Canvas plot_spot_diagram(const SpotDiagram& spots, const PlotOptions& options = {});
// Per field a tangential (ey against py) and a sagittal (ex against px) panel, one curve per
// wavelength, a common error scale in micrometres; a ray that died leaves a gap.
Canvas plot_ray_fan(const RayFan& fan, const PlotOptions& options = {});
// The wavefront map per field (rows) and wavelength (columns), piston removed, on one diverging colour
// scale in waves with its bar, RMS and P-V under each map (wavefront_plot.cpp).
Canvas plot_wavefront_map(const Wavefront& wavefront, const PlotOptions& options = {});
// MTF against spatial frequency (cycles/mm): per field tangential (solid) and sagittal (dashed) in the
// field's colour, the first field's diffraction limit in black, the Strehl ratios in the header.
Canvas plot_mtf(const Mtf& mtf, const PlotOptions& options = {});
// The through-focus MTF: modulation against the focus shift (mm), per field T solid and S dashed.
Canvas plot_through_focus_mtf(const ThroughFocusMtf& mtf, const PlotOptions& options = {});
// The PSF per field, in grey on a logarithmic scale over four decades (the Airy rings show), axes in
// micrometres about the reference chief ray, the Strehl ratio under each (wavefront_plot.cpp).
Canvas plot_psf(const Psf& psf, const PlotOptions& options = {});
// Distortion (%) across, field up.
Canvas plot_distortion(const DistortionCurve& distortion, const PlotOptions& options = {});
// Tangential (solid) and sagittal (dashed) focus shift (mm) across, field up, per wavelength.
Canvas plot_field_curves(const FieldCurves& curves, const PlotOptions& options = {});
// Focal shift (µm) across, wavelength up.
Canvas plot_chromatic_focal_shift(const ChromaticFocalShift& shift, const PlotOptions& options = {});
// Relative illumination, vignetting factor and the cos^4 estimate against field.
Canvas plot_relative_illumination(const RelativeIllumination& illumination, const PlotOptions& options = {});
// How the pupil picture marks the rays a surface stopped: a light colour, plain (hatch 0) or hatched
// (1 rising lines, 2 falling, 3 crossed, 4 and up dotted) when more surfaces stop rays than there are colours.
struct Swatch {
  Rgb colour;
  int hatch = 0;
  friend bool operator==(const Swatch&, const Swatch&) = default;
};
// The swatch of the rank-th surface (0-based, in surface order) that stops rays: no two ranks share one.
Swatch surface_swatch(std::size_t rank);
// Fills the rectangle with `swatch` (hatching continues across neighbouring rectangles).
void fill_swatch(Canvas& canvas, Point2 top_left, Point2 bottom_right, const Swatch& swatch);

// The entrance pupil per field: cells that pass, cells lost coloured by the surface that stopped
// them, the outline of the passing region and its area fraction.
Canvas plot_pupil_shape(const PupilShape& shape, const PlotOptions& options = {});

// The Seidel diagram: per surface and for the sum, grouped bars of Welford's sums S_I..S_V, C_I and C_II
// (mm) with the numbers and signs `lensmith seidel` prints (SeidelAnalysis::to_string), a zero line, and
// tick marks under the groups instead of vertical grid lines (which read as element boundaries).
Canvas plot_seidel_diagram(const SeidelAnalysis& seidel, const std::string& lens_name, const PlotOptions& options = {});

}  // namespace lensmith::plot

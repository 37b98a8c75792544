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
#include "lensmith/analysis/pupil_shape.h"
#include "lensmith/analysis/ray_fan.h"
#include "lensmith/analysis/relative_illumination.h"
#include "lensmith/analysis/spot_diagram.h"
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

// Fields (rows) x wavelengths (columns, plus an overlay of all when there are several); every panel
// centred on the reference chief ray at one common scale in micrometres, RMS and GEO radii below.
Canvas plot_spot_diagram(const SpotDiagram& spots, const PlotOptions& options = {});
// Per field a tangential (ey against py) and a sagittal (ex against px) panel, one curve per
// wavelength, a common error scale in micrometres; a ray that died leaves a gap.
Canvas plot_ray_fan(const RayFan& fan, const PlotOptions& options = {});
// Distortion (%) across, field up.
Canvas plot_distortion(const DistortionCurve& distortion, const PlotOptions& options = {});
// Tangential (solid) and sagittal (dashed) focus shift (mm) across, field up, per wavelength.
Canvas plot_field_curves(const FieldCurves& curves, const PlotOptions& options = {});
// Focal shift (µm) across, wavelength up.
Canvas plot_chromatic_focal_shift(const ChromaticFocalShift& shift, const PlotOptions& options = {});
// Relative illumination, vignetting factor and the cos^4 estimate against field.
Canvas plot_relative_illumination(const RelativeIllumination& illumination, const PlotOptions& options = {});
// The entrance pupil per field: cells that pass, cells lost coloured by the surface that stopped
// them, the outline of the passing region and its area fraction.
Canvas plot_pupil_shape(const PupilShape& shape, const PlotOptions& options = {});

// The Seidel diagram designers know from OpticStudio: per surface and for the sum, grouped bars of
// the transverse third-order contributions (Smith's forms, mm): spherical S_I/(2n'u'), coma
// S_II/(2n'u'), astigmatism S_III/(2n'u'), Petzval S_IV/(2n'u'), distortion S_V/(2n'u'), axial
// colour C_I/(n'u') and lateral colour C_II/(n'u').
Canvas plot_seidel_diagram(const SeidelAnalysis& seidel, const std::string& lens_name, const PlotOptions& options = {});

}  // namespace lensmith::plot

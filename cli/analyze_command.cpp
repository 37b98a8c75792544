// `lensmith analyze --what ...`: the real-ray analyses that have one curve or picture per lens:
// distortion, field curves, chromatic focal shift, relative illumination and the unvignetted pupil.
// A table, one JSON object (docs/cli.md) and optionally a PNG picture.
#include <cmath>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "lensmith/core/json_text.h"
#include "lensmith/report/json_report.h"
#include "json_output.h"
#include "lensmith/analysis/chromatic_focal_shift.h"
#include "lensmith/analysis/distortion_curve.h"
#include "lensmith/analysis/field_curves.h"
#include "lensmith/analysis/pupil_shape.h"
#include "lensmith/analysis/relative_illumination.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "lensmith/plot/analysis_plots.h"

namespace lensmith::cli {

namespace {



// Prints the result, writes the picture: the same three steps for every analysis.
template <typename Result, typename Json, typename Plot>
int report(const Result& result, const AnalyzeCommandOptions& options, const GlobalOptions& global, Json json, Plot plot) {
  if (!options.common.png.empty()) write_picture(plot(result, make_plot_options(global)), options.common.png, options.common.lens, global);
  if (options.common.json) {
    std::cout << json_text(json(result), 2) << "\n";
  } else {
    std::cout << result.to_string();
  }
  return kExitOk;
}

}  // namespace

int run_analyze(const AnalyzeCommandOptions& options, const GlobalOptions& global) {
  const Prescription lens = load_lens(options.common.lens, global);
  const std::string& what = options.what;
  if (what == "focal-shift") {
    FocalShiftOptions o;
    o.wavelengths_nm = options.common.wavelengths_nm;
    if (options.samples) o.samples = *options.samples;
    return report(compute_chromatic_focal_shift(lens, o), options, global, focal_shift_json, plot::plot_chromatic_focal_shift);
  }
  if (what == "pupil") {
    const AnalysisContext context(lens, make_analysis_options(options.common));
    PupilShapeOptions o;
    if (options.grid) o.grid = *options.grid;
    return report(compute_pupil_shape(context, o), options, global, pupil_json, plot::plot_pupil_shape);
  }
  // The curves against field sample the field themselves; --fields does not apply.
  RealRayCommandOptions common = options.common;
  common.relative_fields = {0.0, 1.0};
  const AnalysisContext context(lens, make_analysis_options(common));
  if (what == "distortion") {
    DistortionOptions o;
    if (options.samples) o.field_samples = *options.samples;
    return report(compute_distortion(context, o), options, global, distortion_json, plot::plot_distortion);
  }
  if (what == "field-curves") {
    FieldCurveOptions o;
    if (options.samples) o.field_samples = *options.samples;
    return report(compute_field_curves(context, o), options, global, field_curves_json, plot::plot_field_curves);
  }
  if (what == "illumination") {
    IlluminationOptions o;
    if (options.samples) o.field_samples = *options.samples;
    if (options.grid) o.pupil_grid = *options.grid;
    return report(compute_relative_illumination(context, o), options, global, illumination_json, plot::plot_relative_illumination);
  }
  throw UsageError("--what " + what + ": must be distortion, field-curves, focal-shift, illumination or pupil");
}

}  // namespace lensmith::cli

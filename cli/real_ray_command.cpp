// What `lensmith trace`, `spot`, `fan` and `analyze` share: command-line words to library options,
// the plot font, and writing pictures without ever touching the input.
#include <filesystem>
#include <iostream>

#include "commands.h"
#include "lensmith/render/image_io.h"
#include "lensmith/analysis/analysis_context.h"
#include "lensmith/core/errors.h"
#include "lensmith/plot/analysis_plots.h"

namespace lensmith::cli {

AnalysisOptions make_analysis_options(const RealRayCommandOptions& options) {
  AnalysisOptions a;
  a.relative_fields = options.relative_fields;
  a.wavelengths_nm = options.wavelengths_nm;
  a.max_field_angle_deg = options.field_angle_deg;
  if (options.image == "paraxial") {
    a.image_plane = TracerOptions::ImagePlane::ParaxialFocus;
  } else if (options.image != "prescribed") {
    throw UsageError("--image " + options.image + ": must be prescribed or paraxial");
  }
  if (options.aim == "real") {
    a.aiming = RayAiming::RealStop;
  } else if (options.aim == "paraxial") {
    a.aiming = RayAiming::ParaxialEntrancePupil;
  } else if (!options.aim.empty()) {
    throw UsageError("--aim " + options.aim + ": must be paraxial or real");
  }
  return a;
}

void apply_layout_defaults(const Prescription& lens, bool aim_given, bool field_given, AnalysisOptions& analysis) {
  // Real aiming is for rotationally symmetric refracting lenses (Prescription::why_no_real_ray_aiming).
  if (!aim_given) analysis.aiming = lens.why_no_real_ray_aiming() ? RayAiming::ParaxialEntrancePupil : RayAiming::RealStop;
  // A lens file need not give a field.
  if (!lens.field && !field_given) analysis.relative_fields = {0.0};
}

plot::PlotOptions make_plot_options(const GlobalOptions& global) {
  plot::PlotOptions o;
  static bool warned = false;
  if (!o.font_path && !global.quiet && !warned) {
    std::cerr << "warning: DejaVuSans.ttf not found (install fonts-dejavu-core): the picture is drawn without text\n";
    warned = true;
  }
  return o;
}

void write_picture(const plot::Canvas& canvas, const std::string& png, const std::string& lens, const GlobalOptions& global) {
  ensure_not_an_input(png, {lens.substr(0, lens.rfind('#'))});
  ensure_writable_location(png);
  canvas.write_png(png);
  report_written(png + " (" + std::to_string(canvas.width()) + " x " + std::to_string(canvas.height()) + ")", global);
}

}  // namespace lensmith::cli

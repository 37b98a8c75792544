// `lensmith seidel`: third-order aberrations per surface and summed, like CODE V's third-order
// listing, with the wavefront, transverse and longitudinal forms and Born & Wolf's B..F.
// JSON schema: docs/cli.md.
#include <cmath>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "lensmith/core/json_text.h"
#include "lensmith/report/json_report.h"
#include "json_output.h"
#include "lensmith/core/units.h"
#include "lensmith/seidel/aberration_vector.h"
#include "lensmith/plot/analysis_plots.h"
#include "lensmith/seidel/seidel_analysis.h"

namespace lensmith::cli {

namespace {

SeidelOptions seidel_options_from(const SeidelCommandOptions& options) {
  SeidelOptions o;
  if (options.wavelength_nm) o.wavelength_nm = *options.wavelength_nm;
  if (options.object_distance_m) o.object_distance_mm = mm_from_m(*options.object_distance_m);
  if (options.field_angle_deg) o.field_angle_deg = *options.field_angle_deg;
  if (options.epd_mm) o.entrance_pupil_diameter_mm = *options.epd_mm;
  if (options.f_number) o.f_number = *options.f_number;
  return o;
}

}  // namespace

int run_seidel(const SeidelCommandOptions& options, const GlobalOptions& global) {
  const Prescription lens = load_lens(options.lens, global);
  if (!lens.field && !options.field_angle_deg) {
    throw PrescriptionError("the lens \"" + lens.name + "\" states no field, and the Seidel sums need one (the chief ray): give --field-angle DEG");
  }
  const SeidelAnalysis seidel(lens, seidel_options_from(options));
  if (!options.png.empty()) write_picture(plot::plot_seidel_diagram(seidel, lens.name), options.png, options.lens, global);
  if (!options.json) {
    std::cout << lens.name << "\n\n" << seidel.to_string();
    std::cout << "\n  Born & Wolf coefficients: " << AberrationCoefficients::from(seidel).to_string() << "\n";
    return kExitOk;
  }
  std::cout << json_text(seidel_json(lens, seidel), 2) << "\n";
  return kExitOk;
}

}  // namespace lensmith::cli

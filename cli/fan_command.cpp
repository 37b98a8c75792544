// `lensmith fan`: tangential and sagittal transverse ray fans per field and wavelength; a table, one
// JSON object (docs/cli.md) and optionally a PNG picture.
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "lensmith/core/json_text.h"
#include "lensmith/report/json_report.h"
#include "lensmith/analysis/ray_fan.h"
#include "lensmith/core/units.h"
#include "lensmith/plot/analysis_plots.h"

namespace lensmith::cli {

int run_fan(const FanCommandOptions& options, const GlobalOptions& global) {
  const Prescription lens = load_lens(options.common.lens, global);
  const AnalysisContext context(lens, make_analysis_options(options.common));
  RayFanOptions fan_options;
  fan_options.samples = options.samples;
  const RayFan fan = compute_ray_fan(context, fan_options);
  if (!options.common.png.empty()) {
    write_picture(plot::plot_ray_fan(fan, make_plot_options(global)), options.common.png, options.common.lens, global);
  }
  if (options.common.json) {
    std::cout << json_text(fan_json(fan), 2) << "\n";
  } else {
    std::cout << fan.to_string();
  }
  return kExitOk;
}

}  // namespace lensmith::cli

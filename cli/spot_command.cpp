// `lensmith spot`: spot diagrams per field and wavelength with RMS and GEO radii; a table, one JSON
// object (docs/cli.md) and optionally a PNG picture.
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "lensmith/core/json_text.h"
#include "lensmith/report/json_report.h"
#include "json_output.h"
#include "lensmith/analysis/spot_diagram.h"
#include "lensmith/core/units.h"
#include "lensmith/plot/analysis_plots.h"

namespace lensmith::cli {

int run_spot(const SpotCommandOptions& options, const GlobalOptions& global) {
  const Prescription lens = load_lens(options.common.lens, global);
  const AnalysisContext context(lens, make_analysis_options(options.common));
  SpotOptions spot;
  if (options.random_rays) {
    spot.sampling.kind = PupilSampling::Kind::Random;
    spot.sampling.random_rays = *options.random_rays;
    spot.sampling.seed = options.seed;
  } else {
    spot.sampling.rings = options.rings;
  }
  const SpotDiagram diagram = compute_spot_diagram(context, spot);
  if (!options.common.png.empty()) {
    write_picture(plot::plot_spot_diagram(diagram, make_plot_options(global)), options.common.png, options.common.lens, global);
  }
  if (options.common.json) {
    std::cout << json_text(spot_json(diagram), 2) << "\n";
  } else {
    std::cout << diagram.to_string();
  }
  return kExitOk;
}

}  // namespace lensmith::cli

// `lensmith layout`: the lens's meridional section with a few real ray bundles, as a PNG (--png) or
// a short text summary (elements, stop, total track).
#include <iostream>

#include "commands.h"
#include "lensmith/analysis/lens_layout.h"
#include "lensmith/plot/layout_plot.h"

namespace lensmith::cli {

int run_layout(const LayoutCommandOptions& options, const GlobalOptions& global) {
  const Prescription lens = load_lens(options.common.lens, global);
  AnalysisOptions analysis = make_analysis_options(options.common);
  apply_layout_defaults(lens, !options.common.aim.empty(), options.common.field_angle_deg.has_value(), analysis);
  const AnalysisContext context(lens, analysis);
  LayoutOptions layout_options;
  layout_options.rays_per_field = options.rays;
  const LensLayout layout = compute_lens_layout(context, layout_options);
  if (!options.common.png.empty()) {
    write_picture(plot::plot_lens_layout(layout, make_plot_options(global)), options.common.png, options.common.lens, global);
  }
  std::cout << layout.to_string();
  return kExitOk;
}

}  // namespace lensmith::cli

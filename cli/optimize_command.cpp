// `lensmith optimize`: damped least squares on a merit file's variables and operands; the optimised lens as
// lensmith JSON, the before/after table (or --json), and the layouts before and after (--png).
#include <unistd.h>

#include <cstdio>
#include <iostream>

#include "commands.h"
#include "lensmith/analysis/lens_layout.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/json_text.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/text_file.h"
#include "lensmith/design/optimizer.h"
#include "lensmith/plot/layout_plot.h"
#include "lensmith/prescription/lens_json.h"
#include "lensmith/report/json_report.h"

namespace lensmith::cli {

namespace {

// The lens drawn as `lensmith layout` draws it, its title saying which stage it shows.
plot::Canvas layout_picture(Prescription lens, const std::string& title, const MeritFunction& merit, const GlobalOptions& global) {
  lens.name = title;
  AnalysisOptions analysis;
  analysis.max_field_angle_deg = merit.field_angle_deg;
  apply_layout_defaults(lens, /*aim_given=*/false, merit.field_angle_deg.has_value(), analysis);
  const AnalysisContext context(lens, analysis);
  return plot::plot_lens_layout(compute_lens_layout(context, LayoutOptions{}), make_plot_options(global));
}

}  // namespace

int run_optimize(const OptimizeCommandOptions& o, const GlobalOptions& global) {
  const std::string lens_file = o.lens.substr(0, o.lens.rfind('#'));
  ensure_not_an_input(o.output, {lens_file, o.merit});
  ensure_writable_location(o.output);
  if (!o.png.empty()) {
    ensure_not_an_input(o.png, {lens_file, o.merit, o.output});
    ensure_writable_location(o.png);
  }
  const Prescription lens = load_lens(o.lens, global);
  const MeritFunction merit = read_merit_function(o.merit);
  OptimizeOptions options;
  options.max_iterations = o.iterations;
  options.substitute_glass = !o.keep_model_glass;
  options.threads = o.threads;
  std::vector<OptimizeProgress> history;
  const bool show = !global.quiet && isatty(STDERR_FILENO);
  options.progress = [&](const OptimizeProgress& p) {
    history.push_back(p);
    if (show) {
      std::fprintf(stderr, "%s, iteration %3d: merit %.6g%s\n", p.stage.c_str(), p.iteration, p.merit, p.step_accepted ? "" : " (step rejected)");
    }
  };
  OptimizeResult result = optimize(lens, merit, options);
  result.result.notes = (result.result.notes.empty() ? "" : result.result.notes + " ") + "Optimised by lensmith optimize with the merit file " + o.merit +
                        ": merit " + format_rounded(result.before.merit, 6) + " -> " + format_rounded(result.after.merit, 6) + ".";
  write_file_atomically(o.output, write_lens_json(result.result));
  if (!o.png.empty()) {
    const plot::Canvas before = layout_picture(result.start, lens.name + " (start)", merit, global);
    const plot::Canvas after = layout_picture(result.result, lens.name + " (optimised)", merit, global);
    plot::Canvas both(std::max(before.width(), after.width()), before.height() + after.height());
    both.paste(before, 0, 0);
    both.paste(after, 0, before.height());
    write_picture(both, o.png, o.lens, global);
  }
  if (o.json) {
    std::cout << json_text(optimize_json(result, history), 2) << "\n";
  } else {
    std::cout << result.to_string();
  }
  report_written(o.output, global);
  return kExitOk;
}

}  // namespace lensmith::cli

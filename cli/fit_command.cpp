// `lensmith fit LENS`: fits the lens's ray mapping with polynomials (lens_fit.h), prints the held-out
// errors and the speed of the fit against exact tracing measured in the same run, and saves the fit.
#include <algorithm>
#include <iomanip>
#include <iostream>

#include "commands.h"
#include "lensmith/core/json_text.h"
#include "lensmith/report/json_report.h"
#include "json_output.h"
#include "lensmith/core/errors.h"
#include "lensmith/polyfit/lens_fit.h"
#include "lensmith/render/image_io.h"
#include "progress_bar.h"

namespace lensmith::cli {

std::shared_ptr<const LensFit> fit_for_models(const std::vector<RayModelKind>& models, const Camera& camera,
                                              const std::string& fit_file, const GlobalOptions& global) {
  const Prescription& lens = *camera.lens();
  if (std::find(models.begin(), models.end(), RayModelKind::Poly) == models.end()) {
    if (!fit_file.empty()) throw UsageError("--fit is for --model poly");
    return nullptr;
  }
  require_poly_model_lens(camera);
  if (!fit_file.empty()) {
    auto fit = std::make_shared<const LensFit>(LensFit::read(fit_file));
    fit->check_matches(lens);
    return fit;
  }
  ProgressBar bar("fitting " + (lens.name.empty() ? std::string("the lens") : lens.name), !global.quiet);
  auto fit = std::make_shared<const LensFit>(LensFit::fit(lens, lens_fit_options_for(camera), [&](double f) { bar.update(f); }));
  bar.finish();
  return fit;
}

int run_fit(const FitCommandOptions& o, const GlobalOptions& global) {
  LensFitOptions options;
  options.degree = o.degree;
  options.terms = o.terms;
  options.training_rays = o.training_rays;
  options.test_rays = o.test_rays;
  options.seed = o.seed;
  options.image_radius_mm = o.image_radius_mm;
  options.f_number = o.f_number;
  options.validate();
  if (!o.output.empty()) ensure_not_an_input(o.output, {o.lens});
  const Prescription lens = load_lens(o.lens, global);

  ProgressBar bar("fitting", !global.quiet);
  LensFit fit = LensFit::fit(lens, options, [&](double f) { bar.update(f); });
  fit.measure_speed(lens);
  bar.finish();
  if (!o.output.empty()) fit.write(o.output);

  const LensFitErrors& e = fit.errors();
  const LensFitTiming& t = fit.timing();
  const double speedup = t.exact_ns_per_ray / t.poly_ns_per_ray;
  if (o.json) {
    ojson j = fit_json(fit);
    if (!o.output.empty()) j["output"] = o.output;
    std::cout << json_text(j, 2) << "\n";
    return kExitOk;
  }
  std::cout << std::fixed;
  std::cout << "Polynomial fit of " << lens.name << "\n"
            << "  degree " << options.degree << ", at most " << fit.term_budget() << " terms per output ("
            << fit.sensor_to_outer().size() << " sensor->outer, " << fit.outer_to_sensor().size()
            << " outer->sensor), " << options.training_rays << " training rays, 380-780 nm\n"
            << (fit.symmetry() == LensSymmetry::kRotational
                    ? "  form: rotation invariants (a rotationally symmetric lens)\n"
                    : "  form: x and y components apart, the mirror symmetry of both sections kept (an anamorphic lens)\n");
  if (const auto core = coaxial_core(lens); core && core->lens.surfaces.size() != lens.surfaces.size()) {
    // A tilt-shift lens: the coordinate breaks at its ends are applied exactly where the fit is used.
    std::cout << "  fitted: surfaces " << core->first + 1 << "-" << core->first + core->lens.surfaces.size()
              << ", the elements without the coordinate breaks at the lens's ends (one fit serves every tilt and shift;"
              << " the surfaces below are numbered from the lens's surface " << core->first + 1 << ")\n";
  }
  std::cout << "  clipping surfaces:";
  for (const ClipSurface& c : fit.clip_surfaces()) std::cout << " " << c.surface;
  std::cout << " (stop first)\n"
            << "Held-out errors (" << e.test_rays << " rays passing the lens)\n"
            << std::setprecision(2) << "  outer pupil:  position RMS " << e.position_rms_um << " um, 99th percentile "
            << e.position_p99_um << " um; direction RMS " << std::setprecision(4) << e.direction_rms_mrad << " mrad\n"
            << std::setprecision(2) << "  sensor:       position RMS " << e.sensor_position_rms_um
            << " um, 99th percentile " << e.sensor_position_p99_um << " um; direction RMS " << std::setprecision(4)
            << e.sensor_direction_rms_mrad << " mrad\n"
            << std::setprecision(2) << "  stop:         position RMS " << e.stop_rms_um << " um\n"
            << std::setprecision(5) << "  transmittance RMS " << e.transmittance_rms << "; vignetting verdict differs for "
            << std::setprecision(3) << 100.0 * e.vignetting_mismatch << " % of sampled rays\n"
            << std::setprecision(2) << "Time: fit " << t.fit_seconds << " s; per ray (one thread, sensor -> outer) exact "
            << std::setprecision(1) << t.exact_ns_per_ray << " ns, polynomial " << t.poly_ns_per_ray << " ns ("
            << speedup << "x faster)\n";
  if (!o.output.empty()) report_written(o.output, global);
  return kExitOk;
}

}  // namespace lensmith::cli

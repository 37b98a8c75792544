// `lensmith wavefront`: OPD against the reference sphere per field and wavelength, its RMS and P-V and
// Zernike fit; `lensmith mtf`: the diffraction MTF from the same wavefront. Each a table, one JSON object
// (docs/cli.md) and optionally a PNG.
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "lensmith/analysis/mtf.h"
#include "lensmith/analysis/wavefront.h"
#include "lensmith/core/json_text.h"
#include "lensmith/plot/analysis_plots.h"
#include "lensmith/report/json_report.h"

namespace lensmith::cli {

int run_wavefront(const WavefrontCommandOptions& options, const GlobalOptions& global) {
  if (options.map_in_json && !options.common.json) throw UsageError("--json-map adds the map to --json: give --json too");
  WavefrontOptions wavefront_options;
  wavefront_options.grid = options.grid;
  wavefront_options.ordering = parse_zernike_ordering(options.zernike);
  wavefront_options.zernike_terms = options.terms.value_or(37);
  if (const int most = max_zernike_terms(wavefront_options.ordering); wavefront_options.zernike_terms > most) {
    throw UsageError("--terms " + std::to_string(wavefront_options.zernike_terms) + ": the " + options.zernike + " ordering has terms 1 to " +
                     std::to_string(most));
  }
  wavefront_options.validate();
  const Prescription lens = load_lens(options.common.lens, global);
  const AnalysisContext context(lens, make_analysis_options(options.common));
  const Wavefront wavefront = compute_wavefront(context, wavefront_options);
  if (!options.common.png.empty()) {
    write_picture(plot::plot_wavefront_map(wavefront, make_plot_options(global)), options.common.png, options.common.lens, global);
  }
  if (options.common.json) {
    std::cout << json_text(wavefront_json(wavefront, options.map_in_json), 2) << "\n";
  } else {
    std::cout << wavefront.to_string();
  }
  return kExitOk;
}

int run_mtf(const MtfCommandOptions& options, const GlobalOptions& global) {
  MtfOptions mtf_options;
  mtf_options.pupil_samples = options.pupil_samples;
  mtf_options.max_frequency_per_mm = options.max_frequency_per_mm.value_or(0.0);
  mtf_options.frequency_samples = options.frequency_samples;
  mtf_options.transmittance = options.fresnel;
  mtf_options.wavelength_weights = options.weights;
  mtf_options.validate();
  const Prescription lens = load_lens(options.common.lens, global);
  const AnalysisContext context(lens, make_analysis_options(options.common));
  if (options.through_focus_per_mm) {
    std::vector<double> shifts;
    for (int i = 0; i < options.focus_steps; ++i) shifts.push_back(-options.focus_range_mm + 2.0 * options.focus_range_mm * i / (options.focus_steps - 1));
    const ThroughFocusMtf through = compute_through_focus_mtf(context, *options.through_focus_per_mm, shifts, mtf_options);
    if (!options.common.png.empty()) {
      write_picture(plot::plot_through_focus_mtf(through, make_plot_options(global)), options.common.png, options.common.lens, global);
    }
    if (options.common.json) {
      std::cout << json_text(through_focus_mtf_json(through), 2) << "\n";
    } else {
      std::cout << through.to_string();
    }
    return kExitOk;
  }
  const Mtf mtf = compute_mtf(context, mtf_options);
  if (!options.common.png.empty()) {
    write_picture(plot::plot_mtf(mtf, make_plot_options(global)), options.common.png, options.common.lens, global);
  }
  if (options.common.json) {
    std::cout << json_text(mtf_json(mtf), 2) << "\n";
  } else {
    std::cout << mtf.to_string();
  }
  return kExitOk;
}

int run_psf(const PsfCommandOptions& options, const GlobalOptions& global) {
  if (options.grid_in_json && !options.common.json) throw UsageError("--json-grid adds the grid to --json: give --json too");
  PsfOptions psf_options;
  psf_options.pupil_samples = options.pupil_samples;
  psf_options.size = options.size;
  psf_options.transmittance = options.fresnel;
  psf_options.wavelength_weights = options.weights;
  try {
    psf_options.validate();
  } catch (const OptionsError& e) {
    throw UsageError(std::string("--size ") + std::to_string(options.size) + ": " + e.what());
  }
  const Prescription lens = load_lens(options.common.lens, global);
  const AnalysisContext context(lens, make_analysis_options(options.common));
  const Psf psf = compute_psf(context, psf_options);
  if (!options.common.png.empty()) {
    write_picture(plot::plot_psf(psf, make_plot_options(global)), options.common.png, options.common.lens, global);
  }
  if (options.common.json) {
    std::cout << json_text(psf_json(psf, options.grid_in_json), 2) << "\n";
  } else {
    std::cout << psf.to_string();
  }
  return kExitOk;
}

}  // namespace lensmith::cli

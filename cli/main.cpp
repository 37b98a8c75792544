// lensmith: command-line entry point. Parses options with CLI11, runs one subcommand, and maps
// exceptions to the exit codes documented in docs/cli.md (pbrt-v4 cmd/pbrt.cpp does the same).
#include <CLI/CLI.hpp>
#include <omp.h>

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <optional>
#include <string_view>

#include "commands.h"
#include "json_output.h"
#include "lensmith/core/json_text.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/termination_cleanup.h"
#include "lensmith/glass/glass_catalog.h"
#include "lensmith/prescription/lens_library.h"
#include "lensmith/trace/ray_aiming.h"

namespace lensmith::cli {

void print_diagnostics(const Diagnostics& diagnostics, const GlobalOptions& global) {
  if (global.quiet) return;
  for (const Diagnostic& d : diagnostics) std::cerr << d << "\n";
}

namespace {
// The lens the command loaded, so that a computation the lens cannot support (an afocal system, a field
// beyond its reach) names the file it came from.
std::string loaded_lens;
}  // namespace

Prescription load_lens(const std::string& lens, const GlobalOptions& global, bool resolve_field) {
  loaded_lens = lens;
  LensReadResult result = LensLibrary::load_path_or_name(lens);
  print_diagnostics(result.diagnostics, global);
  if (!resolve_field || !result.prescription.field || result.prescription.field->kind != FieldSpec::Kind::RealImageHeightMm) {
    return std::move(result.prescription);
  }
  Prescription resolved = resolve_real_image_height_field(result.prescription);
  if (!global.quiet) {
    std::cerr << "note: field: real image heights " << result.prescription.field->to_string() << " are the object field "
              << resolved.field->to_string() << " (real chief rays, " << format_rounded(resolved.primary_wavelength_nm(), 6)
              << " nm)\n";
  }
  return resolved;
}

void report_written(const std::string& what, const GlobalOptions& global) {
  if (!global.quiet) std::cerr << "wrote " << what << "\n";
}

void warn_about_aperture(const Camera& camera, const GlobalOptions& global) {
  // 5 % below the design value (about 1/7 stop): the design f-number rounded and typed back is not
  // a request to open the lens.
  constexpr double kMargin = 0.95;
  const double n = camera.f_number(), design = camera.design_f_number(), clear = camera.fastest_unclipped_f_number();
  if (global.quiet || camera.is_thin_lens() || !(n < kMargin * design)) return;
  std::cerr << "warning: f/" << format_rounded(n, 3) << " is faster than this lens's design aperture f/" << format_rounded(design, 3);
  if (clear > n) {
    // On the axis the clear apertures' first-order images are discs centred on the pupil: the share
    // that passes is the square of the f-number ratio.
    std::cerr << ": its clear apertures clip the axial beam, which passes about " << format_rounded(100.0 * (n / clear) * (n / clear), 2)
              << " % of the iris's area (the lens works at about f/" << format_rounded(clear, 3)
              << " on the axis, the rest is vignetting); f/" << format_rounded(clear, 3) << " is the fastest f-number they pass whole\n";
  } else {
    std::cerr << ": its aberrations at this aperture were not corrected by its designer (expect a softer, hazier picture)\n";
  }
}

int anamorphic_output_width(const Camera& camera, int width_px, bool desqueeze, const GlobalOptions& global) {
  const double squeeze = camera.squeeze();
  // Below this the lens does not squeeze: a round lens's 1, to rounding.
  constexpr double kRoundTolerance = 1e-9;
  if (std::abs(squeeze - 1.0) <= kRoundTolerance) {
    if (desqueeze && !global.quiet) std::cerr << "note: --desqueeze has no effect: the lens is not anamorphic\n";
    return 0;
  }
  // A squeeze below 1 (an x section with the longer focal length) stretches the sensor's picture instead.
  const int narrowed = std::max(1, static_cast<int>(std::lround(width_px / squeeze)));
  if (!global.quiet) {
    std::cerr << "note: anamorphic squeeze " << format_rounded(squeeze, 4) << ": ";
    if (desqueeze) {
      std::cerr << "written desqueezed, " << width_px << " px wide as the input (--desqueeze)\n";
    } else {
      std::cerr << "written squeezed as on the sensor, " << narrowed << " px wide (pixel aspect ratio "
                << format_rounded(static_cast<double>(width_px) / narrowed, 4) << "; --desqueeze for the input's " << width_px << ")\n";
    }
    // Where x focuses: noted when its depth of field would not reach the y section's focus plane,
    // taken as 2 % in inverse distance.
    constexpr double kSameFocus = 0.02;
    const double y_mm = camera.focus_distance_mm(), x_mm = camera.x_section_focus_distance_mm().value_or(y_mm);
    const double wy = std::isinf(y_mm) ? 0.0 : 1.0 / y_mm, wx = std::isinf(x_mm) ? 0.0 : 1.0 / x_mm;
    if (std::abs(wx - wy) > kSameFocus * std::max(wy, 1e-3)) {
      std::cerr << "note: the sensor focuses the y section at " << format_rounded(m_from_mm(y_mm), 4) << " m; the x section, whose focal "
                << "length is shorter, is then focused at " << (std::isinf(x_mm) ? std::string("infinity") : format_rounded(m_from_mm(x_mm), 4) + " m")
                << " (lensmith moves the sensor to focus; a real anamorphic focuses its cylinders too: not modelled)\n";
    }
  }
  return desqueeze ? 0 : narrowed;
}

// Numeric checks whose messages read as prose: "must be > 0, got -1", "must be between 0.5 and 512,
// got 600" (CLI11's own print the limits with six decimals, or 309 digits for "no limit").
CLI::Validator positive() {
  return CLI::Validator(
      [](std::string& text) {
        double v = 0.0;
        return CLI::detail::lexical_cast(text, v) && v > 0.0 && std::isfinite(v) ? std::string() : "must be > 0, got " + text;
      },
      "> 0", "positive");
}
CLI::Validator non_negative() {
  return CLI::Validator(
      [](std::string& text) {
        double v = 0.0;
        return CLI::detail::lexical_cast(text, v) && v >= 0.0 && std::isfinite(v) ? std::string() : "must be >= 0, got " + text;
      },
      ">= 0", "non-negative");
}
// lo < value < hi.
CLI::Validator open_range(double lo, double hi) {
  const std::string limits = "between " + format_rounded(lo, 8) + " and " + format_rounded(hi, 8) + " (exclusive)";
  return CLI::Validator(
      [lo, hi, limits](std::string& text) {
        double v = 0.0;
        return CLI::detail::lexical_cast(text, v) && v > lo && v < hi ? std::string() : "must be " + limits + ", got " + text;
      },
      format_rounded(lo, 8) + " < x < " + format_rounded(hi, 8), "open range");
}
CLI::Validator range(double lo, double hi) {
  const std::string limits = format_rounded(lo, 8) + " to " + format_rounded(hi, 8);
  return CLI::Validator(
      [lo, hi, limits](std::string& text) {
        double v = 0.0;
        return CLI::detail::lexical_cast(text, v) && v >= lo && v <= hi ? std::string() : "must be " + limits + ", got " + text;
      },
      limits, "range");
}

// A focus distance: metres > 0, or inf (CLI11's PositiveNumber refuses infinity).
CLI::Validator focus_distance_check() {
  return CLI::Validator(
      [](std::string& text) {
        double v = 0.0;
        return CLI::detail::lexical_cast(text, v) && v > 0.0 ? std::string() : "must be > 0 or inf, got " + text;
      },
      "M > 0 or inf", "focus distance");
}

// On a farm, "all cores" means the cores the scheduler gave this task, not the node's: a Slurm task
// (SLURM_JOB_ID set) runs as many threads as SLURM_CPUS_PER_TASK (sbatch --cpus-per-task), else as
// SLURM_CPUS_ON_NODE (what the job holds on this node). An explicit OMP_NUM_THREADS or --threads wins.
void use_the_allocations_cpus() {
  if (std::getenv("SLURM_JOB_ID") == nullptr || std::getenv("OMP_NUM_THREADS") != nullptr) return;
  for (const char* name : {"SLURM_CPUS_PER_TASK", "SLURM_CPUS_ON_NODE"}) {
    const char* text = std::getenv(name);
    const std::optional<double> n = text ? lensmith::parse_finite_number(text) : std::nullopt;
    if (n && *n >= 1 && *n <= 4096 && *n == std::floor(*n)) {
      omp_set_num_threads(static_cast<int>(*n));
      return;
    }
  }
}

}  // namespace lensmith::cli

int main(int argc, char** argv) {
  using namespace lensmith::cli;
  lensmith::remove_temporaries_on_termination();
  use_the_allocations_cpus();
  CLI::App app{"lensmith: real camera lenses, from prescription to bokeh"};
  app.require_subcommand(1);
  app.fallthrough();  // global flags such as --quiet may follow the subcommand
  app.set_version_flag("--version", "lensmith 0.1.0");
  GlobalOptions global;
  app.add_flag("-q,--quiet", global.quiet, "No warnings or progress on stderr");
  std::vector<std::string> glass_catalogs;
  app.add_option("--glass-catalog", glass_catalogs,
                 "A Zemax .agf (or lensmith .json) glass catalogue, or a folder of .agf, searched after the built-in ones; repeatable "
                 "(also LENSMITH_GLASS_CATALOGS, separated by ':'; docs/glass.md)")
      ->check(CLI::ExistingPath);

  InfoOptions info;
  CLI::App* info_cmd = app.add_subcommand("info", "First-order (paraxial) optics of a lens: focal lengths, cardinal points, pupils, f-number, ray tables");
  info_cmd->add_option("lens", info.lens, "Lens file (.json, .zmx, .seq, .dat, lentil.json#ID) or shipped lens name (see `lensmith lenses`)")->required();
  info_cmd->add_option("-w,--wavelength", info.wavelength_nm, "Wavelength, nm (default: the lens's primary wavelength; range 100-20000)")
      ->check(range(100.0, 20000.0));
  info_cmd->add_option("-d,--object-distance", info.object_distance_m,
                       "Distance from the object to the first lens vertex, metres (default: the lens's, usually infinity; > 0)")
      ->check(positive());
  info_cmd->add_flag("--json", info.json, "Print one JSON object (schema: docs/cli.md)");
  info_cmd->add_flag("--spectral", info.spectral, "Also print first-order values at 64 wavelengths from 380 to 780 nm");

  LensesOptions lenses;
  CLI::App* lenses_cmd = app.add_subcommand("lenses", "List the shipped lenses (or the entries of a lentil lens database)");
  lenses_cmd->add_option("--lentil", lenses.lentil_database, "List the entries of this lentil lenses.json instead")->check(CLI::ExistingFile);
  lenses_cmd->add_flag("--json", lenses.json, "Print a JSON array");

  ConvertOptions convert;
  CLI::App* convert_cmd = app.add_subcommand("convert", "Write a lens (any supported format) as a lensmith JSON lens file");
  convert_cmd->add_option("lens", convert.lens, "Lens file or shipped lens name")->required();
  convert_cmd->add_option("-o,--output", convert.output, "Output .json file (written atomically; never the input)")->required();
  convert_cmd->add_option("--scale-to-efl", convert.scale_to_efl_mm, "Scale every length so the EFL becomes this, mm (> 0)")
      ->check(positive());

  // Real-ray analyses (docs/cli.md, docs/analysis.md).
  const std::string lens_help = "Lens file (.json, .zmx, .seq, .dat, lentil.json#ID) or shipped lens name (see `lensmith lenses`)";
  const CLI::Validator pupil_check(
      [](std::string& text) { return check_pupil_text(text); }, "PX,PY", "pupil in the unit disc");
  const CLI::IsMember image_words({"prescribed", "paraxial"});
  const CLI::IsMember aim_words({"paraxial", "real"});
  const std::string aim_help =
      "Ray aiming: paraxial (at the paraxial entrance pupil, Zemax's \"ray aiming off\") or real (iterate onto the real stop); "
      "default: as the lens file says (real for a Zemax file with ray aiming on and for CODE V files, else paraxial)";

  TraceCommandOptions trace;
  CLI::App* trace_cmd = app.add_subcommand("trace", "Trace one real ray and print it at every surface and at the image plane");
  trace_cmd->add_option("lens", trace.lens, lens_help)->required();
  CLI::Option* trace_angle = trace_cmd->add_option("--field-angle", trace.field_angle_deg,
                                                   "Object-space field angle along y, degrees (default 0; -90 < DEG < 90)")
                                 ->check(open_range(-90.0, 90.0));
  CLI::Option* trace_height = trace_cmd->add_option("--object-height", trace.object_height_mm,
                                                    "Object height along y for a finite object, mm (instead of --field-angle)");
  CLI::Option* trace_relative = trace_cmd->add_option("--field", trace.relative_field,
                                                      "Field as a fraction of the lens's maximum field, 0 to 1 (instead of --field-angle)")
                                    ->check(range(0.0, 1.0));
  trace_angle->excludes(trace_height)->excludes(trace_relative);
  trace_height->excludes(trace_relative);
  trace_cmd->add_option("--pupil", trace.pupil, "Normalised pupil coordinate PX,PY in the unit disc (default 0,0: the chief ray)")
      ->check(pupil_check);
  trace_cmd->add_option("-w,--wavelength", trace.wavelength_nm, "Wavelength, nm (default: the lens's primary; 100-20000)")
      ->check(range(100.0, 20000.0));
  trace_cmd->add_option("--image", trace.image, "Image plane: prescribed (the lens's last thickness) or paraxial (paraxial focus)")
      ->check(image_words);
  trace_cmd->add_option("--aim", trace.aim, aim_help)->check(aim_words);
  trace_cmd->add_flag("--json", trace.json, "Print one JSON object (schema: docs/cli.md)");

  // Options of spot, fan and analyze.
  auto add_real_ray_options = [&](CLI::App* cmd, RealRayCommandOptions& o) {
    cmd->add_option("lens", o.lens, lens_help)->required();
    cmd->add_option("--fields", o.relative_fields, "Fields as fractions of the maximum field, comma separated, each 0 to 1 (default 0,0.7,1)")
        ->delimiter(',')
        ->check(range(0.0, 1.0));
    cmd->add_option("--field-angle", o.field_angle_deg,
                    "The object-space half field angle that field 1 means, degrees (0 < DEG < 90; default: the lens's field)")
        ->check(open_range(0.0, 90.0));
    cmd->add_option("-w,--wavelength", o.wavelengths_nm, "Wavelengths, nm, repeated or comma separated (default: the lens's; 100-20000)")
        ->delimiter(',')
        ->check(range(100.0, 20000.0));
    cmd->add_option("--image", o.image, "Image plane: prescribed (the lens's last thickness) or paraxial (paraxial focus)")
        ->check(image_words);
    cmd->add_option("--aim", o.aim, aim_help)->check(aim_words);
    cmd->add_option("--png", o.png, "Also write a picture to this PNG file (written atomically; never the input)");
    cmd->add_flag("--json", o.json, "Print one JSON object (schema: docs/cli.md)");
  };

  SpotCommandOptions spot;
  CLI::App* spot_cmd = app.add_subcommand("spot", "Spot diagrams per field and wavelength with RMS and GEO radii");
  add_real_ray_options(spot_cmd, spot.common);
  CLI::Option* spot_rings = spot_cmd->add_option("--rings", spot.rings, "Hexapolar rings (1 + 3 N (N + 1) rays; default 6 = 127 rays; 1-200)")
                                ->check(range(1, 200));
  CLI::Option* spot_random = spot_cmd->add_option("--random", spot.random_rays, "Uniform random pupil points instead, this many (1-1000000)")
                                 ->check(range(1, 1000000));
  spot_cmd->add_option("--seed", spot.seed, "Seed of --random (default 1; the same seed gives the same rays everywhere)")->needs(spot_random);
  spot_rings->excludes(spot_random);

  WavefrontCommandOptions wavefront;
  CLI::App* wavefront_cmd =
      app.add_subcommand("wavefront", "Wavefront (OPD against the reference sphere) per field and wavelength: RMS, P-V, Zernike fit, map");
  add_real_ray_options(wavefront_cmd, wavefront.common);
  wavefront_cmd->add_option("--grid", wavefront.grid, "Pupil samples across the map (default 64; 8-1024)")->check(range(8, 1024));
  wavefront_cmd->add_option("--zernike", wavefront.zernike, "Zernike ordering: fringe (default; Z1-Z37, not normalised) or standard (Noll, normalised)")
      ->check(CLI::IsMember({"fringe", "standard"}));
  wavefront_cmd->add_option("--terms", wavefront.terms, "Zernike terms fitted (default 37; fringe 1-37, standard 1-231)")->check(range(1, 231));
  wavefront_cmd->add_flag("--json-map", wavefront.map_in_json, "With --json: the OPD map's grid too (waves, row-major from py = -1)");

  MtfCommandOptions mtf;
  CLI::App* mtf_cmd = app.add_subcommand("mtf", "Diffraction MTF (FFT of the pupil function), tangential and sagittal per field, and the Strehl ratio");
  add_real_ray_options(mtf_cmd, mtf.common);
  mtf_cmd->add_option("--pupil-samples", mtf.pupil_samples, "Pupil grid across the pupil (default 64; 16-512)")->check(range(16, 512));
  mtf_cmd->add_option("--max-frequency", mtf.max_frequency_per_mm, "Highest frequency, cycles/mm (default: the diffraction cutoff; > 0)")
      ->check(positive());
  mtf_cmd->add_option("--frequencies", mtf.frequency_samples, "Points per curve (default 51; 2-1001)")->check(range(2, 1001));
  CLI::Option* through_focus = mtf_cmd->add_option("--through-focus", mtf.through_focus_per_mm,
                                                   "Instead: the MTF at this frequency (cycles/mm, > 0) against the image plane's shift")
                                   ->check(positive());
  mtf_cmd->add_option("--focus-range", mtf.focus_range_mm, "With --through-focus: shifts from -MM to +MM (default 0.1; > 0)")
      ->check(positive())
      ->needs(through_focus);
  mtf_cmd->add_option("--weights", mtf.weights, "Wavelength weights of the polychromatic MTF, one per wavelength, comma separated, each >= 0 (default: equal)")
      ->delimiter(',')
      ->check(non_negative());
  mtf_cmd->add_flag("--fresnel", mtf.fresnel, "Apodise the pupil by each ray's uncoated Fresnel transmittance (default: amplitude 1 where rays pass)");
  mtf_cmd->add_option("--focus-steps", mtf.focus_steps, "With --through-focus: shifts (default 21; 2-1001)")->check(range(2, 1001))->needs(through_focus);

  PsfCommandOptions psf;
  CLI::App* psf_cmd = app.add_subcommand("psf", "Diffraction PSF (FFT of the pupil function) per field, polychromatic, with the Strehl ratio");
  add_real_ray_options(psf_cmd, psf.common);
  psf_cmd->add_option("--pupil-samples", psf.pupil_samples, "Pupil grid across the pupil (default 64; 16-512)")->check(range(16, 512));
  psf_cmd->add_option("--size", psf.size, "PSF samples across (default 128; 8 to 4 x --pupil-samples, rounded up to a power of two)")
      ->check(range(8, 2048));
  psf_cmd->add_flag("--json-grid", psf.grid_in_json, "With --json: the intensity grid too");
  psf_cmd->add_option("--weights", psf.weights, "Wavelength weights of the polychromatic PSF, one per wavelength, comma separated, each >= 0 (default: equal)")
      ->delimiter(',')
      ->check(non_negative());
  psf_cmd->add_flag("--fresnel", psf.fresnel, "Apodise the pupil by each ray's uncoated Fresnel transmittance (default: amplitude 1 where rays pass)");

  SeidelCommandOptions seidel;
  CLI::App* seidel_cmd = app.add_subcommand("seidel", "Third-order (Seidel) aberrations per surface and summed, and Born & Wolf's B..F");
  seidel_cmd->add_option("lens", seidel.lens, "Lens file or shipped lens name")->required();
  seidel_cmd->add_option("-w,--wavelength", seidel.wavelength_nm, "Wavelength, nm (default: the lens's primary; 100-20000)")
      ->check(range(100.0, 20000.0));
  seidel_cmd->add_option("-d,--object-distance", seidel.object_distance_m, "Object to first vertex, metres (default: the lens's; > 0)")
      ->check(positive());
  seidel_cmd->add_option("--field-angle", seidel.field_angle_deg, "Maximum field angle, degrees (default: the lens's; 0-89.9)")
      ->check(range(0.0, 89.9));
  CLI::Option* seidel_epd = seidel_cmd->add_option("--epd", seidel.epd_mm, "Entrance-pupil diameter, mm (default: the lens's aperture; > 0)")
                                ->check(positive());
  seidel_cmd->add_option("--fstop", seidel.f_number, "Image-space F/# = EFL/EPD instead of --epd (> 0)")->check(positive())->excludes(seidel_epd);
  seidel_cmd->add_option("--png", seidel.png, "Also write the Seidel diagram (per-surface bar chart) to this PNG");
  seidel_cmd->add_flag("--json", seidel.json, "Print one JSON object (schema: docs/cli.md)");

  LayoutCommandOptions layout;
  CLI::App* layout_cmd = app.add_subcommand("layout", "The lens drawn in section with its stop, image plane and real ray bundles per field");
  layout_cmd->add_option("lens", layout.common.lens, lens_help)->required();
  layout_cmd->add_option("--fields", layout.common.relative_fields,
                         "Fields of the bundles as fractions of the maximum field, comma separated, each 0 to 1 (default 0,0.7,1)")
      ->delimiter(',')
      ->check(CLI::Range(0.0, 1.0));
  layout_cmd->add_option("--field-angle", layout.common.field_angle_deg, "The half field angle that field 1 means, degrees (default: the lens's)")
      ->check(CLI::Range(1e-9, 89.999999));
  layout_cmd->add_option("--rays", layout.rays, "Rays per bundle from pupil edge to edge (default 5; 1-101)")->check(CLI::Range(1, 101));
  layout_cmd->add_option("--aim", layout.common.aim, "Ray aiming: real (the default where the lens allows it: rays fill the real stop) or paraxial (the default for mirror systems and those with tilts or toroids)")->check(aim_words);
  layout_cmd->add_option("--png", layout.common.png, "Write the drawing to this PNG file (written atomically; never the input)");

  OptimizeCommandOptions optimize;
  CLI::App* optimize_cmd = app.add_subcommand("optimize", "Optimise a lens by damped least squares on a merit file's variables and operands (docs/optimize.md)");
  optimize_cmd->add_option("lens", optimize.lens, lens_help)->required();
  optimize_cmd->add_option("--merit", optimize.merit, "Merit file: variables, operands with targets or limits and weights (docs/optimize.md)")
      ->required()
      ->check(CLI::ExistingFile);
  optimize_cmd->add_option("-o,--output", optimize.output, "The optimised lens, a lensmith JSON lens file (written atomically; never an input)")->required();
  optimize_cmd->add_option("--png", optimize.png, "Write the layouts before and after to this PNG file");
  optimize_cmd->add_option("--iterations", optimize.iterations, "Most Levenberg-Marquardt iterations per stage (default 50; 1-10000)")->check(range(1, 10000));
  optimize_cmd->add_flag("--keep-model-glass", optimize.keep_model_glass,
                         "Keep the model glasses the glass variables chose (default: each replaced by the nearest catalogue glass, the rest re-optimised)");
  optimize_cmd->add_option("--threads", optimize.threads, "Threads for the derivatives (default 0 = all cores, or the CPUs a Slurm task was given)")->check(range(0, 4096));
  optimize_cmd->add_flag("--json", optimize.json, "Print one JSON object (schema: docs/cli.md)");

  FanCommandOptions fan;
  CLI::App* fan_cmd = app.add_subcommand("fan", "Transverse ray fans (ey against py, ex against px) per field and wavelength");
  add_real_ray_options(fan_cmd, fan.common);
  fan_cmd->add_option("--samples", fan.samples, "Pupil points per fan from -1 to 1, odd (default 41; 3-1001)")
      ->check(range(3, 1001))
      ->check(CLI::Validator(
          [](std::string& text) {
            int n = 0;
            return CLI::detail::lexical_cast(text, n) && n % 2 == 1 ? std::string()
                                                                     : "must be odd, so that the chief ray (py = 0) is traced; got " + text;
          },
          "ODD", "odd count"));

  AnalyzeCommandOptions analyze;
  CLI::App* analyze_cmd = app.add_subcommand(
      "analyze", "Distortion, field curves, chromatic focal shift, relative illumination or the unvignetted pupil");
  add_real_ray_options(analyze_cmd, analyze.common);
  analyze_cmd->add_option("--what", analyze.what, "distortion | field-curves | focal-shift | illumination | pupil")
      ->required()
      ->check(CLI::IsMember({"distortion", "field-curves", "focal-shift", "illumination", "pupil"}));
  analyze_cmd->add_option("--samples", analyze.samples,
                          "Field samples from 0 to 1 (default 21), or wavelength samples for focal-shift (default 41); 2-1001")
      ->check(range(2, 1001));
  analyze_cmd->add_option("--grid", analyze.grid, "Pupil grid cells across the diameter for illumination and pupil (default 64; 8-1024)")
      ->check(range(8, 1024));

  BokehCommandOptions bokeh;
  CLI::App* bokeh_cmd = app.add_subcommand(
      "bokeh", "Photograph an all-in-focus image and its depth through a lens: defocus, bokeh shape, aberrations");
  bokeh_cmd->add_option("--image", bokeh.image, "All-in-focus image: EXR/HDR linear radiance, or 8/16-bit sRGB")->required();
  bokeh_cmd->add_option("--depth", bokeh.depth, "Depth FILE[:CHANNEL] (default: the image's own Z, depth.Z or a layer's Depth.Z; a one-channel file is its depth)");
  bokeh_cmd->add_option("--depth-kind", bokeh.depth_kind, "z (planar, default) | distance (from the camera) | inverse (1/z)")
      ->check(CLI::IsMember({"z", "distance", "inverse"}));
  bokeh_cmd->add_option("--depth-unit", bokeh.depth_unit, "m (default) | cm | mm")->check(CLI::IsMember({"m", "cm", "mm"}));
  bokeh_cmd->add_option("--invalid-depth", bokeh.invalid_depth, "Depth pixels that are NaN, infinite-negative, zero or negative (inverse depth: NaN or negative): error naming the pixel (default) | far (infinitely far) | near (the nearest valid depth)")
      ->check(CLI::IsMember({"error", "far", "near"}));
  bokeh_cmd->add_option("-o,--output", bokeh.output, "Output: .exr (float, with metadata) or .png/.jpg/.tif (sRGB)")->required();
  CLI::Option* bokeh_lens = bokeh_cmd->add_option("--lens", bokeh.lens, "Lens file or shipped lens name (lensmith lenses)");
  CLI::Option* bokeh_thin = bokeh_cmd->add_flag("--thin-lens", bokeh.thin_lens, "An ideal thin lens instead of a prescription");
  bokeh_thin->excludes(bokeh_lens);
  bokeh_cmd->add_option("--focal-length", bokeh.focal_length_mm, "Thin-lens focal length, mm (> 0)")->check(positive())->needs(bokeh_thin);
  bokeh_cmd->add_option("--fstop", bokeh.f_number, "f-number (default: the lens's own; 0.5-512)")->check(range(0.5, 512.0));
  CLI::Option* bokeh_focus =
      bokeh_cmd->add_option("--focus", bokeh.focus_m, "Focus distance, metres from the lens's entrance pupil (the perspective centre; > 0, inf for infinity)")
          ->check(focus_distance_check());
  bokeh_cmd->add_option("--other-channels", bokeh.other_channels,
                        "An EXR input's channels besides R, G, B, A and Z (render passes) in an EXR output: keep (default: unchanged, in focus) | defocus (each through the picture's rays, without colour fringes) | drop")
      ->check(CLI::IsMember({"keep", "defocus", "drop"}));
  // Colour management (docs/color-management.md).
  bokeh_cmd->add_option("--ocio", bokeh.ocio_config, "OpenColorIO config for --input-colorspace/--output-colorspace (default: $OCIO)")
      ->check(CLI::ExistingFile);
  bokeh_cmd->add_option("--input-colorspace", bokeh.input_colorspace,
                        "The input picture's colour space in the OCIO config (e.g. ACEScg); default: linear Rec.709, no conversion");
  bokeh_cmd->add_option("--output-colorspace", bokeh.output_colorspace,
                        "The .exr output's colour space in the OCIO config (default: the input's when --input-colorspace is given, "
                        "else linear Rec.709)");
  bokeh_cmd->add_option("--working-colorspace", bokeh.working_colorspace,
                        "The config's linear Rec.709 colour space, for configs without an aces_interchange role (OCIO 1 configs)");
  bokeh_cmd->add_flag("--keep-depth", bokeh.keep_depth,
                      "Write the input's depth (planar metres from the entrance pupil, inf for the sky) as the Z channel of an .exr output");
  bokeh_cmd->add_flag("--desqueeze", bokeh.desqueeze,
                      "An anamorphic lens's picture desqueezed, at the input's width and framing, instead of squeezed as on the sensor "
                      "(width / squeeze, the EXR's pixelAspectRatio the squeeze)");
  bokeh_cmd->add_option("--focus-pixel", bokeh.focus_pixel, "Focus on the depth at this pixel of the input, X,Y (0,0 = top left), instead of --focus")
      ->excludes(bokeh_focus);
  bokeh_cmd->add_option("--sensor-width", bokeh.sensor_width_mm, "Sensor width of the input image's pinhole camera, mm (default: the EXR's lensmith:sensor_width_mm, else 36)")
      ->check(positive());
  CLI::Option* bokeh_pf = bokeh_cmd->add_option("--pinhole-focal-length", bokeh.pinhole_focal_length_mm,
                                                "Focal length of the input's pinhole camera, mm (default: the EXR's lensmith:focal_length_mm, else the lens EFL)")
                              ->check(positive());
  bokeh_cmd->add_option("--hfov", bokeh.hfov_deg, "Horizontal field of view of the input image, degrees (instead of the focal length)")
      ->check(range(0.01, 179.99))->excludes(bokeh_pf);
  CLI::Option* bokeh_blades = bokeh_cmd->add_option("--blades", bokeh.blades, "Straight iris blades (3-64; default: a circular iris)")
                                  ->check(range(3, 64));
  bokeh_cmd->add_option("--blade-rotation", bokeh.blade_rotation_deg, "Rotation of the blade polygon, degrees")->needs(bokeh_blades);
  bokeh_cmd->add_option("--aperture-image", bokeh.aperture_image, "Aperture transmission from a picture over the pupil square")
      ->excludes(bokeh_blades);
  bokeh_cmd->add_option("--model", bokeh.model, "thin | paraxial | seidel (default) | poly | exact")
      ->check(CLI::IsMember({"thin", "paraxial", "seidel", "poly", "exact"}));
  bokeh_cmd->add_option("--seidel-coefficients", bokeh.seidel_coefficients,
                        "seidel model: fitted (default: third-order terms fitted per field to the real rays) | sums (the Seidel sums, Asberg's method as published)")
      ->check(CLI::IsMember({"fitted", "sums"}));
  bokeh_cmd->add_option("--fit", bokeh.fit, "Fit file for --model poly (lensmith fit -o); default: fit the lens in this run")
      ->check(CLI::ExistingFile);
  bokeh_cmd->add_option("--method", bokeh.method,
                        "scatter (default: every pixel scattered through the ray model, depth-layered) | multiview (Lee et al. 2009: "
                        "per pixel --samples lens rays traced through the layered scene; for deep input) | lightfield (Yu et al. "
                        "2010: the picture warped to --views pupil points through the ray model, nearest wins, views averaged) | ewa "
                        "(Krivanek et al. 2003: every pixel a Gaussian splat widened by the lens's blur, level of detail, A-buffer) | gather (Jimenez 2014: "
                        "half-resolution ring gather over tiles of nearest depth and largest blur, foreground over background; with "
                        "--hidden trace --scene FILE, Tan et al. 2022's rays traced into the scene where a ray mask says)")
      ->check(CLI::IsMember({"scatter", "multiview", "lightfield", "ewa", "gather"}));
  CLI::Option* bokeh_samples =
      bokeh_cmd->add_option("--samples", bokeh.samples, "multiview: lens rays per output pixel (1-4096, default 32)")->check(range(1, 4096));
  CLI::Option* bokeh_layers =
      bokeh_cmd->add_option("--layers", bokeh.layers, "multiview: depth layers, evenly spaced in signed blur (1-64, default 8)")->check(range(1, 64));
  CLI::Option* bokeh_ray_grid =
      bokeh_cmd->add_option("--ray-grid", bokeh.ray_grid_px,
                            "multiview: lens rays computed every this many pixels and interpolated between (1-64, default 16; 1 = every pixel)")
          ->check(range(1, 64));
  CLI::Option* bokeh_cones = bokeh_cmd->add_flag(
      "--no-cone-tracing", bokeh.no_cone_tracing,
      "multiview: each lens ray sees one pixel where it hits, not the mean over its cone (Lee et al.'s approximate cone tracing, on by default)");
  CLI::Option* bokeh_views =
      bokeh_cmd->add_option("--views", bokeh.views, "lightfield: views, one per pupil point (1-1024, default 36 as Yu et al.)")->check(range(1, 1024));
  CLI::Option* bokeh_mip = bokeh_cmd->add_flag(
      "--no-mip-filter", bokeh.no_mip_filter,
      "lightfield: read each view's colour from its pixel, not from the mipmap window of its share of the blur (Yu et al.'s pre-filter, on by default)");
  CLI::Option* bokeh_circular = bokeh_cmd->add_flag(
      "--circular-splats", bokeh.circular_splats,
      "ewa: circular Gaussians of the circle of confusion at the pinhole position (Krivanek et al.'s kernel), not the lens's PSF covariance, centroid and vignetting");
  CLI::Option* bokeh_lod = bokeh_cmd->add_flag(
      "--no-level-of-detail", bokeh.no_level_of_detail, "ewa: every pixel its own splat (no coarser surfels where the blur is large: slower as blur grows)");
  CLI::Option* bokeh_rings =
      bokeh_cmd->add_option("--rings", bokeh.rings, "gather: rings of taps, 3 (default: Jimenez's 48 taps) or 4 (Tan et al.'s 80)")
          ->check(CLI::IsMember({3, 4}));
  CLI::Option* bokeh_median = bokeh_cmd->add_flag("--no-median", bokeh.no_median, "gather: leave out the 3 x 3 median postfilter");
  CLI::Option* bokeh_scene = bokeh_cmd->add_option("--scene", bokeh.scene,
                                                   "gather --hidden trace: the lensmith-scene JSON file the picture is the pinhole render of")
                                 ->check(CLI::ExistingFile);
  CLI::Option* bokeh_trace_rays =
      bokeh_cmd->add_option("--trace-rays", bokeh.trace_rays, "gather --hidden trace: most rays per half-resolution pixel, a quarter through each of its pixels (1-4096, default 256)")
          ->check(range(1, 4096));
  std::vector<CLI::Option*> bokeh_scatter_only;
  CLI::Option* bokeh_hidden =
      bokeh_cmd->add_option("--hidden", bokeh.hidden,
                            "Background hidden behind foreground edges: extend (default) | stretch (scatter); trace (gather: Tan et al.'s "
                            "hybrid, exact rays into --scene where the picture cannot know)")
          ->check(CLI::IsMember({"extend", "stretch", "trace"}));
  bokeh_scatter_only.push_back(bokeh_cmd->add_option("--edge-pixels", bokeh.edge_pixels,
                        "Anti-aliased depth-edge pixels: split (default: between their two surfaces by colour) | keep (at their depth)")
      ->check(CLI::IsMember({"split", "keep"})));
  bokeh_cmd->add_flag("--no-vignetting", bokeh.no_vignetting,
                      "Every point as bright as on the axis: no cos^4-type falloff, no darkening where clear apertures clip "
                      "(the bokeh keeps its cat's-eye shape)");
  bokeh_scatter_only.push_back(bokeh_cmd->add_flag("--no-shape-reuse", bokeh.no_shape_reuse,
                      "Map every pixel's footprint on its own (paraxial, Seidel; slower, for checking). By default a pixel whose "
                      "footprint differs from its row neighbour's by under 1/16 px beyond a move draws that neighbour's mapped shape"));
  bokeh_scatter_only.push_back(bokeh_cmd->add_flag("--rays-per-pixel", bokeh.rays_per_pixel,
                      "exact, poly: aim and trace every pixel's footprint rays itself (much slower, for checking). By default a "
                      "rotationally symmetric lens's rays are interpolated from a table every 8 px of field and 1 px of blur"));
  bokeh_scatter_only.push_back(bokeh_cmd->add_flag("--mesh-footprints", bokeh.mesh_footprints,
                      "exact, poly: deposit every footprint's mesh triangles (about ten times slower, for checking). By default "
                      "each footprint is drawn from a light image of its table node, turned to its azimuth"));
  bokeh_scatter_only.push_back(bokeh_cmd->add_flag("--timings", bokeh.timings,
                      "Print the wall time of each stage (reading, the render's stages, writing) to stderr, also with --quiet"));
  bokeh_cmd->add_flag("--no-spectral", bokeh.no_spectral, "Trace every ray at 587.6 nm and keep RGB as it is (no colour fringes)");
  bokeh_cmd->add_option("--spectral-samples", bokeh.spectral_samples, "Wavelengths of the spectral quadrature (3-64, default 16)")
      ->check(range(3, 64));
  bokeh_cmd->add_option("--highlight-gain", bokeh.highlight_gain, "8/16-bit inputs: boost clipped highlights up to this factor (>= 1; default 1 = off)")
      ->check(range(1.0, 1.0e6));
  bokeh_cmd->add_option("--highlight-threshold", bokeh.highlight_threshold, "Encoded value from which a channel counts as clipped (default 0.98)")
      ->check(range(0.5, 1.0));
  bokeh_scatter_only.push_back(bokeh_cmd->add_option("--layer-spacing", bokeh.layer_spacing_px, "Depth-layer step in signed blur diameter, px (default 2)")
      ->check(range(0.1, 1000.0)));
  bokeh_scatter_only.push_back(bokeh_cmd->add_option("--subrows", bokeh.subrows, "Sub-rows per pixel of the scatter (1-16, default 4)")->check(range(1, 16)));
  bokeh_scatter_only.push_back(bokeh_cmd->add_option("--max-blur", bokeh.max_blur_px, "Largest blur diameter, px; nearer points are clamped (default 1000)")
      ->check(range(1.0, 1.0e6)));
  bokeh_cmd->add_option("--threads", bokeh.threads, "Threads (default 0 = all cores, or the CPUs a Slurm task was given)")->check(range(0, 4096));
  CLI::Option* bokeh_frames = bokeh_cmd->add_option(
      "--frames", bokeh.frames,
      "Render a shot: these frames (1001-1100, 1001-1100x2, 1,5,10-20) of the sequences --image, --depth and -o name "
      "(shot.####.exr, shot.%04d.exr, shot.@@@@.exr; docs/sequences.md)");
  bokeh_cmd->add_option("--chunk", bokeh.chunk, "With --frames: only chunk I (0-based) of N contiguous chunks of the frames, I/N (a farm task)")
      ->needs(bokeh_frames);
  bokeh_cmd->add_option("--curves", bokeh.curves,
                        "With --frames: per-frame camera values from keyframes, a .json or .csv file of focus_m, fstop, focal_length_mm "
                        "(thin lens), pinhole_focal_length_mm curves")
      ->needs(bokeh_frames)->check(CLI::ExistingFile);
  bokeh_cmd->add_flag("--skip-existing", bokeh.skip_existing, "With --frames: leave frames whose output exists (a resumed shot)")
      ->needs(bokeh_frames);
  bokeh_cmd->add_flag("--list-frames", bokeh.list_frames,
                      "With --frames: print the frames this command would render (after --chunk), one per line, and render nothing "
                      "(checks the sequence options; farm scripts count frames with it)")
      ->needs(bokeh_frames);

  ValidateCommandOptions validate;
  CLI::App* validate_cmd = app.add_subcommand(
      "validate", "How close the paraxial, Seidel and poly models come to the exact tracer: PSF metrics, pictures, a report");
  validate_cmd->add_option("lens", validate.lens, "Lens file or shipped lens name")->required();
  validate_cmd->add_option("--fstop", validate.f_number, "f-number (default: the lens's own; 0.5-512)")->check(range(0.5, 512.0));
  validate_cmd->add_option("--focus", validate.focus_m, "Focus distance, metres from the entrance pupil (default 3; inf allowed)")->check(focus_distance_check());
  validate_cmd->add_option("--out", validate.out, "Directory for report.md and psf.png (default ./validation)");
  validate_cmd->add_option("--models", validate.models, "Models to compare with exact (default paraxial seidel; also poly)")
      ->check(CLI::IsMember({"paraxial", "seidel", "poly"}));
  validate_cmd->add_option("--seidel-coefficients", validate.seidel_coefficients,
                           "seidel model: fitted (default: third-order terms fitted per field to the real rays) | sums (the Seidel sums, Asberg's method as published)")
      ->check(CLI::IsMember({"fitted", "sums"}));
  validate_cmd->add_option("--fit", validate.fit, "Fit file for the poly model (lensmith fit -o); default: fit the lens in this run")
      ->check(CLI::ExistingFile);
  validate_cmd->add_option("--width", validate.width_px, "Frame width the fields refer to, px (default 1920)")->check(range(16, 65536));
  validate_cmd->add_option("--height", validate.height_px, "Frame height, px (default 1080)")->check(range(16, 65536));
  validate_cmd->add_option("--pupil-samples", validate.pupil_samples, "Pupil grid per axis for each PSF (default 96; 2-512)")
      ->check(range(2, 512));
  validate_cmd->add_option("--min-overlap", validate.min_overlap, "Fail (exit 6) when a model's worst PSF overlap is below this (0-1)")
      ->check(range(0.0, 1.0));
  validate_cmd->add_option("--scene", validate.scenes, "Analytic scene (JSON) for the image-level comparison; repeatable")
      ->check(CLI::ExistingFile);
  validate_cmd->add_option("--image-width", validate.image_width_px, "Width of the image-level renders, px (default 320)")
      ->check(range(16, 8192));
  validate_cmd->add_option("--image-height", validate.image_height_px, "Height of the image-level renders, px (default 180)")
      ->check(range(16, 8192));
  validate_cmd->add_option("--image-layers", validate.image_layers,
                            "Also score each model on the scene as layered (deep) input of this many peeled layers (default 4; 0: the flat picture only)")
      ->check(range(0, 16));
  validate_cmd->add_option("--image-methods", validate.image_methods,
                           "Depth-of-field methods scored on each scene: scatter, multiview, lightfield, ewa, gather (default all five)")
      ->check(CLI::IsMember({"scatter", "multiview", "lightfield", "ewa", "gather"}));
  validate_cmd->add_option("--image-views", validate.image_views, "Views of the lightfield method (default 36)")->check(range(1, 1024));
  validate_cmd->add_option("--image-trace-rays", validate.image_trace_rays,
                           "Most rays per half-resolution pixel of the gather method's hybrid run (Tan et al.; default 256)")
      ->check(range(1, 4096));
  validate_cmd->add_option("--image-samples", validate.image_samples, "Lens rays per pixel of the multiview method (default 32)")
      ->check(range(1, 4096));
  validate_cmd->add_option("--image-spp", validate.image_spp, "Samples per pixel of the ground truth (default 64)")
      ->check(range(1, 1 << 20));
  validate_cmd->add_option("--min-edge-psnr", validate.min_edge_psnr_db, "Fail (exit 6) when a model's depth-edge PSNR is below this, dB");
  validate_cmd->add_option("--max-centroid-offset", validate.max_centroid_offset_um,
                           "Fail (exit 6) when a model's largest centroid offset exceeds this, um")
      ->check(positive());

  FitCommandOptions fit;
  CLI::App* fit_cmd = app.add_subcommand(
      "fit", "Fit the lens's ray mapping with polynomials (polynomial optics): held-out errors, speed, a fit file");
  fit_cmd->add_option("lens", fit.lens, "Lens file or shipped lens name")->required();
  fit_cmd->add_option("--degree", fit.degree, "Highest total degree of a term (1-11, default 7)")->check(range(1, 11));
  fit_cmd->add_option("--terms", fit.terms, "Term budget per output (1-1000; default: 5 per surface less 12, within 12-40)")
      ->check(range(1, 1000));
  fit_cmd->add_option("--training-rays", fit.training_rays, "Rays the fit is made from (200-10000000, default 30000)")
      ->check(range(200, 10000000));
  fit_cmd->add_option("--test-rays", fit.test_rays, "Held-out rays the errors are measured on (100-10000000, default 10000)")
      ->check(range(100, 10000000));
  fit_cmd->add_option("--seed", fit.seed, "Seed of the training rays (default 2016; test rays use another stream)");
  fit_cmd->add_option("--image-radius", fit.image_radius_mm,
                      "Radius on the sensor plane the fit covers, mm (default 24.9: a 36 x 24 frame plus 15 %)")
      ->check(positive());
  fit_cmd->add_option("--fstop", fit.f_number, "Widest f-number the fit serves (default: the lens's own; 0.5-512)")
      ->check(range(0.5, 512.0));
  fit_cmd->add_option("-o,--output", fit.output, "Write the fit here (lensmith-fit JSON; docs/polyfit.md)");
  fit_cmd->add_flag("--json", fit.json, "Print one JSON object (schema: docs/cli.md)");

  SceneRenderOptions scene_render;
  CLI::App* scene_cmd = app.add_subcommand("scene", "Analytic scenes (docs/scene-format.md): render them through a pinhole or a lens");
  scene_cmd->require_subcommand(1);
  CLI::App* scene_render_cmd = scene_cmd->add_subcommand(
      "render", "All-in-focus picture and depth (--pinhole), or the ground truth through a lens (--lens, --thin-lens)");
  scene_render_cmd->add_option("scene", scene_render.scene, "Scene file (lensmith-scene JSON)")->required()->check(CLI::ExistingFile);
  scene_render_cmd->add_option("-o,--output", scene_render.output, "Output: .exr (float, with metadata) or .png/.jpg/.tif (sRGB)")
      ->required();
  CLI::Option* scene_pinhole = scene_render_cmd->add_flag("--pinhole", scene_render.pinhole, "Render through a pinhole (all in focus)");
  CLI::Option* scene_lens = scene_render_cmd->add_option("--lens", scene_render.lens, "Render through this lens: file or shipped name (exact tracing)");
  CLI::Option* scene_thin = scene_render_cmd->add_flag("--thin-lens", scene_render.thin_lens, "Render through an ideal thin lens (needs --focal-length, --fstop)");
  scene_pinhole->excludes(scene_lens)->excludes(scene_thin);
  scene_lens->excludes(scene_thin);
  CLI::Option* scene_depth =
      scene_render_cmd->add_option("--depth", scene_render.depth, "With --pinhole: also write the planar depth, float EXR channel Z, metres")
          ->needs(scene_pinhole);
  scene_render_cmd
      ->add_option("--layers", scene_render.layers,
                   "With --pinhole: a deep OpenEXR (-o .exr) of the N nearest surfaces along every ray, depth-peeled (1-16)")
      ->check(CLI::Range(1, 16))
      ->needs(scene_pinhole)
      ->excludes(scene_depth);
  scene_render_cmd->add_option("--focal-length", scene_render.focal_length_mm, "Thin-lens focal length, mm (> 0)")
      ->check(positive())->needs(scene_thin);
  // Options of renders through a lens: meaningless for a pinhole.
  const std::vector<CLI::Option*> lens_only{
      scene_render_cmd->add_option("--fstop", scene_render.f_number, "f-number (default: the lens's own; 0.5-512)")
          ->check(range(0.5, 512.0)),
      scene_render_cmd->add_option("--focus", scene_render.focus_m, "Focus distance, metres from the entrance pupil (> 0; inf)")
          ->check(focus_distance_check()),
      scene_render_cmd->add_option("--spp", scene_render.spp, "Samples per pixel (default 64; 1-1048576)")->check(range(1, 1 << 20)),
      scene_render_cmd->add_option("--noise-target", scene_render.noise_target,
                                   "Double the samples until the estimated mean relative error is below this (> 0)")
          ->check(positive()),
      scene_render_cmd->add_option("--max-spp", scene_render.max_spp, "Most samples per pixel with --noise-target (>= --spp; default 4096 or --spp if larger)")
          ->check(range(1, 1 << 20)),
      scene_render_cmd->add_option("--seed", scene_render.seed, "Random seed (default 1; the same seed gives the same image)"),
      scene_render_cmd->add_flag("--no-spectral", scene_render.no_spectral, "Trace every ray at 587.6 nm and keep RGB as it is"),
      scene_render_cmd->add_option("--spectral-samples", scene_render.spectral_samples, "Wavelengths of the spectral quadrature (3-64, default 16)")
          ->check(range(3, 64)),
      scene_render_cmd->add_flag("--desqueeze", scene_render.desqueeze,
                                 "An anamorphic lens's picture desqueezed, --width px wide as framed, instead of squeezed as on the sensor "
                                 "(width / squeeze, the EXR's pixelAspectRatio the squeeze)")};
  for (CLI::Option* option : lens_only) option->excludes(scene_pinhole);
  scene_render_cmd->add_option("--width", scene_render.width_px, "Image width, px (default 640)")->check(range(1, 65536));
  scene_render_cmd->add_option("--height", scene_render.height_px, "Image height, px (default 360)")->check(range(1, 65536));
  scene_render_cmd->add_option("--sensor-width", scene_render.sensor_width_mm, "Sensor width of the pinhole framing, mm (default 36)")
      ->check(positive());
  scene_render_cmd->add_option("--pinhole-focal-length", scene_render.pinhole_focal_length_mm,
                               "Pinhole focal length of the framing, mm (default: the lens EFL, the thin lens's focal length; 50 with --pinhole)")
      ->check(positive());
  scene_render_cmd->add_option("--threads", scene_render.threads, "Threads (default 0 = all cores, or the CPUs a Slurm task was given)")->check(range(0, 4096));

  // Under --json an error is also one JSON object on stdout, so that a script reading stdout sees
  // it: {"error": {"exit_code": N, "message": "..."}}.
  bool json = false;
  for (int i = 1; i < argc; ++i) json = json || std::string_view(argv[i]) == "--json";
  auto fail = [json](int code, const std::string& message) {
    std::cerr << "lensmith: " << message << "\n";
    if (json) std::cout << lensmith::json_text(ojson{{"error", {{"exit_code", code}, {"message", message}}}}, 2) << "\n";
    return code;
  };
  // The first word that is not an option names the subcommand.
  for (int i = 1; i < argc; ++i) {
    const std::string_view word = argv[i];
    if (word == "--glass-catalog") {  // the global option that takes a value
      ++i;
      continue;
    }
    if (word.empty() || word.front() == '-') continue;
    std::string names;
    bool known = false;
    for (const CLI::App* sub : app.get_subcommands({})) {
      known = known || sub->get_name() == word;
      names += (names.empty() ? "" : ", ") + sub->get_name();
    }
    if (!known) return fail(kExitUsage, "unknown subcommand '" + std::string(word) + "'; the subcommands are " + names);
    break;
  }

  // CLI11 drops the empty piece of "--fields 0,,1": refuse it rather than read two fields.
  for (int i = 1; i < argc; ++i) {
    const std::string_view word = argv[i];
    std::string_view value;
    if (word == "--fields" && i + 1 < argc) value = argv[i + 1];
    if (word.rfind("--fields=", 0) == 0) value = word.substr(9);
    if (!value.empty() && (value.front() == ',' || value.back() == ',' || value.find(",,") != std::string_view::npos)) {
      return fail(kExitUsage, "--fields " + std::string(value) + ": an empty entry between commas; give each field, e.g. 0,0.7,1");
    }
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    if (json) std::cout << lensmith::json_text(ojson{{"error", {{"exit_code", kExitUsage}, {"message", e.what()}}}}, 2) << "\n";
    app.exit(e);
    return kExitUsage;
  }

  try {
    if (!glass_catalogs.empty()) lensmith::GlassCatalog::add_user_catalogs(glass_catalogs);
    if (*info_cmd) return run_info(info, global);
    if (*lenses_cmd) return run_lenses(lenses, global);
    if (*convert_cmd) return run_convert(convert, global);
    if (*seidel_cmd) return run_seidel(seidel, global);
    if (*trace_cmd) return run_trace(trace, global);
    if (*spot_cmd) return run_spot(spot, global);
    if (*fan_cmd) return run_fan(fan, global);
    if (*wavefront_cmd) return run_wavefront(wavefront, global);
    if (*mtf_cmd) return run_mtf(mtf, global);
    if (*psf_cmd) return run_psf(psf, global);
    if (*layout_cmd) return run_layout(layout, global);
    if (*optimize_cmd) return run_optimize(optimize, global);
    if (*analyze_cmd) return run_analyze(analyze, global);
    if (*bokeh_cmd) {
      // Options of one method given to the other are an error, not silently ignored.
      for (CLI::Option* option : bokeh_scatter_only) {
        if (option->count() > 0) bokeh.scatter_options.push_back(option->get_name());
      }
      for (CLI::Option* option : {bokeh_samples, bokeh_layers, bokeh_ray_grid, bokeh_cones}) {
        if (option->count() > 0) bokeh.multiview_options.push_back(option->get_name());
      }
      for (CLI::Option* option : {bokeh_views, bokeh_mip}) {
        if (option->count() > 0) bokeh.lightfield_options.push_back(option->get_name());
      }
      for (CLI::Option* option : {bokeh_circular, bokeh_lod}) {
        if (option->count() > 0) bokeh.ewa_options.push_back(option->get_name());
      }
      for (CLI::Option* option : {bokeh_rings, bokeh_median, bokeh_scene, bokeh_trace_rays}) {
        if (option->count() > 0) bokeh.gather_options.push_back(option->get_name());
      }
      // --hidden is scatter's (extend, stretch) and gather's (trace).
      if (bokeh_hidden->count() > 0 && bokeh.method != "gather") bokeh.scatter_options.push_back(bokeh_hidden->get_name());
      return bokeh.frames.empty() ? run_bokeh(bokeh, global) : run_bokeh_sequence(bokeh, global);
    }
    if (*validate_cmd) return run_validate(validate, global);
    if (*scene_render_cmd) return run_scene_render(scene_render, global);
    if (*fit_cmd) return run_fit(fit, global);
  } catch (const lensmith::UsageError& e) {
    return fail(kExitUsage, e.what());
  } catch (const lensmith::ComputationError& e) {
    const std::string message = e.what();
    const bool names_lens = loaded_lens.empty() || message.find(loaded_lens) != std::string::npos;
    return fail(kExitComputation, names_lens ? message : loaded_lens + ": " + message);
  } catch (const lensmith::IoError& e) {
    return fail(kExitIo, e.what());
  } catch (const lensmith::Error& e) {
    return fail(kExitInput, e.what());
  } catch (const std::exception& e) {
    return fail(kExitInternal, std::string("internal error (please report it with the command line): ") + e.what());
  }
  return kExitUsage;
}

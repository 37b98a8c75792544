// lensmith: command-line entry point. Parses options with CLI11, runs one subcommand, and maps
// exceptions to the exit codes documented in docs/cli.md (pbrt-v4 cmd/pbrt.cpp does the same).
#include <CLI/CLI.hpp>

#include <iostream>

#include "commands.h"
#include "lensmith/core/errors.h"
#include "lensmith/prescription/lens_library.h"

namespace lensmith::cli {

void print_diagnostics(const Diagnostics& diagnostics, const GlobalOptions& global) {
  if (global.quiet) return;
  for (const Diagnostic& d : diagnostics) std::cerr << d << "\n";
}

Prescription load_lens(const std::string& lens, const GlobalOptions& global) {
  LensReadResult result = LensLibrary::load_path_or_name(lens);
  print_diagnostics(result.diagnostics, global);
  return std::move(result.prescription);
}

}  // namespace lensmith::cli

int main(int argc, char** argv) {
  using namespace lensmith::cli;
  CLI::App app{"lensmith: real camera lenses, from prescription to bokeh"};
  app.require_subcommand(1);
  app.fallthrough();  // global flags such as --quiet may follow the subcommand
  app.set_version_flag("--version", "lensmith 0.1.0");
  GlobalOptions global;
  app.add_flag("-q,--quiet", global.quiet, "No warnings or progress on stderr");

  InfoOptions info;
  CLI::App* info_cmd = app.add_subcommand("info", "First-order (paraxial) optics of a lens: focal lengths, cardinal points, pupils, f-number, ray tables");
  info_cmd->add_option("lens", info.lens, "Lens file (.json, .zmx, .dat, lentil.json#ID) or shipped lens name (see `lensmith lenses`)")->required();
  info_cmd->add_option("-w,--wavelength", info.wavelength_nm, "Wavelength, nm (default: the lens's primary wavelength; range 100-20000)")
      ->check(CLI::Range(100.0, 20000.0));
  info_cmd->add_option("-d,--object-distance", info.object_distance_m,
                       "Distance from the object to the first lens vertex, metres (default: the lens's, usually infinity; > 0)")
      ->check(CLI::PositiveNumber);
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
      ->check(CLI::PositiveNumber);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitUsage;
  }

  try {
    if (*info_cmd) return run_info(info, global);
    if (*lenses_cmd) return run_lenses(lenses, global);
    if (*convert_cmd) return run_convert(convert, global);
  } catch (const lensmith::ComputationError& e) {
    std::cerr << "lensmith: " << e.what() << "\n";
    return kExitComputation;
  } catch (const lensmith::IoError& e) {
    std::cerr << "lensmith: " << e.what() << "\n";
    return kExitIo;
  } catch (const lensmith::Error& e) {
    std::cerr << "lensmith: " << e.what() << "\n";
    return kExitInput;
  } catch (const std::exception& e) {
    std::cerr << "lensmith: internal error: " << e.what() << "\n";
    return kExitInternal;
  }
  return kExitUsage;
}

// The lensmith command's subcommands: each fills an options struct from the command line, makes
// one library call and prints the result. main.cpp turns exceptions into exit codes.
#pragma once

#include <optional>
#include <string>

#include "lensmith/core/diagnostic.h"
#include "lensmith/prescription/prescription.h"

namespace lensmith::cli {

// Exit codes (documented in docs/cli.md).
inline constexpr int kExitOk = 0;
inline constexpr int kExitUsage = 2;         // bad command line
inline constexpr int kExitInput = 3;         // a lens file, glass or option value is wrong
inline constexpr int kExitComputation = 4;   // the lens has no answer (e.g. afocal: no focal length)
inline constexpr int kExitIo = 5;            // a file could not be read or written
inline constexpr int kExitInternal = 70;     // a bug: please report it

struct GlobalOptions {
  bool quiet = false;  // --quiet: no warnings or progress on stderr
};

struct InfoOptions {
  std::string lens;                          // file path or shipped lens name
  std::optional<double> wavelength_nm;       // default: the lens's primary wavelength
  std::optional<double> object_distance_m;   // metres from the object to surface 1; default: the lens's
  bool json = false;
  bool spectral = false;                     // add the 64-wavelength table
};
int run_info(const InfoOptions& options, const GlobalOptions& global);

struct LensesOptions {
  std::string lentil_database;  // list the entries of a lentil lenses.json instead
  bool json = false;
};
int run_lenses(const LensesOptions& options, const GlobalOptions& global);

struct ConvertOptions {
  std::string lens;
  std::string output;  // native JSON file to write
  std::optional<double> scale_to_efl_mm;  // scale the lens so its EFL (primary wavelength) becomes this
};
int run_convert(const ConvertOptions& options, const GlobalOptions& global);

// Prints the reader's warnings to stderr unless quiet.
void print_diagnostics(const Diagnostics& diagnostics, const GlobalOptions& global);

// Loads LENS (a file path or a shipped lens name) and prints its warnings.
Prescription load_lens(const std::string& lens, const GlobalOptions& global);

}  // namespace lensmith::cli

// `lensmith convert`: any supported lens file to lensmith's native JSON.
#include <filesystem>
#include <iostream>

#include "commands.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/text_file.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "lensmith/prescription/lens_json.h"

namespace lensmith::cli {

int run_convert(const ConvertOptions& options, const GlobalOptions& global) {
  std::error_code ec;
  const std::string input_file = options.lens.substr(0, options.lens.rfind('#'));
  if (std::filesystem::exists(input_file, ec) && std::filesystem::exists(options.output, ec) &&
      std::filesystem::equivalent(input_file, options.output, ec)) {
    throw IoError(options.output + ": is the input file; lensmith never overwrites its inputs");
  }
  Prescription lens = load_lens(options.lens, global);
  if (options.scale_to_efl_mm) {
    const double efl = ParaxialSystem(lens).efl_mm();
    lens = lens.scaled(*options.scale_to_efl_mm / std::abs(efl));
  }
  write_file_atomically(options.output, write_lens_json(lens));
  if (!global.quiet) std::cerr << "wrote " << options.output << "\n";
  return kExitOk;
}

}  // namespace lensmith::cli

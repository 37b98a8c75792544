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
  ensure_not_an_input(options.output, {options.lens.substr(0, options.lens.rfind('#'))});
  ensure_writable_location(options.output);
  Prescription lens = load_lens(options.lens, global, /*resolve_field=*/false);
  if (options.scale_to_efl_mm) {
    const double efl = ParaxialSystem(lens).efl_mm();
    lens = lens.scaled(*options.scale_to_efl_mm / std::abs(efl));
  }
  write_file_atomically(options.output, write_lens_json(lens));
  report_written(options.output, global);
  return kExitOk;
}

}  // namespace lensmith::cli

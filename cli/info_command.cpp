// `lensmith info`: first-order optics of a lens, as a readable listing or one JSON object
// (schema in docs/cli.md; every axial position is z in mm with z = 0 at the vertex of surface 1).
#include <cmath>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "lensmith/core/json_text.h"
#include "lensmith/report/json_report.h"
#include "json_output.h"
#include "lensmith/core/units.h"
#include "lensmith/paraxial/paraxial_spectral_table.h"
#include "lensmith/paraxial/paraxial_system.h"

namespace lensmith::cli {

int run_info(const InfoOptions& options, const GlobalOptions& global) {
  const Prescription lens = load_lens(options.lens, global);
  ParaxialOptions paraxial;
  if (options.wavelength_nm) paraxial.wavelength_nm = *options.wavelength_nm;
  if (options.object_distance_m) paraxial.object_distance_mm = mm_from_m(*options.object_distance_m);
  const ParaxialSystem system(lens, paraxial);

  // Glass indices are only trustworthy inside the catalogue's range: say so when we step outside.
  if (!global.quiet) {
    for (std::size_t i = 0; i < lens.surfaces.size(); ++i) {
      const Glass& g = lens.surfaces[i].medium;
      if (!g.covers(system.wavelength_nm())) {
        std::cerr << "warning: surface " << i + 1 << ": glass " << g.name() << " is specified only from " << g.valid_range_nm().min_nm
                  << " to " << g.valid_range_nm().max_nm << " nm; its index at " << system.wavelength_nm() << " nm is extrapolated\n";
      }
    }
  }

  std::optional<ParaxialSpectralTable> table;
  if (options.spectral) {
    SpectralTableOptions spectral;
    spectral.object_distance_mm = paraxial.object_distance_mm;
    table.emplace(lens, spectral);
  }

  if (options.json) {
    ojson o = info_json(lens, system);
    if (table) o["spectral"] = spectral_json(*table);
    std::cout << json_text(o, 2) << "\n";
    return kExitOk;
  }
  std::cout << lens.to_string() << "\n";
  if (!lens.source.empty()) std::cout << "Source: " << lens.source << "\n\n";
  std::cout << system.to_string();
  if (table) std::cout << "\n" << table->to_string();
  return kExitOk;
}

}  // namespace lensmith::cli

// `lensmith info`: first-order optics of a lens, as a readable listing or one JSON object
// (schema in docs/cli.md; every axial position is z in mm with z = 0 at the vertex of surface 1).
#include <cmath>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/json_text.h"
#include "lensmith/core/number_parsing.h"
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

  // A lens with toroidal or biconic surfaces has a second section: its x (sagittal) first-order data, and the
  // anamorphic squeeze EFL_y / EFL_x; or none, where the x section has no power (a cylinder alone).
  const bool anamorphic = lens.is_anamorphic();
  std::optional<ParaxialSystem> x_system;
  std::string x_afocal;
  if (anamorphic) {
    ParaxialOptions x = paraxial;
    x.section = Section::X;
    try {
      x_system.emplace(lens, x);
    } catch (const ComputationError& e) {
      x_afocal = e.what();
    }
  }

  if (options.json) {
    ojson o = info_json(lens, system);
    if (anamorphic) {
      ojson x = ojson::object();
      if (x_system) {
        x["efl_mm"] = x_system->efl_mm();
        x["bfl_mm"] = x_system->bfl_mm();
        x["squeeze"] = system.efl_mm() / x_system->efl_mm();
      } else {
        x["afocal"] = true;
        x["why"] = x_afocal;
      }
      o["x_section"] = x;
    }
    if (table) o["spectral"] = spectral_json(*table);
    std::cout << json_text(o, 2) << "\n";
    return kExitOk;
  }
  std::cout << lens.to_string() << "\n";
  if (!lens.source.empty()) std::cout << "Source: " << lens.source << "\n\n";
  std::cout << system.to_string();
  if (anamorphic) {
    std::cout << "\nThe x section (sagittal; the listing above is the y section, OpticStudio's paraxial one):\n";
    if (x_system) {
      std::cout << "  Effective focal length EFL        " << format_rounded(x_system->efl_mm(), 8) << " mm\n"
                << "  Back focal length BFL             " << format_rounded(x_system->bfl_mm(), 8) << " mm\n"
                << "  Anamorphic squeeze EFL_y / EFL_x  " << format_rounded(system.efl_mm() / x_system->efl_mm(), 6) << "\n";
    } else {
      std::cout << "  no first-order image: " << x_afocal << "\n";
    }
  }
  if (table) std::cout << "\n" << table->to_string();
  return kExitOk;
}

}  // namespace lensmith::cli

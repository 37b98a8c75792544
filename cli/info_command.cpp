// `lensmith info`: first-order optics of a lens, as a readable listing or one JSON object
// (schema in docs/cli.md; every axial position is z in mm with z = 0 at the vertex of surface 1).
#include <cmath>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "json_output.h"
#include "lensmith/core/units.h"
#include "lensmith/paraxial/paraxial_spectral_table.h"
#include "lensmith/paraxial/paraxial_system.h"

namespace lensmith::cli {

namespace {



ojson ray_table_json(const ParaxialRayTable& t) {
  ojson rows = ojson::array();
  for (const auto& r : t.rows) {
    rows.push_back({{"surface", r.surface}, {"y_mm", r.y_mm}, {"u", r.u_after}, {"i", r.i}, {"n_after", r.n_after}});
  }
  return {{"object_slope", t.object_slope}, {"object_height_mm", t.object_height_mm}, {"surfaces", rows},
          {"image_height_mm", t.image_height_mm}};
}

ojson info_json(const Prescription& lens, const ParaxialSystem& p) {
  ojson o;
  o["name"] = lens.name;
  o["wavelength_nm"] = p.wavelength_nm();
  o["object_distance_mm"] = number_or_null(p.object_distance_mm());
  o["efl_mm"] = p.efl_mm();
  o["bfl_mm"] = p.bfl_mm();
  o["ffl_mm"] = p.ffl_mm();
  o["front_focal_length_mm"] = p.front_focal_length_mm();
  o["rear_focal_length_mm"] = p.rear_focal_length_mm();
  o["z_front_focal_mm"] = p.z_front_focal_mm();
  o["z_rear_focal_mm"] = p.z_rear_focal_mm();
  o["z_front_principal_mm"] = p.z_front_principal_mm();
  o["z_rear_principal_mm"] = p.z_rear_principal_mm();
  o["z_front_nodal_mm"] = p.z_front_nodal_mm();
  o["z_rear_nodal_mm"] = p.z_rear_nodal_mm();
  o["z_last_surface_mm"] = p.z_last_surface_mm();
  o["stop_surface"] = p.stop_surface();
  o["stop_flagged"] = p.stop_was_flagged();
  o["entrance_pupil"] = {{"z_mm", p.entrance_pupil().z_mm}, {"diameter_mm", p.entrance_pupil().diameter_mm}};
  o["exit_pupil"] = {{"z_mm", p.exit_pupil().z_mm}, {"diameter_mm", p.exit_pupil().diameter_mm}};
  o["f_number"] = p.f_number();
  o["working_f_number"] = p.working_f_number();
  o["image_space_na"] = p.image_space_na();
  auto h = p.lagrange_invariant();
  o["lagrange_invariant"] = h ? ojson(*h) : ojson(nullptr);
  o["image_distance_mm"] = number_or_null(p.image_distance_mm());
  o["z_image_mm"] = number_or_null(p.z_image_mm());
  o["magnification"] = p.magnification();
  o["image_plane_distance_mm"] = p.image_plane_distance_mm();
  const auto& m = p.system_matrix();
  o["system_matrix"] = {{"a11", m.a11}, {"a12", m.a12}, {"a21", m.a21}, {"a22", m.a22}};
  o["marginal_ray"] = ray_table_json(p.marginal_ray());
  o["chief_ray"] = p.chief_ray() ? ray_table_json(*p.chief_ray()) : ojson(nullptr);
  return o;
}

ojson spectral_json(const ParaxialSpectralTable& table) {
  ojson rows = ojson::array();
  for (const auto& s : table.samples()) {
    rows.push_back({{"wavelength_nm", s.wavelength_nm}, {"efl_mm", s.efl_mm}, {"bfl_mm", s.bfl_mm}, {"ffl_mm", s.ffl_mm},
                    {"z_front_principal_mm", s.z_front_principal_mm}, {"z_rear_principal_mm", s.z_rear_principal_mm},
                    {"entrance_pupil", {{"z_mm", s.z_entrance_pupil_mm}, {"diameter_mm", s.entrance_pupil_diameter_mm}}},
                    {"exit_pupil", {{"z_mm", s.z_exit_pupil_mm}, {"diameter_mm", s.exit_pupil_diameter_mm}}},
                    {"image_distance_mm", number_or_null(s.image_distance_mm)}, {"magnification", s.magnification},
                    {"extrapolated", s.extrapolated}});
  }
  return rows;
}

}  // namespace

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
    std::cout << o.dump(2) << "\n";
    return kExitOk;
  }
  std::cout << lens.to_string() << "\n";
  if (!lens.source.empty()) std::cout << "Source: " << lens.source << "\n\n";
  std::cout << system.to_string();
  if (table) std::cout << "\n" << table->to_string();
  return kExitOk;
}

}  // namespace lensmith::cli

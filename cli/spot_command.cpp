// `lensmith spot`: spot diagrams per field and wavelength with RMS and GEO radii; a table, one JSON
// object (docs/cli.md) and optionally a PNG picture.
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "json_output.h"
#include "lensmith/analysis/spot_diagram.h"
#include "lensmith/core/units.h"
#include "lensmith/plot/analysis_plots.h"

namespace lensmith::cli {

namespace {



ojson losses_json(const RayLossCount& l) {
  return {{"total", l.total()},          {"vignetted", l.vignetted},         {"missed", l.missed},
          {"tir", l.total_internal_reflection}, {"not_converged", l.not_converged}, {"invalid_input", l.invalid_input}};
}

ojson statistics_json(const SpotStatistics& s) {
  return {{"traced", s.traced},
          {"passed", s.passed},
          {"lost", losses_json(s.lost)},
          {"centroid_x_mm", number_or_null(s.centroid_x_mm)},
          {"centroid_y_mm", number_or_null(s.centroid_y_mm)},
          {"rms_radius_chief_um", number_or_null(um_from_mm(s.rms_radius_chief_mm))},
          {"geo_radius_chief_um", number_or_null(um_from_mm(s.geo_radius_chief_mm))},
          {"rms_radius_centroid_um", number_or_null(um_from_mm(s.rms_radius_centroid_mm))},
          {"geo_radius_centroid_um", number_or_null(um_from_mm(s.geo_radius_centroid_mm))}};
}

ojson spot_json(const SpotDiagram& d) {
  ojson o;
  o["lens"] = d.lens_name;
  if (d.sampling.kind == PupilSampling::Kind::Hexapolar) {
    o["sampling"] = {{"kind", "hexapolar"}, {"rings", d.sampling.rings}, {"rays", d.sampling.count()}};
  } else {
    o["sampling"] = {{"kind", "random"}, {"rays", d.sampling.count()}, {"seed", d.sampling.seed}};
  }
  o["wavelengths_nm"] = d.wavelengths_nm;
  o["reference_wavelength_nm"] = d.reference_wavelength_nm;
  o["field_unit"] = d.field_unit;
  o["image_plane_z_mm"] = d.image_plane_z_mm;
  ojson fields = ojson::array();
  for (const FieldSpot& f : d.fields) {
    ojson field;
    field["relative_field"] = f.relative_field;
    field["field_value"] = f.field_value;
    field["chief"] = {{"x_mm", f.chief.x_mm}, {"y_mm", f.chief.y_mm}};
    field["polychromatic"] = statistics_json(f.polychromatic);
    ojson spots = ojson::array();
    for (const Spot& s : f.spots) {
      ojson spot = statistics_json(s.stats);
      spot["wavelength_nm"] = s.wavelength_nm;
      ojson px = ojson::array(), py = ojson::array(), x = ojson::array(), y = ojson::array();
      for (std::size_t i = 0; i < s.points.size(); ++i) {
        px.push_back(s.pupil[i].px);
        py.push_back(s.pupil[i].py);
        x.push_back(s.points[i].x_mm);
        y.push_back(s.points[i].y_mm);
      }
      spot["rays"] = {{"px", px}, {"py", py}, {"x_mm", x}, {"y_mm", y}};
      spots.push_back(spot);
    }
    field["spots"] = spots;
    fields.push_back(field);
  }
  o["fields"] = fields;
  return o;
}

}  // namespace

int run_spot(const SpotCommandOptions& options, const GlobalOptions& global) {
  const Prescription lens = load_lens(options.common.lens, global);
  const AnalysisContext context(lens, make_analysis_options(options.common));
  SpotOptions spot;
  if (options.random_rays) {
    spot.sampling.kind = PupilSampling::Kind::Random;
    spot.sampling.random_rays = *options.random_rays;
    spot.sampling.seed = options.seed;
  } else {
    spot.sampling.rings = options.rings;
  }
  const SpotDiagram diagram = compute_spot_diagram(context, spot);
  if (!options.common.png.empty()) {
    write_picture(plot::plot_spot_diagram(diagram, make_plot_options(global)), options.common.png, options.common.lens, global);
  }
  if (options.common.json) {
    std::cout << spot_json(diagram).dump(2) << "\n";
  } else {
    std::cout << diagram.to_string();
  }
  return kExitOk;
}

}  // namespace lensmith::cli

// `lensmith fan`: tangential and sagittal transverse ray fans per field and wavelength; a table, one
// JSON object (docs/cli.md) and optionally a PNG picture.
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "lensmith/analysis/ray_fan.h"
#include "lensmith/core/units.h"
#include "lensmith/plot/analysis_plots.h"

namespace lensmith::cli {

namespace {

using ojson = nlohmann::ordered_json;

ojson samples_json(const std::vector<FanSample>& samples, const char* pupil_key, const char* error_key) {
  ojson out = ojson::array();
  for (const FanSample& s : samples) {
    out.push_back({{pupil_key, s.pupil},
                   {error_key, s.ok() ? ojson(um_from_mm(s.error_mm)) : ojson(nullptr)},
                   {"status", std::string(to_string(s.status))},
                   {"surface", s.surface > 0 ? ojson(s.surface) : ojson(nullptr)}});
  }
  return out;
}

ojson fan_json(const RayFan& fan) {
  ojson o;
  o["lens"] = fan.lens_name;
  o["wavelengths_nm"] = fan.wavelengths_nm;
  o["reference_wavelength_nm"] = fan.reference_wavelength_nm;
  o["field_unit"] = fan.field_unit;
  o["image_plane_z_mm"] = fan.image_plane_z_mm;
  ojson fields = ojson::array();
  for (const FieldFan& f : fan.fields) {
    ojson curves = ojson::array();
    for (const FanCurve& c : f.curves) {
      curves.push_back({{"wavelength_nm", c.wavelength_nm},
                        {"tangential", samples_json(c.tangential, "py", "ey_um")},
                        {"sagittal", samples_json(c.sagittal, "px", "ex_um")}});
    }
    fields.push_back({{"relative_field", f.relative_field},
                      {"field_value", f.field_value},
                      {"chief", {{"x_mm", f.chief.x_mm}, {"y_mm", f.chief.y_mm}}},
                      {"curves", curves}});
  }
  o["fields"] = fields;
  return o;
}

}  // namespace

int run_fan(const FanCommandOptions& options, const GlobalOptions& global) {
  const Prescription lens = load_lens(options.common.lens, global);
  const AnalysisContext context(lens, make_analysis_options(options.common));
  RayFanOptions fan_options;
  fan_options.samples = options.samples;
  const RayFan fan = compute_ray_fan(context, fan_options);
  if (!options.common.png.empty()) {
    write_picture(plot::plot_ray_fan(fan, make_plot_options(global)), options.common.png, options.common.lens, global);
  }
  if (options.common.json) {
    std::cout << fan_json(fan).dump(2) << "\n";
  } else {
    std::cout << fan.to_string();
  }
  return kExitOk;
}

}  // namespace lensmith::cli

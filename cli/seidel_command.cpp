// `lensmith seidel`: third-order aberrations per surface and summed, like CODE V's third-order
// listing, with the wavefront, transverse and longitudinal forms and Born & Wolf's B..F.
// JSON schema: docs/cli.md.
#include <cmath>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "json_output.h"
#include "lensmith/core/units.h"
#include "lensmith/seidel/aberration_vector.h"
#include "lensmith/plot/analysis_plots.h"
#include "lensmith/seidel/seidel_analysis.h"

namespace lensmith::cli {

namespace {


ojson sums_json(const SeidelSums& s) {
  return {{"S1", s.S1}, {"S2", s.S2}, {"S3", s.S3}, {"S4", s.S4}, {"S5", s.S5}, {"C1", s.C1}, {"C2", s.C2}};
}

}  // namespace

namespace {

SeidelOptions seidel_options_from(const SeidelCommandOptions& options) {
  SeidelOptions o;
  if (options.wavelength_nm) o.wavelength_nm = *options.wavelength_nm;
  if (options.object_distance_m) o.object_distance_mm = mm_from_m(*options.object_distance_m);
  if (options.field_angle_deg) o.field_angle_deg = *options.field_angle_deg;
  if (options.epd_mm) o.entrance_pupil_diameter_mm = *options.epd_mm;
  if (options.f_number) o.f_number = *options.f_number;
  return o;
}

}  // namespace

int run_seidel(const SeidelCommandOptions& options, const GlobalOptions& global) {
  const Prescription lens = load_lens(options.lens, global);
  if (!lens.field && !options.field_angle_deg) {
    throw PrescriptionError("the lens \"" + lens.name + "\" states no field, and the Seidel sums need one (the chief ray): give --field-angle DEG");
  }
  const SeidelAnalysis seidel(lens, seidel_options_from(options));
  if (!options.png.empty()) write_picture(plot::plot_seidel_diagram(seidel, lens.name), options.png, options.lens, global);
  if (!options.json) {
    std::cout << lens.name << "\n\n" << seidel.to_string();
    std::cout << "\n  Born & Wolf coefficients: " << AberrationCoefficients::from(seidel).to_string() << "\n";
    return kExitOk;
  }
  ojson o;
  o["name"] = lens.name;
  o["wavelength_nm"] = seidel.wavelength_nm();
  const double d = seidel.paraxial().object_distance_mm();
  o["object_distance_mm"] = std::isinf(d) ? ojson(nullptr) : ojson(d);
  o["entrance_pupil_diameter_mm"] = seidel.paraxial().entrance_pupil().diameter_mm;
  o["lagrange_invariant"] = seidel.lagrange_invariant();
  o["image_space_slope"] = seidel.image_slope();
  o["sums"] = sums_json(seidel.sums());
  ojson surfaces = ojson::array();
  for (std::size_t k = 0; k < seidel.surfaces().size(); ++k) {
    ojson row = sums_json(seidel.surfaces()[k]);
    row["surface"] = k + 1;
    row["aspheric"] = sums_json(seidel.aspheric_parts()[k]);
    surfaces.push_back(row);
  }
  o["surfaces"] = surfaces;
  const WavefrontCoefficients w = seidel.wavefront().in_waves(seidel.wavelength_nm());
  o["wavefront_waves"] = {{"W040", w.W040}, {"W131", w.W131}, {"W222", w.W222}, {"W220", w.W220}, {"W311", w.W311}, {"W020", w.W020}, {"W111", w.W111}};
  const WavefrontCoefficients wmm = seidel.wavefront();
  o["wavefront_mm"] = {{"W040", wmm.W040}, {"W131", wmm.W131}, {"W222", wmm.W222}, {"W220", wmm.W220}, {"W311", wmm.W311}, {"W020", wmm.W020}, {"W111", wmm.W111}};
  const TransverseAberrations t = seidel.transverse();
  o["transverse_mm"] = {{"TSA", t.TSA}, {"TCO", t.TCO}, {"TAS", t.TAS}, {"SAS", t.SAS}, {"PTB", t.PTB}, {"DST", t.DST}, {"TAX", t.TAX}, {"TLAT", t.TLAT}};
  const LongitudinalAberrations l = seidel.longitudinal();
  o["longitudinal_mm"] = {{"LSA", l.LSA}, {"LTAS", l.LTAS}, {"LSAS", l.LSAS}, {"LPTZ", l.LPTZ}, {"LAX", l.LAX}};
  const FieldCurvatures f = seidel.field_curvatures();
  o["field_curvatures_per_mm"] = {{"tangential", f.tangential_per_mm}, {"sagittal", f.sagittal_per_mm}, {"petzval", f.petzval_per_mm}};
  o["petzval_radius_mm"] = std::isinf(f.petzval_radius_mm()) ? ojson(nullptr) : ojson(f.petzval_radius_mm());
  const AberrationCoefficients c = AberrationCoefficients::from(seidel);
  o["born_wolf"] = {{"B", c.B_mm}, {"C", c.C_mm}, {"D", c.D_mm}, {"E", c.E_mm}, {"F", c.F_mm}, {"units", "mm; rho = 1 at the pupil edge, y0 = 1 at the maximum field"},
                    {"pupil_radius_mm", c.pupil_radius_mm}, {"max_field_tangent", c.max_field_tangent}};
  const BornWolfUnits u = c.in_born_wolf_units();
  o["born_wolf_units"] = {{"B", u.B}, {"C", u.C}, {"D", u.D}, {"E", u.E}, {"F", u.F},
                          {"D0_mm", std::isinf(u.D0_mm) ? ojson(nullptr) : ojson(u.D0_mm)}, {"D1_mm", u.D1_mm}};
  std::cout << o.dump(2) << "\n";
  return kExitOk;
}

}  // namespace lensmith::cli

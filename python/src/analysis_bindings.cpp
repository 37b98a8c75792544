// Real-ray analyses in Python: spot diagrams, ray fans and the one-curve analyses of
// `lensmith analyze` (distortion, field curves, focal shift, illumination, pupil), as the command's
// JSON reports and, on request, the same PNG pictures (docs/python.md, "Real rays").
#include <filesystem>

#include <pybind11/stl.h>

#include "bindings.h"
#include "lensmith/analysis/analysis_context.h"
#include "lensmith/analysis/chromatic_focal_shift.h"
#include "lensmith/analysis/distortion_curve.h"
#include "lensmith/analysis/field_curves.h"
#include "lensmith/analysis/pupil_shape.h"
#include "lensmith/analysis/ray_fan.h"
#include "lensmith/analysis/relative_illumination.h"
#include "lensmith/analysis/spot_diagram.h"
#include "lensmith/core/errors.h"
#include "lensmith/plot/analysis_plots.h"
#include "lensmith/render/image_io.h"

namespace lensmith::python {

void ensure_not_the_lens_file(const std::string& output, const LensHandle& lens) {
  // The lens file (a lentil database's, without its "#id"); a shipped lens's id names no file.
  const std::string file = lens.origin.substr(0, lens.origin.rfind('#'));
  if (!file.empty() && std::filesystem::exists(file)) ensure_not_an_input(output, {file});
}

void write_picture(const plot::Canvas& canvas, const std::string& png, const LensHandle& lens) {
  ensure_not_the_lens_file(png, lens);
  ensure_writable_location(png);
  canvas.write_png(png);
}

namespace {

// What the command's --fields, --wavelength, --field-angle, --image and --aim say, as the library's options.
struct RealRayArgs {
  std::vector<double> fields{0.0, 0.7, 1.0};
  std::vector<double> wavelengths_nm;
  std::optional<double> field_angle_deg;
  std::string image = "prescribed";
  std::string aim;  // "paraxial", "real", or empty: as the lens file says

  AnalysisOptions options() const {
    AnalysisOptions a;
    a.relative_fields = fields;
    a.wavelengths_nm = wavelengths_nm;
    a.max_field_angle_deg = field_angle_deg;
    if (image == "paraxial") {
      a.image_plane = TracerOptions::ImagePlane::ParaxialFocus;
    } else if (image != "prescribed") {
      throw OptionsError("image = '" + image + "': must be 'prescribed' or 'paraxial'");
    }
    if (aim == "real") {
      a.aiming = RayAiming::RealStop;
    } else if (aim == "paraxial") {
      a.aiming = RayAiming::ParaxialEntrancePupil;
    } else if (!aim.empty()) {
      throw OptionsError("aim = '" + aim + "': must be 'paraxial' or 'real'");
    }
    return a;
  }
};

RealRayArgs args(std::vector<double> fields, std::vector<double> wavelengths_nm, std::optional<double> field_angle_deg, std::string image,
                 std::string aim) {
  return {std::move(fields), std::move(wavelengths_nm), field_angle_deg, std::move(image), std::move(aim)};
}

#define LENSMITH_REAL_RAY_ARGS                                                                                                           \
  py::arg("fields") = std::vector<double>{0.0, 0.7, 1.0}, py::arg("wavelengths_nm") = std::vector<double>{},                            \
  py::arg("field_angle_deg") = py::none(), py::arg("image") = "prescribed", py::arg("aim") = ""

}  // namespace

void bind_analysis(py::module_& m) {
  m.def("spot_json", [](const LensHandle& lens, std::vector<double> fields, std::vector<double> wavelengths_nm,
                        std::optional<double> field_angle_deg, std::string image, std::string aim, int rings,
                        std::optional<int> random_rays, std::uint64_t seed, const std::string& png) {
    const Prescription p = lens.checked();
    const RealRayArgs a = args(std::move(fields), std::move(wavelengths_nm), field_angle_deg, std::move(image), std::move(aim));
    SpotOptions spot;
    if (random_rays) {
      spot.sampling.kind = PupilSampling::Kind::Random;
      spot.sampling.random_rays = *random_rays;
      spot.sampling.seed = seed;
    } else {
      spot.sampling.rings = rings;
    }
    py::gil_scoped_release release;
    const SpotDiagram d = compute_spot_diagram(AnalysisContext(p, a.options()), spot);
    if (!png.empty()) write_picture(plot::plot_spot_diagram(d, {}), png, lens);
    return dump(spot_json(d));
  }, py::arg("lens"), LENSMITH_REAL_RAY_ARGS, py::arg("rings") = 6, py::arg("random_rays") = py::none(), py::arg("seed") = 1,
     py::arg("png") = "");

  m.def("fan_json", [](const LensHandle& lens, std::vector<double> fields, std::vector<double> wavelengths_nm,
                       std::optional<double> field_angle_deg, std::string image, std::string aim, int samples, const std::string& png) {
    const Prescription p = lens.checked();
    const RealRayArgs a = args(std::move(fields), std::move(wavelengths_nm), field_angle_deg, std::move(image), std::move(aim));
    RayFanOptions o;
    o.samples = samples;
    py::gil_scoped_release release;
    const RayFan fan = compute_ray_fan(AnalysisContext(p, a.options()), o);
    if (!png.empty()) write_picture(plot::plot_ray_fan(fan, {}), png, lens);
    return dump(fan_json(fan));
  }, py::arg("lens"), LENSMITH_REAL_RAY_ARGS, py::arg("samples") = 41, py::arg("png") = "");

  // `lensmith analyze --what WHAT`: the same defaults and the same field sampling.
  m.def("analyze_json", [](const LensHandle& lens, const std::string& what, std::vector<double> fields, std::vector<double> wavelengths_nm,
                           std::optional<double> field_angle_deg, std::string image, std::string aim, std::optional<int> samples,
                           std::optional<int> grid, const std::string& png) {
    const Prescription p = lens.checked();
    RealRayArgs a = args(std::move(fields), std::move(wavelengths_nm), field_angle_deg, std::move(image), std::move(aim));
    py::gil_scoped_release release;
    if (what == "focal-shift") {
      FocalShiftOptions o;
      o.wavelengths_nm = a.wavelengths_nm;
      if (samples) o.samples = *samples;
      const ChromaticFocalShift r = compute_chromatic_focal_shift(p, o);
      if (!png.empty()) write_picture(plot::plot_chromatic_focal_shift(r, {}), png, lens);
      return dump(focal_shift_json(r));
    }
    if (what == "pupil") {
      PupilShapeOptions o;
      if (grid) o.grid = *grid;
      const PupilShape r = compute_pupil_shape(AnalysisContext(p, a.options()), o);
      if (!png.empty()) write_picture(plot::plot_pupil_shape(r, {}), png, lens);
      return dump(pupil_json(r));
    }
    // The curves against field sample the field themselves; `fields` does not apply.
    a.fields = {0.0, 1.0};
    const AnalysisContext context(p, a.options());
    if (what == "distortion") {
      DistortionOptions o;
      if (samples) o.field_samples = *samples;
      const DistortionCurve r = compute_distortion(context, o);
      if (!png.empty()) write_picture(plot::plot_distortion(r, {}), png, lens);
      return dump(distortion_json(r));
    }
    if (what == "field-curves") {
      FieldCurveOptions o;
      if (samples) o.field_samples = *samples;
      const FieldCurves r = compute_field_curves(context, o);
      if (!png.empty()) write_picture(plot::plot_field_curves(r, {}), png, lens);
      return dump(field_curves_json(r));
    }
    if (what == "illumination") {
      IlluminationOptions o;
      if (samples) o.field_samples = *samples;
      if (grid) o.pupil_grid = *grid;
      const RelativeIllumination r = compute_relative_illumination(context, o);
      if (!png.empty()) write_picture(plot::plot_relative_illumination(r, {}), png, lens);
      return dump(illumination_json(r));
    }
    throw OptionsError("what = '" + what + "': must be distortion, field-curves, focal-shift, illumination or pupil");
  }, py::arg("lens"), py::arg("what"), LENSMITH_REAL_RAY_ARGS, py::arg("samples") = py::none(), py::arg("grid") = py::none(),
     py::arg("png") = "");
}

}  // namespace lensmith::python

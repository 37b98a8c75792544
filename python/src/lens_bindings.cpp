// Lenses in Python: loading (files and shipped names), the native JSON both ways, surfaces one can
// read and change, and the first-order and third-order reports (docs/python.md, "Lenses").
#include <cmath>
#include <sstream>

#include <pybind11/stl.h>

#include "bindings.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/text_file.h"
#include "lensmith/core/units.h"
#include "lensmith/glass/glass_catalog.h"
#include "lensmith/paraxial/paraxial_spectral_table.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "lensmith/plot/analysis_plots.h"
#include "lensmith/prescription/lens_json.h"
#include "lensmith/prescription/lens_library.h"
#include "lensmith/seidel/seidel_analysis.h"
#include "lensmith/trace/ray_aiming.h"

namespace lensmith::python {

Prescription LensHandle::checked() const {
  Prescription p = prescription;
  p.resolve_materials(GlassCatalog::builtin());
  p.validate();
  return p;
}

namespace {

// One surface of a lens, by number: reads and writes go to the lens itself.
struct SurfaceView {
  LensPtr lens;
  std::size_t index = 0;  // 0-based
  Surface& get() const {
    if (index >= lens->prescription.surfaces.size()) {
      throw PrescriptionError("surface " + std::to_string(index + 1) + " no longer exists: the lens has " +
                              std::to_string(lens->prescription.surfaces.size()) + " surfaces");
    }
    return lens->prescription.surfaces[index];
  }
};

// "air", "N-BK7" or "SCHOTT:N-BK7" (vendor:name): checked against the catalogues at once, so that a
// misspelt glass is an error where it is written (GlassError naming the closest names).
MaterialSpec material_from_text(const std::string& text) {
  if (text == "air" || text == "AIR" || text.empty()) return MaterialSpec::air();
  const std::size_t colon = text.find(':');
  MaterialSpec m = colon == std::string::npos ? MaterialSpec::catalog(text) : MaterialSpec::catalog(text.substr(colon + 1), text.substr(0, colon));
  (void)m.resolve(GlassCatalog::builtin());
  return m;
}

LensPtr handle_from(LensReadResult result, std::string origin, std::vector<std::string>* warnings) {
  if (warnings) {
    for (const Diagnostic& d : result.diagnostics) warnings->push_back(d.to_string());
  }
  auto lens = std::make_shared<LensHandle>();
  // A real-image-height field becomes object field points here, by tracing, as the CLI does.
  lens->prescription = resolve_real_image_height_field(result.prescription);
  lens->origin = std::move(origin);
  return lens;
}

std::string aperture_kind(ApertureSpec::Kind kind) {
  switch (kind) {
    case ApertureSpec::Kind::EntrancePupilDiameter: return "entrance_pupil_diameter_mm";
    case ApertureSpec::Kind::ImageSpaceFNumber: return "image_space_f_number";
    case ApertureSpec::Kind::FloatByStop: return "float_by_stop";
    case ApertureSpec::Kind::ParaxialWorkingFNumber: return "paraxial_working_f_number";
    case ApertureSpec::Kind::ObjectSpaceNA: return "object_space_na";
    case ApertureSpec::Kind::ObjectConeAngleDeg: return "object_cone_angle_deg";
  }
  return "?";
}

ParaxialOptions paraxial_options(std::optional<double> wavelength_nm, std::optional<double> object_distance_m) {
  ParaxialOptions o;
  if (wavelength_nm) o.wavelength_nm = *wavelength_nm;
  if (object_distance_m) o.object_distance_mm = mm_from_m(*object_distance_m);
  return o;
}

}  // namespace

void bind_lens(py::module_& m) {
  m.def("lenses", [] {
    std::vector<py::dict> out;
    for (const ShippedLens& l : LensLibrary::list()) {
      py::dict d;
      d["id"] = l.id;
      d["name"] = l.name;
      d["source"] = l.source;
      out.push_back(d);
    }
    return out;
  }, "The shipped lenses, sorted by id: [{'id', 'name', 'source'}, ...].");

  py::class_<SurfaceView>(m, "Surface", "One surface of a lens; reading and writing its attributes reads and changes the lens.")
      .def_property_readonly("number", [](const SurfaceView& s) { (void)s.get(); return s.index + 1; }, "1-based surface number")
      .def_property("radius_mm", [](const SurfaceView& s) { return s.get().radius_mm(); },
                    [](const SurfaceView& s, double r) {
                      if (r == 0.0 || std::isnan(r)) throw OptionsError("radius_mm = " + std::to_string(r) + ": must be non-zero (inf for a plane)");
                      s.get().curvature_per_mm = std::isinf(r) ? 0.0 : 1.0 / r;
                    }, "radius of curvature, mm (inf = plane)")
      .def_property("curvature_per_mm", [](const SurfaceView& s) { return s.get().curvature_per_mm; },
                    [](const SurfaceView& s, double c) { s.get().curvature_per_mm = c; })
      .def_property("thickness_mm", [](const SurfaceView& s) { return s.get().thickness_mm; },
                    [](const SurfaceView& s, double t) { s.get().thickness_mm = t; }, "to the next vertex (last: to the image plane), mm")
      .def_property("glass", [](const SurfaceView& s) { return s.get().material.to_string(); },
                    [](const SurfaceView& s, const std::string& text) {
                      s.get().material = material_from_text(text);
                    }, "the medium after the surface: 'air', a catalogue name, or 'VENDOR:NAME'")
      .def("set_model_glass", [](const SurfaceView& s, double nd, std::optional<double> vd) {
             s.get().material = MaterialSpec::model(nd, vd);
           }, py::arg("nd"), py::arg("vd") = py::none(), "A model glass from nd and Abbe number Vd (None: no dispersion).")
      .def("index", [](const SurfaceView& s, double wavelength_nm) {
             return s.get().material.resolve(GlassCatalog::builtin()).index(wavelength_nm);
           }, py::arg("wavelength_nm"), "Refractive index of the medium after the surface.")
      .def_property("semi_diameter_mm", [](const SurfaceView& s) { return s.get().semi_diameter_mm; },
                    [](const SurfaceView& s, std::optional<double> v) { s.get().semi_diameter_mm = v; }, "semi-diameter, mm (None = not given)")
      .def_property("clips_rays", [](const SurfaceView& s) { return s.get().clips_rays; },
                    [](const SurfaceView& s, bool v) { s.get().clips_rays = v; },
                    "whether semi_diameter_mm is a clear aperture that stops rays (False: a Zemax DIAM, a size only)")
      .def_property("is_stop", [](const SurfaceView& s) { return s.get().is_stop; },
                    [](const SurfaceView& s, bool v) { s.get().is_stop = v; })
      .def_property("conic", [](const SurfaceView& s) { return s.get().conic; }, [](const SurfaceView& s, double k) { s.get().conic = k; })
      .def_property("even_asphere", [](const SurfaceView& s) { return s.get().even_asphere; },
                    [](const SurfaceView& s, const Surface::EvenAsphere& a) { s.get().even_asphere = a; },
                    "a2, a4, ..., a16 (the r^2 ... r^16 terms, mm^(1-2j))")
      .def_property("comment", [](const SurfaceView& s) { return s.get().comment; },
                    [](const SurfaceView& s, const std::string& c) { s.get().comment = c; })
      .def("sag_mm", [](const SurfaceView& s, double r_mm) { return s.get().sag_mm(r_mm); }, py::arg("r_mm"))
      .def("__repr__", [](const SurfaceView& s) { return "<Surface " + std::to_string(s.index + 1) + ": " + s.get().to_string() + ">"; });

  py::class_<LensHandle, LensPtr>(m, "Lens")
      .def_static("load", [](const std::string& path_or_name) {
             std::vector<std::string> warnings;
             LensPtr lens;
             {
               py::gil_scoped_release release;
               lens = handle_from(LensLibrary::load_path_or_name(path_or_name), path_or_name, &warnings);
             }
             return py::make_tuple(lens, warnings);
           }, py::arg("path_or_name"))
      .def_static("from_json_text", [](const std::string& text, const std::string& name) {
             std::vector<std::string> warnings;
             LensPtr lens = handle_from(read_lens_json(text, name), "", &warnings);
             return py::make_tuple(lens, warnings);
           }, py::arg("text"), py::arg("name"))
      .def("to_json_text", [](const LensHandle& l) { return write_lens_json(l.prescription); })
      .def("save", [](const LensHandle& l, const std::string& path) {
             ensure_not_the_lens_file(path, l);
             write_file_atomically(path, write_lens_json(l.prescription));
           }, py::arg("path"))
      .def("copy", [](const LensHandle& l) { return std::make_shared<LensHandle>(LensHandle{l.prescription, ""}); })
      .def("check", [](const LensHandle& l) { (void)l.checked(); })
      .def("scaled", [](const LensHandle& l, double factor) { return std::make_shared<LensHandle>(LensHandle{l.checked().scaled(factor), ""}); },
           py::arg("factor"))
      .def_property("name", [](const LensHandle& l) { return l.prescription.name; }, [](LensHandle& l, const std::string& n) { l.prescription.name = n; })
      .def_property_readonly("source", [](const LensHandle& l) { return l.prescription.source; })
      .def_property_readonly("origin", [](const LensHandle& l) { return l.origin; })
      .def_property("object_distance_mm", [](const LensHandle& l) { return l.prescription.object_distance_mm; },
                    [](LensHandle& l, double d) { l.prescription.object_distance_mm = d; })
      .def_property_readonly("ray_aiming", [](const LensHandle& l) {
             return l.prescription.ray_aiming == RayAiming::RealStop ? "real" : "paraxial";
           }, "the ray aiming the lens file asks for: 'paraxial' or 'real'")
      .def_property_readonly("wavelengths_nm", [](const LensHandle& l) { return l.prescription.wavelengths_nm; })
      .def_property_readonly("primary_wavelength_nm", [](const LensHandle& l) { return l.prescription.primary_wavelength_nm(); })
      .def_property_readonly("aperture", [](const LensHandle& l) {
             return py::make_tuple(aperture_kind(l.prescription.aperture.kind), l.prescription.aperture.value);
           })
      .def_property_readonly("max_field", [](const LensHandle& l) -> py::object {
             if (!l.prescription.field) return py::none();
             const FieldSpec& f = *l.prescription.field;
             const char* unit = f.kind == FieldSpec::Kind::AngleDeg         ? "deg"
                                : f.kind == FieldSpec::Kind::ObjectHeightMm ? "object mm"
                                : f.kind == FieldSpec::Kind::ImageHeightMm  ? "image mm"
                                                                            : "real image mm";
             return py::make_tuple(f.max_value(), unit);
           })
      .def("surface_count", [](const LensHandle& l) { return l.prescription.surfaces.size(); })
      .def_static("surface", [](const LensPtr& l, std::size_t number) {
             if (number < 1 || number > l->prescription.surfaces.size()) {
               throw py::index_error("surface " + std::to_string(number) + ": the lens has surfaces 1 to " + std::to_string(l->prescription.surfaces.size()));
             }
             return SurfaceView{l, number - 1};
           })
      .def("__eq__", [](const LensHandle& a, const LensHandle& b) { return a.prescription == b.prescription; })
      .def("__str__", [](const LensHandle& l) { return l.prescription.to_string(); })
      .def("paraxial_json", [](const LensHandle& l, std::optional<double> wavelength_nm, std::optional<double> object_distance_m) {
             const Prescription p = l.checked();
             py::gil_scoped_release release;
             return dump(info_json(p, ParaxialSystem(p, paraxial_options(wavelength_nm, object_distance_m))));
           }, py::arg("wavelength_nm") = py::none(), py::arg("object_distance_m") = py::none())
      .def("spectral_json", [](const LensHandle& l, std::optional<double> object_distance_m, int samples, double min_nm, double max_nm) {
             const Prescription p = l.checked();
             SpectralTableOptions o;
             o.samples = samples;
             o.min_wavelength_nm = min_nm;
             o.max_wavelength_nm = max_nm;
             if (object_distance_m) o.object_distance_mm = mm_from_m(*object_distance_m);
             py::gil_scoped_release release;
             return dump(spectral_json(ParaxialSpectralTable(p, o)));
           }, py::arg("object_distance_m") = py::none(), py::arg("samples") = 64, py::arg("min_wavelength_nm") = 380.0,
           py::arg("max_wavelength_nm") = 780.0)
      .def("seidel_json", [](const LensHandle& l, std::optional<double> wavelength_nm, std::optional<double> object_distance_m,
                            std::optional<double> field_angle_deg, std::optional<double> epd_mm, std::optional<double> f_number,
                            const std::string& png) {
             const Prescription p = l.checked();
             if (!p.field && !field_angle_deg) {
               throw OptionsError("the lens \"" + p.name + "\" states no field, and the Seidel sums need one (the chief ray): give field_angle_deg");
             }
             SeidelOptions o;
             if (wavelength_nm) o.wavelength_nm = *wavelength_nm;
             if (object_distance_m) o.object_distance_mm = mm_from_m(*object_distance_m);
             o.field_angle_deg = field_angle_deg;
             o.entrance_pupil_diameter_mm = epd_mm;
             o.f_number = f_number;
             py::gil_scoped_release release;
             const SeidelAnalysis seidel(p, o);
             if (!png.empty()) write_picture(plot::plot_seidel_diagram(seidel, p.name), png, l);
             return dump(seidel_json(p, seidel));
           }, py::arg("wavelength_nm") = py::none(), py::arg("object_distance_m") = py::none(), py::arg("field_angle_deg") = py::none(),
           py::arg("epd_mm") = py::none(), py::arg("f_number") = py::none(), py::arg("png") = "");
}

}  // namespace lensmith::python

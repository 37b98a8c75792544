// Native lens format: reader and writer. Key-by-key reference: docs/lens-format.md.
#include "lensmith/core/ascii_text.h"
#include "lensmith/prescription/lens_json.h"

#include <cmath>
#include <utility>

#include "lensmith/core/json_text.h"
#include "lensmith/core/located_json.h"
#include "lensmith/core/units.h"
#include "lensmith/prescription/surface_aperture_json.h"

namespace lensmith {

namespace {

using nlohmann::json;

constexpr const char* kFormatName = "lensmith-lens";
const std::vector<std::string> kTopKeys = {"format", "version", "name", "source", "notes", "object_distance_mm",
                                           "object_material", "aperture", "field", "wavelengths_nm",
                                           "primary_wavelength_nm", "ray_aiming", "object_space_telecentric", "surfaces"};
const std::vector<std::string> kSurfaceKeys = {"radius_mm", "curvature_per_mm", "thickness_mm", "material", "semi_diameter_mm",
                                               "clips_rays", "aperture", "stop", "conic", "even_asphere", "mirror",
                                               "toroidal", "biconic", "coordinate_break", "comment"};
const std::vector<std::string> kBreakKeys = {"decenter_x_mm", "decenter_y_mm", "tilt_x_deg", "tilt_y_deg", "tilt_z_deg", "order"};
const std::vector<std::string> kApertureKeys = {"shape", "radius_mm", "half_x_mm", "half_y_mm", "min_radius_mm",
                                                "obscuration", "decenter_x_mm", "decenter_y_mm"};
const std::vector<std::string> kAsphereKeys = {"a2", "a4", "a6", "a8", "a10", "a12", "a14", "a16"};

// Reads a material: "air", "NAME", or {"glass", "vendor"} / {"nd", "vd"}.
MaterialSpec read_material(const LocatedJson& doc, const std::string& pointer, const std::string& path) {
  const json& v = doc.root().at(json::json_pointer(pointer));
  if (v.is_string()) {
    const std::string name = v.get<std::string>();
    if (name.empty()) throw FileError(doc.where(pointer), path + ": empty glass name");
    if (to_lower_ascii(name) == "air") return MaterialSpec::air();
    return MaterialSpec::catalog(name);
  }
  if (!v.is_object()) {
    throw FileError(doc.where(pointer), path + ": expected \"air\", a glass name, {\"glass\": ...} or {\"nd\": ..., \"vd\": ...}, got " +
                                               json_type_phrase(v));
  }
  JsonObjectReader r(doc, pointer, path);
  if (r.has("glass")) {
    MaterialSpec m = MaterialSpec::catalog(r.get_string("glass"), r.get_optional_string("vendor").value_or(""));
    if (m.glass.empty()) r.fail("glass", "empty glass name");
    r.finish({"glass", "vendor"});
    return m;
  }
  if (r.has("nd")) {
    const double nd = r.get_number("nd");
    auto vd = r.get_optional_number("vd");
    if (!(nd >= 1.0 && nd <= 5.0)) r.fail("nd", "must lie in [1, 5]");
    if (vd && !(*vd > 0.0)) r.fail("vd", "must be > 0");
    r.finish({"nd", "vd"});
    return MaterialSpec::model(nd, vd);
  }
  r.fail("", "a material object needs \"glass\" (catalogue glass) or \"nd\" (model glass)");
}

double read_length_or_infinity(JsonObjectReader& r, const std::string& key, double fallback) {
  const json* v = r.get(key);
  if (!v) return fallback;
  if (v->is_string() && v->get<std::string>() == "infinity") return kInfinity;
  if (!v->is_number()) r.fail(key, "expected a number (mm) or \"infinity\", got " + json_type_phrase(*v));
  return v->get<double>();
}

std::vector<double> read_number_list(JsonObjectReader& r, const std::string& key) {
  const json* v = r.get(key);
  if (v->is_number()) return {v->get<double>()};
  if (!v->is_array()) r.fail(key, "expected a number or an array of numbers, got " + json_type_phrase(*v));
  std::vector<double> out;
  const std::string pointer = r.child_pointer(key);
  for (std::size_t i = 0; i < v->size(); ++i) {
    const json& e = (*v)[i];
    if (!e.is_number()) {
      throw FileError(r.document().where(pointer + "/" + std::to_string(i)),
                          r.child_path(key) + "[" + std::to_string(i) + "]: expected a number, got " + json_type_phrase(e));
    }
    out.push_back(e.get<double>());
  }
  if (out.empty()) r.fail(key, "the list is empty");
  return out;
}

ApertureSpec read_aperture(const LocatedJson& doc, JsonObjectReader& top) {
  ApertureSpec a;
  if (!top.has("aperture")) return a;  // float by stop
  top.get("aperture");
  JsonObjectReader r(doc, top.child_pointer("aperture"), "aperture");
  int given = 0;
  if (auto epd = r.get_optional_number("entrance_pupil_diameter_mm")) {
    a = {ApertureSpec::Kind::EntrancePupilDiameter, *epd};
    ++given;
  }
  if (auto f = r.get_optional_number("f_number")) {
    a = {ApertureSpec::Kind::ImageSpaceFNumber, *f};
    ++given;
  }
  if (auto floating = r.get_optional_bool("float_by_stop")) {
    if (!*floating) r.fail("float_by_stop", "only true is meaningful; give entrance_pupil_diameter_mm or f_number instead");
    a = {ApertureSpec::Kind::FloatByStop, 0.0};
    ++given;
  }
  std::string key_given = a.kind == ApertureSpec::Kind::EntrancePupilDiameter ? "entrance_pupil_diameter_mm" : "f_number";
  for (const auto& [key, kind] : {std::pair{"paraxial_working_f_number", ApertureSpec::Kind::ParaxialWorkingFNumber},
                                  std::pair{"object_space_na", ApertureSpec::Kind::ObjectSpaceNA},
                                  std::pair{"object_cone_angle_deg", ApertureSpec::Kind::ObjectConeAngleDeg}}) {
    if (auto v = r.get_optional_number(key)) {
      a = {kind, *v};
      key_given = key;
      ++given;
    }
  }
  r.finish({"entrance_pupil_diameter_mm", "f_number", "float_by_stop", "paraxial_working_f_number", "object_space_na",
            "object_cone_angle_deg"});
  if (given != 1) {
    r.fail("", "give exactly one of entrance_pupil_diameter_mm, f_number, float_by_stop, paraxial_working_f_number, "
               "object_space_na, object_cone_angle_deg");
  }
  if (a.kind != ApertureSpec::Kind::FloatByStop && !(std::isfinite(a.value) && a.value > 0.0)) r.fail(key_given, "must be finite and > 0");
  return a;
}

std::optional<FieldSpec> read_field(const LocatedJson& doc, JsonObjectReader& top) {
  if (!top.has("field")) return std::nullopt;
  top.get("field");
  JsonObjectReader r(doc, top.child_pointer("field"), "field");
  FieldSpec f;
  int given = 0;
  if (r.has("angle_deg")) {
    f = {FieldSpec::Kind::AngleDeg, read_number_list(r, "angle_deg")};
    ++given;
  }
  if (r.has("object_height_mm")) {
    f = {FieldSpec::Kind::ObjectHeightMm, read_number_list(r, "object_height_mm")};
    ++given;
  }
  if (r.has("image_height_mm")) {
    f = {FieldSpec::Kind::ImageHeightMm, read_number_list(r, "image_height_mm")};
    ++given;
  }
  if (r.has("real_image_height_mm")) {
    f = {FieldSpec::Kind::RealImageHeightMm, read_number_list(r, "real_image_height_mm")};
    ++given;
  }
  if (r.has("vignetting")) {
    const std::size_t count = r.get_array_size("vignetting");
    if (count != f.values.size()) {
      r.fail("vignetting", "gives " + std::to_string(count) + " sets of factors for " + std::to_string(f.values.size()) +
                               " field points; give one per point");
    }
    for (std::size_t i = 0; i < count; ++i) {
      JsonObjectReader v(doc, r.child_pointer("vignetting") + "/" + std::to_string(i), r.child_path("vignetting") + "[" + std::to_string(i) + "]");
      VignettingFactors factors;
      factors.vdx = v.get_optional_number("vdx").value_or(0.0);
      factors.vdy = v.get_optional_number("vdy").value_or(0.0);
      factors.vcx = v.get_optional_number("vcx").value_or(0.0);
      factors.vcy = v.get_optional_number("vcy").value_or(0.0);
      factors.van_deg = v.get_optional_number("van_deg").value_or(0.0);
      if (!(factors.vcx < 1.0)) v.fail("vcx", "must be below 1 (1 closes the pupil)");
      if (!(factors.vcy < 1.0)) v.fail("vcy", "must be below 1 (1 closes the pupil)");
      v.finish({"vdx", "vdy", "vcx", "vcy", "van_deg"});
      f.vignetting.push_back(factors);
    }
  }
  r.finish({"angle_deg", "object_height_mm", "image_height_mm", "real_image_height_mm", "vignetting"});
  if (given != 1) r.fail("", "give exactly one of angle_deg, object_height_mm, image_height_mm, real_image_height_mm");
  return f;
}

// A radius (mm) or "flat" as a curvature (1/mm).
double read_radius(JsonObjectReader& r, const std::string& key) {
  const json* v = r.get(key);
  if (v->is_string() && v->get<std::string>() == "flat") return 0.0;
  if (v->is_number()) {
    const double radius = v->get<double>();
    if (radius == 0.0 || !std::isfinite(radius)) r.fail(key, "must be finite and non-zero; write \"flat\" for a plane");
    return 1.0 / radius;
  }
  r.fail(key, "expected a number (mm) or \"flat\", got " + json_type_phrase(*v));
}

Surface read_surface(const LocatedJson& doc, const std::string& pointer, const std::string& path, bool last, bool* thickness_given) {
  JsonObjectReader r(doc, pointer, path);
  Surface s;
  const bool has_radius = r.has("radius_mm");
  const bool has_curvature = r.has("curvature_per_mm");
  if (has_radius && has_curvature) r.fail("curvature_per_mm", "give radius_mm or curvature_per_mm, not both");
  const int kinds = int(r.has("toroidal")) + int(r.has("biconic")) + int(r.has("coordinate_break"));
  if (kinds > 1) r.fail("", "a surface is one of toroidal, biconic or coordinate_break, not several");
  if (r.has("coordinate_break")) {
    // A coordinate break has no shape: only its decentres, tilts and thickness.
    for (const char* key : {"radius_mm", "curvature_per_mm", "material", "conic", "even_asphere", "mirror", "stop", "semi_diameter_mm",
                            "aperture", "clips_rays"}) {
      if (r.has(key)) r.fail(key, "a coordinate break has no " + std::string(key) + " (it only moves and turns the surfaces after it)");
    }
    r.get("coordinate_break");
    JsonObjectReader b(doc, r.child_pointer("coordinate_break"), r.child_path("coordinate_break"));
    s.kind = SurfaceKind::CoordinateBreak;
    CoordinateBreak& cb = s.coordinate_break;
    cb.decenter_x_mm = b.get_optional_number("decenter_x_mm").value_or(0.0);
    cb.decenter_y_mm = b.get_optional_number("decenter_y_mm").value_or(0.0);
    cb.tilt_x_deg = b.get_optional_number("tilt_x_deg").value_or(0.0);
    cb.tilt_y_deg = b.get_optional_number("tilt_y_deg").value_or(0.0);
    cb.tilt_z_deg = b.get_optional_number("tilt_z_deg").value_or(0.0);
    const std::string order = b.get_optional_string("order").value_or("decenter_first");
    if (order != "decenter_first" && order != "tilt_first") {
      b.fail("order", "expected \"decenter_first\" (Zemax order 0) or \"tilt_first\" (order 1), got \"" + order + "\"");
    }
    cb.tilt_first = order == "tilt_first";
    b.finish(kBreakKeys);
    auto thickness = r.get_optional_number("thickness_mm");
    *thickness_given = thickness.has_value();
    if (thickness) {
      s.thickness_mm = *thickness;
    } else if (!last) {
      r.fail("", "missing thickness_mm (distance to the next vertex along the new z axis, mm)");
    }
    s.comment = r.get_optional_string("comment").value_or("");
    r.finish(kSurfaceKeys);
    return s;
  }
  if (r.has("toroidal")) {
    r.get("toroidal");
    JsonObjectReader t(doc, r.child_pointer("toroidal"), r.child_path("toroidal"));
    s.kind = SurfaceKind::Toroidal;
    if (!t.has("radius_of_rotation_mm")) t.fail("", "missing radius_of_rotation_mm (mm, or \"flat\" for a cylinder)");
    s.curvature_x_per_mm = read_radius(t, "radius_of_rotation_mm");
    t.finish({"radius_of_rotation_mm"});
  }
  if (r.has("biconic")) {
    r.get("biconic");
    JsonObjectReader b(doc, r.child_pointer("biconic"), r.child_path("biconic"));
    s.kind = SurfaceKind::Biconic;
    if (!b.has("radius_x_mm")) b.fail("", "missing radius_x_mm (mm, or \"flat\")");
    s.curvature_x_per_mm = read_radius(b, "radius_x_mm");
    s.conic_x = b.get_optional_number("conic_x").value_or(0.0);
    b.finish({"radius_x_mm", "conic_x"});
  }
  s.mirror = r.get_optional_bool("mirror").value_or(false);
  if (s.mirror && r.has("material")) r.fail("material", "a mirror has no material: the medium before it continues after the reflection");
  if (has_radius) {
    const json* v = r.get("radius_mm");
    if (v->is_string() && v->get<std::string>() == "flat") {
      s.curvature_per_mm = 0.0;
    } else if (v->is_number()) {
      const double radius = v->get<double>();
      if (radius == 0.0 || !std::isfinite(radius)) r.fail("radius_mm", "must be finite and non-zero; write \"flat\" for a plane");
      s.curvature_per_mm = 1.0 / radius;
    } else {
      r.fail("radius_mm", "expected a number (mm) or \"flat\", got " + json_type_phrase(*v));
    }
  } else if (has_curvature) {
    s.curvature_per_mm = r.get_number("curvature_per_mm");
    if (!std::isfinite(s.curvature_per_mm)) r.fail("curvature_per_mm", "must be finite");
  } else {
    r.fail("", "missing radius_mm (a number or \"flat\") or curvature_per_mm");
  }

  auto thickness = r.get_optional_number("thickness_mm");
  *thickness_given = thickness.has_value();
  if (thickness) {
    s.thickness_mm = *thickness;
  } else if (!last) {
    r.fail("", "missing thickness_mm (distance to the next vertex, mm)");
  }
  if (r.has("material")) {
    r.get("material");
    s.material = read_material(doc, r.child_pointer("material"), r.child_path("material"));
  }
  s.semi_diameter_mm = r.get_optional_number("semi_diameter_mm");
  if (s.semi_diameter_mm && !(*s.semi_diameter_mm > 0.0)) r.fail("semi_diameter_mm", "must be > 0");
  s.clips_rays = r.get_optional_bool("clips_rays").value_or(true);
  if (!s.clips_rays && !s.semi_diameter_mm) r.fail("clips_rays", "false is meaningful only with a semi_diameter_mm");
  if (r.has("aperture")) {
    r.get("aperture");
    s.aperture = read_surface_aperture(doc, r.child_pointer("aperture"), r.child_path("aperture"));
  }
  s.is_stop = r.get_optional_bool("stop").value_or(false);
  s.conic = r.get_optional_number("conic").value_or(0.0);
  if (r.has("even_asphere")) {
    r.get("even_asphere");
    JsonObjectReader a(doc, r.child_pointer("even_asphere"), r.child_path("even_asphere"));
    for (std::size_t j = 0; j < kAsphereKeys.size(); ++j) {
      s.even_asphere[j] = a.get_optional_number(kAsphereKeys[j]).value_or(0.0);
    }
    a.finish(kAsphereKeys);
  }
  s.comment = r.get_optional_string("comment").value_or("");
  r.finish(kSurfaceKeys);
  return s;
}

}  // namespace

SurfaceAperture read_surface_aperture(const LocatedJson& doc, const std::string& pointer, const std::string& path) {
  JsonObjectReader r(doc, pointer, path);
  SurfaceAperture a;
  const std::string shape = r.get_optional_string("shape").value_or("circular");
  if (shape == "circular") {
    a.shape = SurfaceAperture::Shape::Circular;
    a.half_x_mm = a.half_y_mm = r.get_number("radius_mm");
    if (!(a.half_x_mm > 0.0)) r.fail("radius_mm", "must be > 0");
    if (r.has("half_x_mm") || r.has("half_y_mm")) r.fail("half_x_mm", "a circular aperture has radius_mm, not half widths");
    a.min_radius_mm = r.get_optional_number("min_radius_mm").value_or(0.0);
    if (!(a.min_radius_mm >= 0.0 && a.min_radius_mm < a.half_x_mm)) r.fail("min_radius_mm", "must lie in [0, radius_mm)");
  } else if (shape == "rectangular" || shape == "elliptical") {
    a.shape = shape == "rectangular" ? SurfaceAperture::Shape::Rectangular : SurfaceAperture::Shape::Elliptical;
    a.half_x_mm = r.get_number("half_x_mm");
    a.half_y_mm = r.get_number("half_y_mm");
    if (!(a.half_x_mm > 0.0)) r.fail("half_x_mm", "must be > 0");
    if (!(a.half_y_mm > 0.0)) r.fail("half_y_mm", "must be > 0");
    if (r.has("radius_mm") || r.has("min_radius_mm")) r.fail("radius_mm", "a " + shape + " aperture has half_x_mm and half_y_mm");
  } else {
    r.fail("shape", "expected \"circular\", \"rectangular\" or \"elliptical\", got \"" + shape + "\"");
  }
  a.obscuration = r.get_optional_bool("obscuration").value_or(false);
  if (a.obscuration && a.min_radius_mm > 0.0) r.fail("min_radius_mm", "an obscuration has no inner radius");
  a.decenter_x_mm = r.get_optional_number("decenter_x_mm").value_or(0.0);
  a.decenter_y_mm = r.get_optional_number("decenter_y_mm").value_or(0.0);
  r.finish(kApertureKeys);
  return a;
}

LensReadResult read_lens_json(std::string_view text, const std::string& file_name, const GlassCatalog& catalogue) {
  const LocatedJson doc = LocatedJson::parse(text, file_name);
  JsonObjectReader top(doc, "", "");
  LensReadResult result;
  Prescription& p = result.prescription;

  const std::string format = top.get_string("format");
  if (format != kFormatName) top.fail("format", "expected \"" + std::string(kFormatName) + "\", got \"" + format + "\"");
  const double version = top.get_number("version");
  if (version != std::floor(version) || version < 1 || version > kLensFormatVersion) {
    top.fail("version", "this build reads versions 1 to " + std::to_string(kLensFormatVersion));
  }
  p.name = top.get_string("name");
  p.source = top.get_optional_string("source").value_or("");
  p.notes = top.get_optional_string("notes").value_or("");
  p.object_distance_mm = read_length_or_infinity(top, "object_distance_mm", kInfinity);
  if (!(p.object_distance_mm > 0.0)) top.fail("object_distance_mm", "must be > 0 mm or \"infinity\"");
  if (top.has("object_material")) {
    top.get("object_material");
    p.object_material = read_material(doc, top.child_pointer("object_material"), "object_material");
  }
  p.aperture = read_aperture(doc, top);
  p.field = read_field(doc, top);
  p.object_space_telecentric = top.get_optional_bool("object_space_telecentric").value_or(false);
  if (auto aiming = top.get_optional_string("ray_aiming")) {
    if (*aiming == "real") {
      p.ray_aiming = RayAiming::RealStop;
    } else if (*aiming != "paraxial") {
      top.fail("ray_aiming", "expected \"paraxial\" (at the paraxial entrance pupil) or \"real\" (onto the real stop)");
    }
  }

  if (top.has("wavelengths_nm")) {
    p.wavelengths_nm = read_number_list(top, "wavelengths_nm");
    auto primary = top.get_optional_number("primary_wavelength_nm");
    if (!primary) {
      if (p.wavelengths_nm.size() > 1) top.fail("wavelengths_nm", "primary_wavelength_nm is missing; with several wavelengths one must be named primary");
      p.primary_wavelength_index = 0;
    } else {
      bool found = false;
      for (std::size_t i = 0; i < p.wavelengths_nm.size(); ++i) {
        if (p.wavelengths_nm[i] == *primary) {
          p.primary_wavelength_index = i;
          found = true;
          break;
        }
      }
      if (!found) top.fail("primary_wavelength_nm", "must be one of wavelengths_nm");
    }
  } else if (auto primary = top.get_optional_number("primary_wavelength_nm")) {
    bool found = false;
    for (std::size_t i = 0; i < p.wavelengths_nm.size(); ++i) {
      if (p.wavelengths_nm[i] == *primary) {
        p.primary_wavelength_index = i;
        found = true;
      }
    }
    if (!found) top.fail("primary_wavelength_nm", "without wavelengths_nm it must be one of the defaults 486.1327, 587.5618, 656.2725");
  }

  const std::size_t count = top.get_array_size("surfaces");
  if (count == 0) top.fail("surfaces", "a lens needs at least one surface");
  constexpr std::size_t kMaxSurfaces = 10000;  // far beyond any real lens; bounds hostile input
  if (count > kMaxSurfaces) top.fail("surfaces", "more than 10000 surfaces");
  for (std::size_t i = 0; i < count; ++i) {
    const std::string pointer = "/surfaces/" + std::to_string(i);
    const std::string path = "surfaces[" + std::to_string(i) + "] (surface " + std::to_string(i + 1) + ")";
    bool thickness_given = false;
    p.surfaces.push_back(read_surface(doc, pointer, path, i + 1 == count, &thickness_given));
    if (i + 1 == count) p.image_at_paraxial_focus = !thickness_given;
  }
  top.finish(kTopKeys);

  try {
    p.resolve_materials(catalogue);
    p.validate();
  } catch (const SubjectError& e) {
    // Point at the surface the error is about, else at the top of the file.
    SourceLocation where{file_name, 1, 1};
    const int n = e.subject().surface;
    if (n >= 1 && static_cast<std::size_t>(n) <= count) where = doc.where("/surfaces/" + std::to_string(n - 1));
    throw FileError(where, e.what());
  } catch (const Error& e) {
    throw FileError(SourceLocation{file_name, 1, 1}, e.what());
  }
  return result;
}

namespace {

using ojson = nlohmann::ordered_json;

ojson radius_value(double curvature_per_mm) {
  if (curvature_per_mm == 0.0) return "flat";
  return 1.0 / curvature_per_mm;
}


ojson write_material(const MaterialSpec& m) {
  switch (m.kind) {
    case MaterialSpec::Kind::Air: return "air";
    case MaterialSpec::Kind::Catalog:
      if (m.vendor.empty()) return m.glass;
      return ojson{{"glass", m.glass}, {"vendor", m.vendor}};
    case MaterialSpec::Kind::Model: {
      ojson o{{"nd", m.nd}};
      if (m.vd) o["vd"] = *m.vd;
      return o;
    }
  }
  return "air";
}

ojson write_numbers(const std::vector<double>& values) {
  ojson a = ojson::array();
  for (double v : values) a.push_back(v);
  return a;
}

}  // namespace

std::string write_lens_json(const Prescription& p) {
  ojson o;
  o["format"] = kFormatName;
  o["version"] = kLensFormatVersion;
  o["name"] = p.name;
  if (!p.source.empty()) o["source"] = p.source;
  if (!p.notes.empty()) o["notes"] = p.notes;
  if (std::isinf(p.object_distance_mm)) {
    o["object_distance_mm"] = "infinity";
  } else {
    o["object_distance_mm"] = p.object_distance_mm;
  }
  if (p.object_material.kind != MaterialSpec::Kind::Air) o["object_material"] = write_material(p.object_material);
  switch (p.aperture.kind) {
    case ApertureSpec::Kind::EntrancePupilDiameter: o["aperture"] = ojson{{"entrance_pupil_diameter_mm", p.aperture.value}}; break;
    case ApertureSpec::Kind::ImageSpaceFNumber: o["aperture"] = ojson{{"f_number", p.aperture.value}}; break;
    case ApertureSpec::Kind::FloatByStop: o["aperture"] = ojson{{"float_by_stop", true}}; break;
    case ApertureSpec::Kind::ParaxialWorkingFNumber: o["aperture"] = ojson{{"paraxial_working_f_number", p.aperture.value}}; break;
    case ApertureSpec::Kind::ObjectSpaceNA: o["aperture"] = ojson{{"object_space_na", p.aperture.value}}; break;
    case ApertureSpec::Kind::ObjectConeAngleDeg: o["aperture"] = ojson{{"object_cone_angle_deg", p.aperture.value}}; break;
  }
  if (p.field) {
    const char* key = p.field->kind == FieldSpec::Kind::AngleDeg         ? "angle_deg"
                      : p.field->kind == FieldSpec::Kind::ObjectHeightMm ? "object_height_mm"
                      : p.field->kind == FieldSpec::Kind::ImageHeightMm  ? "image_height_mm"
                                                                         : "real_image_height_mm";
    o["field"] = ojson{{key, write_numbers(p.field->values)}};
    if (!p.field->vignetting.empty()) {
      ojson list = ojson::array();
      for (const VignettingFactors& v : p.field->vignetting) {
        ojson one = ojson::object();
        for (const auto& [name, value] : {std::pair{"vdx", v.vdx}, std::pair{"vdy", v.vdy}, std::pair{"vcx", v.vcx},
                                          std::pair{"vcy", v.vcy}, std::pair{"van_deg", v.van_deg}}) {
          if (value != 0.0) one[name] = value;
        }
        list.push_back(one);
      }
      o["field"]["vignetting"] = list;
    }
  }
  o["wavelengths_nm"] = write_numbers(p.wavelengths_nm);
  o["primary_wavelength_nm"] = p.primary_wavelength_nm();
  if (p.ray_aiming == RayAiming::RealStop) o["ray_aiming"] = "real";
  if (p.object_space_telecentric) o["object_space_telecentric"] = true;
  ojson surfaces = ojson::array();
  for (std::size_t i = 0; i < p.surfaces.size(); ++i) {
    const Surface& s = p.surfaces[i];
    ojson j;
    const bool last = i + 1 == p.surfaces.size();
    if (s.is_coordinate_break()) {
      const CoordinateBreak& b = s.coordinate_break;
      ojson cb = ojson::object();
      if (b.decenter_x_mm != 0.0) cb["decenter_x_mm"] = b.decenter_x_mm;
      if (b.decenter_y_mm != 0.0) cb["decenter_y_mm"] = b.decenter_y_mm;
      if (b.tilt_x_deg != 0.0) cb["tilt_x_deg"] = b.tilt_x_deg;
      if (b.tilt_y_deg != 0.0) cb["tilt_y_deg"] = b.tilt_y_deg;
      if (b.tilt_z_deg != 0.0) cb["tilt_z_deg"] = b.tilt_z_deg;
      if (b.tilt_first) cb["order"] = "tilt_first";
      j["coordinate_break"] = cb;
      if (!(last && p.image_at_paraxial_focus)) j["thickness_mm"] = s.thickness_mm;
      if (!s.comment.empty()) j["comment"] = s.comment;
      surfaces.push_back(j);
      continue;
    }
    if (s.curvature_per_mm == 0.0) {
      j["radius_mm"] = "flat";
    } else if (1.0 / (1.0 / s.curvature_per_mm) == s.curvature_per_mm) {
      j["radius_mm"] = 1.0 / s.curvature_per_mm;  // exact round trip through the radius
    } else {
      j["curvature_per_mm"] = s.curvature_per_mm;
    }
    if (!(last && p.image_at_paraxial_focus)) j["thickness_mm"] = s.thickness_mm;
    if (s.mirror) {
      j["mirror"] = true;
    } else {
      j["material"] = write_material(s.material);
    }
    if (s.kind == SurfaceKind::Toroidal) j["toroidal"] = ojson{{"radius_of_rotation_mm", radius_value(s.curvature_x_per_mm)}};
    if (s.kind == SurfaceKind::Biconic) {
      ojson b;
      b["radius_x_mm"] = radius_value(s.curvature_x_per_mm);
      if (s.conic_x != 0.0) b["conic_x"] = s.conic_x;
      j["biconic"] = b;
    }
    if (s.semi_diameter_mm) j["semi_diameter_mm"] = *s.semi_diameter_mm;
    if (s.semi_diameter_mm && !s.clips_rays) j["clips_rays"] = false;
    if (s.aperture) j["aperture"] = surface_aperture_json<ojson>(*s.aperture);
    if (s.is_stop) j["stop"] = true;
    if (s.conic != 0.0) j["conic"] = s.conic;
    if (s.has_asphere()) {
      ojson a;
      for (std::size_t k = 0; k < s.even_asphere.size(); ++k) {
        if (s.even_asphere[k] != 0.0) a[kAsphereKeys[k]] = s.even_asphere[k];
      }
      j["even_asphere"] = a;
    }
    if (!s.comment.empty()) j["comment"] = s.comment;
    surfaces.push_back(j);
  }
  o["surfaces"] = surfaces;
  return json_text(o, 2) + "\n";
}

}  // namespace lensmith

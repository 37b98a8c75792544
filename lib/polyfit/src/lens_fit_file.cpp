// The lensmith-fit JSON file (docs/fit-format.md): written with every double in shortest round-trip
// form (nlohmann's dump), so a reloaded fit evaluates bit for bit like the one written; read strictly
// (unknown keys, wrong types, non-finite numbers and inconsistent sizes are errors with file:line:col).
#include <cmath>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lensmith/core/errors.h"
#include "lensmith/core/json_text.h"
#include "lensmith/core/located_json.h"
#include "lensmith/core/text_file.h"
#include "lensmith/core/units.h"
#include "lensmith/polyfit/lens_fit.h"
#include "lensmith/prescription/surface_aperture_json.h"

namespace lensmith {
namespace {

using nlohmann::json;

constexpr const char* kFormat = "lensmith-fit";
// Version 1: rotationally symmetric lenses (invariant terms). Version 2 adds the symmetry, the x
// section's pupils, the front surface's kind and component terms (anamorphic lenses); a rotational fit
// is still written as version 1, so that earlier lensmith reads it.
constexpr int kVersionRotational = 1;
constexpr int kVersionSections = 2;

constexpr std::array<const char*, 3> kFactorNames{"p", "d", "1"};
constexpr std::array<const char*, 3> kComponentNames{"x", "y", "1"};

json map_to_json(const FittedMap& fitted, const std::vector<std::string>& outputs) {
  json terms = json::array(), coefficients = json::array();
  auto add = [&](const auto& map, auto term_json) {
    for (std::size_t t = 0; t < map.size(); ++t) {
      terms.push_back(term_json(map.terms()[t]));
      json c = json::array();
      for (int k = 0; k < map.outputs(); ++k) c.push_back(map.coefficient(t, k));
      coefficients.push_back(c);
    }
  };
  if (fitted.is_rotational()) {
    add(fitted.rotational(), [](const InvariantTerm& term) {
      json e = json::array();
      for (const auto x : term.exponents) e.push_back(static_cast<int>(x));
      e.push_back(kFactorNames[static_cast<std::size_t>(term.factor)]);
      return e;
    });
  } else {
    add(fitted.component(), [](const ComponentTerm& term) {
      json e = json::array();
      for (const auto x : term.monomial.exponents) e.push_back(static_cast<int>(x));
      e.push_back(kComponentNames[static_cast<std::size_t>(term.component)]);
      return e;
    });
  }
  return json{{"outputs", outputs}, {"terms", terms}, {"coefficients", coefficients}};
}

json pupils_to_json(const LensFit::Pupils& p) {
  return {{"z_entrance_pupil_mm", p.z_entrance_pupil_mm},
          {"entrance_per_stop", p.entrance_per_stop},
          {"z_exit_pupil_mm", p.z_exit_pupil_mm},
          {"exit_per_stop", p.exit_per_stop}};
}

std::vector<std::string> clip_names(const std::vector<ClipSurface>& clip) {
  std::vector<std::string> names;
  for (std::size_t q = 0; q < clip.size(); ++q) {
    names.push_back("position on surface " + std::to_string(clip[q].surface) + (q == 0 ? " (stop), mm" : ", mm"));
  }
  return names;
}

class FitReader {
 public:
  explicit FitReader(const LocatedJson& doc) : doc_(doc) {}

  [[noreturn]] void fail(const std::string& pointer, const std::string& path, const std::string& message) const {
    throw FileError(doc_.where(pointer), path + ": " + message);
  }
  const json& at(const std::string& pointer) const { return doc_.root().at(json::json_pointer(pointer)); }
  double number(const std::string& pointer, const std::string& path) const {
    const json& v = at(pointer);
    if (!v.is_number()) fail(pointer, path, "expected a number, got " + json_type_phrase(v));
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(pointer, path, "must be finite");
    return x;
  }
  int integer(JsonObjectReader& r, const std::string& key, int min, int max) const {
    const double v = r.get_number(key);
    if (v != std::floor(v) || v < min || v > max) {
      r.fail(key, "expected a whole number in " + std::to_string(min) + ".." + std::to_string(max));
    }
    return static_cast<int>(v);
  }
  double positive(JsonObjectReader& r, const std::string& key) const {
    const double v = r.get_number(key);
    if (!(std::isfinite(v) && v > 0.0)) r.fail(key, "expected a finite number > 0");
    return v;
  }
  double finite(JsonObjectReader& r, const std::string& key) const {
    const double v = r.get_number(key);
    if (!std::isfinite(v)) r.fail(key, "expected a finite number");
    return v;
  }

  // The object at `key` of `parent` (consumed); an error when it is missing.
  JsonObjectReader object(JsonObjectReader& parent, const std::string& key) const {
    if (parent.get(key) == nullptr) parent.fail(key, "missing: expected an object");
    return JsonObjectReader(doc_, parent.child_pointer(key), parent.child_path(key));
  }

  // A map's terms: invariant ([u, v, w, lambda exponents, factor]) for a rotational fit, component
  // ([x, y, dx, dy, lambda exponents, component]) for a fit of section mirrors.
  FittedMap map(JsonObjectReader& parent, const std::string& key, int outputs, bool vector, bool rotational) const {
    JsonObjectReader r = object(parent, key);
    const std::size_t names = r.get_array_size("outputs");
    if (names != static_cast<std::size_t>(outputs)) {
      r.fail("outputs", "expected " + std::to_string(outputs) + " outputs, got " + std::to_string(names));
    }
    const std::size_t count = r.get_array_size("terms");
    if (count == 0) r.fail("terms", "expected at least one term");
    if (r.get_array_size("coefficients") != count) {
      r.fail("coefficients", "expected one row per term (" + std::to_string(count) + ")");
    }
    const std::size_t exponents = rotational ? 4 : kPolyVariables;
    const std::string shape = rotational ? std::string("[u, v, w, lambda exponents, factor ") + (vector ? "\"p\" or \"d\"]" : "\"1\"]")
                                         : std::string("[x, y, dx, dy, lambda exponents, component ") +
                                               (vector ? "\"x\" or \"y\"]" : "\"1\"]");
    std::vector<InvariantTerm> invariant_terms(rotational ? count : 0);
    std::vector<ComponentTerm> component_terms(rotational ? 0 : count);
    std::vector<double> coefficients;
    for (std::size_t t = 0; t < count; ++t) {
      const std::string tp = r.child_pointer("terms") + "/" + std::to_string(t);
      const std::string tpath = r.child_path("terms") + "[" + std::to_string(t) + "]";
      const json& e = at(tp);
      if (!e.is_array() || e.size() != exponents + 1) fail(tp, tpath, "expected " + shape);
      int degree = 0;
      for (std::size_t i = 0; i < exponents; ++i) {
        const double v = number(tp + "/" + std::to_string(i), tpath + "[" + std::to_string(i) + "]");
        if (v != std::floor(v) || v < 0 || v > kMaxPolyDegree) {
          fail(tp + "/" + std::to_string(i), tpath, "an exponent must be a whole number in 0.." + std::to_string(kMaxPolyDegree));
        }
        if (rotational) {
          invariant_terms[t].exponents[i] = static_cast<std::uint8_t>(v);
        } else {
          component_terms[t].monomial.exponents[i] = static_cast<std::uint8_t>(v);
        }
      }
      const std::string fp = tp + "/" + std::to_string(exponents);
      const std::string fpath = tpath + "[" + std::to_string(exponents) + "]";
      const json& f = at(fp);
      const std::string factor = f.is_string() ? f.get<std::string>() : std::string();
      if (rotational) {
        if (vector && factor == "p") {
          invariant_terms[t].factor = RayFactor::kPosition;
        } else if (vector && factor == "d") {
          invariant_terms[t].factor = RayFactor::kDirection;
        } else if (!vector && factor == "1") {
          invariant_terms[t].factor = RayFactor::kOne;
        } else {
          fail(fp, fpath, std::string("expected the factor ") + (vector ? "\"p\" or \"d\"" : "\"1\""));
        }
        degree = invariant_terms[t].total_degree();
      } else {
        if (vector && factor == "x") {
          component_terms[t].component = MapComponent::kX;
        } else if (vector && factor == "y") {
          component_terms[t].component = MapComponent::kY;
        } else if (!vector && factor == "1") {
          component_terms[t].component = MapComponent::kScalar;
        } else {
          fail(fp, fpath, std::string("expected the component ") + (vector ? "\"x\" or \"y\"" : "\"1\""));
        }
        degree = component_terms[t].total_degree();
      }
      if (degree > kMaxPolyDegree) fail(tp, tpath, "total degree above " + std::to_string(kMaxPolyDegree));
      const std::string cp = r.child_pointer("coefficients") + "/" + std::to_string(t);
      const std::string cpath = r.child_path("coefficients") + "[" + std::to_string(t) + "]";
      const json& c = at(cp);
      if (!c.is_array() || c.size() != static_cast<std::size_t>(outputs)) {
        fail(cp, cpath, "expected " + std::to_string(outputs) + " coefficients (one per output)");
      }
      for (int k = 0; k < outputs; ++k) {
        coefficients.push_back(number(cp + "/" + std::to_string(k), cpath + "[" + std::to_string(k) + "]"));
      }
    }
    r.finish({"outputs", "terms", "coefficients"});
    try {
      if (rotational) return RotationalMap(std::move(invariant_terms), outputs, std::move(coefficients));
      return ComponentMap(std::move(component_terms), outputs, std::move(coefficients));
    } catch (const FitError& e) {
      parent.fail(key, e.what());
    }
  }

  LensFit::Pupils pupils(JsonObjectReader& parent, const std::string& key) const {
    JsonObjectReader p = object(parent, key);
    LensFit::Pupils out;
    out.z_entrance_pupil_mm = finite(p, "z_entrance_pupil_mm");
    out.entrance_per_stop = finite(p, "entrance_per_stop");
    out.z_exit_pupil_mm = finite(p, "z_exit_pupil_mm");
    out.exit_per_stop = finite(p, "exit_per_stop");
    p.finish({"z_entrance_pupil_mm", "entrance_per_stop", "z_exit_pupil_mm", "exit_per_stop"});
    return out;
  }

 private:
  const LocatedJson& doc_;
};

}  // namespace

std::string LensFit::to_json() const {
  json root;
  const bool rotational = symmetry_ == LensSymmetry::kRotational;
  root["format"] = kFormat;
  root["version"] = rotational ? kVersionRotational : kVersionSections;
  if (!rotational) root["symmetry"] = std::string(lensmith::to_string(symmetry_));
  root["lens"] = {{"name", lens_name_}, {"prescription_hash", lens_hash_}};
  json options = {{"degree", options_.degree},
                  {"terms", options_.terms},
                  {"term_budget", term_budget_},
                  {"training_rays", options_.training_rays},
                  {"test_rays", options_.test_rays},
                  {"seed", options_.seed},
                  {"min_wavelength_nm", options_.min_wavelength_nm},
                  {"max_wavelength_nm", options_.max_wavelength_nm},
                  {"pupil_margin", options_.pupil_margin},
                  {"aperture_margin", options_.aperture_margin}};
  if (options_.image_radius_mm) options["image_radius_mm"] = *options_.image_radius_mm;
  if (options_.f_number) options["f_number"] = *options_.f_number;
  root["options"] = options;
  root["sensor_plane_z_mm"] = sensor_z_mm_;
  root["image_radius_mm"] = image_radius_mm_;
  json clip = json::array();
  for (const ClipSurface& c : clip_) {
    json entry = {{"surface", c.surface}};
    // An explicit aperture clips instead of the semi-diameter, which may then be unlimited.
    if (std::isfinite(c.semi_diameter_mm)) entry["semi_diameter_mm"] = c.semi_diameter_mm;
    if (c.aperture) entry["aperture"] = surface_aperture_json<json>(*c.aperture);
    clip.push_back(entry);
  }
  root["clip_surfaces"] = clip;
  root["scales"] = {{"sensor_position_mm", scales_.sensor_position_mm},
                    {"sensor_direction", scales_.sensor_direction},
                    {"outer_position_mm", scales_.outer_position_mm},
                    {"outer_direction", scales_.outer_direction},
                    {"wavelength_centre_nm", scales_.wavelength_centre_nm},
                    {"wavelength_half_range_nm", scales_.wavelength_half_range_nm}};
  root["pupils"] = pupils_to_json(pupils_);
  if (!rotational) root["pupils_x"] = pupils_to_json(pupils_x_);
  root["front_surface"] = {{"curvature_per_mm", front_.curvature_per_mm},
                           {"conic", front_.conic},
                           {"even_asphere", front_.even_asphere}};
  if (!rotational) {
    root["front_surface"]["kind"] = std::string(lensmith::to_string(front_.kind));
    root["front_surface"]["curvature_x_per_mm"] = front_.curvature_x_per_mm;
    root["front_surface"]["conic_x"] = front_.conic_x;
  }
  root["maps"] = {
      {"sensor_to_outer", map_to_json(sensor_to_outer_, {"position on the outer plane, mm", "direction on the outer plane"})},
      {"sensor_to_clip", map_to_json(sensor_clip_, clip_names(clip_))},
      {"outer_to_sensor", map_to_json(outer_to_sensor_, {"position on the sensor plane, mm", "direction on the sensor plane"})},
      {"outer_to_clip", map_to_json(outer_clip_, clip_names(clip_))},
      {"transmittance", map_to_json(transmittance_, {"uncoated Fresnel transmittance"})}};
  root["test_errors"] = {{"test_rays", errors_.test_rays},
                         {"position_rms_um", errors_.position_rms_um},
                         {"position_p99_um", errors_.position_p99_um},
                         {"direction_rms_mrad", errors_.direction_rms_mrad},
                         {"stop_rms_um", errors_.stop_rms_um},
                         {"transmittance_rms", errors_.transmittance_rms},
                         {"sensor_position_rms_um", errors_.sensor_position_rms_um},
                         {"sensor_position_p99_um", errors_.sensor_position_p99_um},
                         {"sensor_direction_rms_mrad", errors_.sensor_direction_rms_mrad},
                         {"vignetting_mismatch", errors_.vignetting_mismatch}};
  root["timing"] = {{"fit_seconds", timing_.fit_seconds},
                    {"exact_ns_per_ray", timing_.exact_ns_per_ray},
                    {"poly_ns_per_ray", timing_.poly_ns_per_ray}};
  return json_text(root, 1) + "\n";
}

void LensFit::write(const std::string& path) const { write_file_atomically(path, to_json()); }

LensFit LensFit::read(const std::string& path) {
  const std::string bytes = read_file_bytes(path);
  return parse(decode_text(bytes, path), path);
}

LensFit LensFit::parse(std::string_view text, const std::string& file_name) {
  const LocatedJson doc = LocatedJson::parse(text, file_name);
  const FitReader in(doc);
  JsonObjectReader top(doc, "", "");
  if (top.get_string("format") != kFormat) top.fail("format", std::string("expected \"") + kFormat + "\"");
  const double version = top.get_number("version");
  if (version != kVersionRotational && version != kVersionSections) {
    top.fail("version", "this lensmith reads version " + std::to_string(kVersionRotational) + " and " +
                            std::to_string(kVersionSections) + " fit files");
  }
  const bool sections = version == kVersionSections;
  LensFit fit;
  if (sections) {
    const std::string symmetry = top.get_string("symmetry");
    if (symmetry == lensmith::to_string(LensSymmetry::kRotational)) {
      fit.symmetry_ = LensSymmetry::kRotational;
    } else if (symmetry == lensmith::to_string(LensSymmetry::kSectionMirrors)) {
      fit.symmetry_ = LensSymmetry::kSectionMirrors;
    } else {
      top.fail("symmetry", "expected \"rotational\" or \"section mirrors\"");
    }
  }
  const bool rotational = fit.symmetry_ == LensSymmetry::kRotational;
  {
    JsonObjectReader lens = in.object(top, "lens");
    fit.lens_name_ = lens.get_string("name");
    fit.lens_hash_ = lens.get_string("prescription_hash");
    if (fit.lens_hash_.size() != 16 || fit.lens_hash_.find_first_not_of("0123456789abcdef") != std::string::npos) {
      lens.fail("prescription_hash", "expected 16 lower-case hex digits");
    }
    lens.finish({"name", "prescription_hash"});
  }
  {
    JsonObjectReader o = in.object(top, "options");
    LensFitOptions& opt = fit.options_;
    opt.degree = in.integer(o, "degree", 1, kMaxPolyDegree);
    opt.terms = in.integer(o, "terms", 0, 1 << 20);
    fit.term_budget_ = in.integer(o, "term_budget", 1, 1 << 20);
    opt.training_rays = in.integer(o, "training_rays", 1, 1 << 30);
    opt.test_rays = in.integer(o, "test_rays", 1, 1 << 30);
    const json* seed = o.get("seed");
    if (seed == nullptr || !seed->is_number_unsigned()) o.fail("seed", "expected a whole number >= 0");
    opt.seed = seed->get<std::uint64_t>();
    opt.min_wavelength_nm = in.positive(o, "min_wavelength_nm");
    opt.max_wavelength_nm = in.positive(o, "max_wavelength_nm");
    if (o.has("image_radius_mm")) opt.image_radius_mm = in.positive(o, "image_radius_mm");
    if (o.has("f_number")) opt.f_number = in.positive(o, "f_number");
    opt.pupil_margin = in.positive(o, "pupil_margin");
    opt.aperture_margin = in.positive(o, "aperture_margin");
    o.finish({"degree", "terms", "term_budget", "training_rays", "test_rays", "seed", "min_wavelength_nm", "max_wavelength_nm",
              "image_radius_mm", "f_number", "pupil_margin", "aperture_margin"});
    if (!(opt.max_wavelength_nm > opt.min_wavelength_nm)) o.fail("max_wavelength_nm", "must exceed min_wavelength_nm");
  }
  fit.sensor_z_mm_ = in.finite(top, "sensor_plane_z_mm");
  fit.image_radius_mm_ = in.positive(top, "image_radius_mm");
  const std::size_t clips = top.get_array_size("clip_surfaces");
  if (clips < 1 || clips > static_cast<std::size_t>(kMaxMapOutputs)) {
    top.fail("clip_surfaces", "expected 1.." + std::to_string(kMaxMapOutputs) + " surfaces (the stop first)");
  }
  for (std::size_t q = 0; q < clips; ++q) {
    JsonObjectReader c(doc, top.child_pointer("clip_surfaces") + "/" + std::to_string(q),
                       top.child_path("clip_surfaces") + "[" + std::to_string(q) + "]");
    ClipSurface s;
    s.surface = in.integer(c, "surface", 1, 100000);
    if (c.get("aperture")) {
      if (q == 0) c.fail("aperture", "the stop clips as a circle: an explicit aperture is for the other surfaces");
      s.aperture = read_surface_aperture(doc, c.child_pointer("aperture"), c.child_path("aperture"));
      s.semi_diameter_mm = c.has("semi_diameter_mm") ? in.positive(c, "semi_diameter_mm") : kInfinity;
    } else {
      s.semi_diameter_mm = in.positive(c, "semi_diameter_mm");
    }
    c.finish({"surface", "semi_diameter_mm", "aperture"});
    fit.clip_.push_back(s);
  }
  {
    JsonObjectReader s = in.object(top, "scales");
    fit.scales_.sensor_position_mm = in.positive(s, "sensor_position_mm");
    fit.scales_.sensor_direction = in.positive(s, "sensor_direction");
    fit.scales_.outer_position_mm = in.positive(s, "outer_position_mm");
    fit.scales_.outer_direction = in.positive(s, "outer_direction");
    fit.scales_.wavelength_centre_nm = in.positive(s, "wavelength_centre_nm");
    fit.scales_.wavelength_half_range_nm = in.positive(s, "wavelength_half_range_nm");
    s.finish({"sensor_position_mm", "sensor_direction", "outer_position_mm", "outer_direction", "wavelength_centre_nm",
              "wavelength_half_range_nm"});
  }
  fit.pupils_ = in.pupils(top, "pupils");
  fit.pupils_x_ = sections ? in.pupils(top, "pupils_x") : fit.pupils_;
  {
    JsonObjectReader f = in.object(top, "front_surface");
    FrontSurface front;
    front.curvature_per_mm = in.finite(f, "curvature_per_mm");
    front.conic = in.finite(f, "conic");
    const std::size_t n = f.get_array_size("even_asphere");
    if (n != front.even_asphere.size()) f.fail("even_asphere", "expected 8 coefficients (a2 .. a16)");
    for (std::size_t i = 0; i < n; ++i) {
      front.even_asphere[i] = in.number(f.child_pointer("even_asphere") + "/" + std::to_string(i),
                                        f.child_path("even_asphere") + "[" + std::to_string(i) + "]");
    }
    if (sections) {
      const std::string kind = f.get_string("kind");
      if (kind == lensmith::to_string(SurfaceKind::Standard)) {
        front.kind = SurfaceKind::Standard;
      } else if (kind == lensmith::to_string(SurfaceKind::Toroidal)) {
        front.kind = SurfaceKind::Toroidal;
      } else if (kind == lensmith::to_string(SurfaceKind::Biconic)) {
        front.kind = SurfaceKind::Biconic;
      } else {
        f.fail("kind", "expected \"standard\", \"toroidal\" or \"biconic\"");
      }
      front.curvature_x_per_mm = in.finite(f, "curvature_x_per_mm");
      front.conic_x = in.finite(f, "conic_x");
    }
    if (sections) {
      f.finish({"curvature_per_mm", "conic", "even_asphere", "kind", "curvature_x_per_mm", "conic_x"});
    } else {
      f.finish({"curvature_per_mm", "conic", "even_asphere"});
    }
    fit.set_front_surface(front);
  }
  {
    JsonObjectReader m = in.object(top, "maps");
    const int clip_outputs = static_cast<int>(clips);
    fit.sensor_to_outer_ = in.map(m, "sensor_to_outer", 2, true, rotational);
    fit.sensor_clip_ = in.map(m, "sensor_to_clip", clip_outputs, true, rotational);
    fit.outer_to_sensor_ = in.map(m, "outer_to_sensor", 2, true, rotational);
    fit.outer_clip_ = in.map(m, "outer_to_clip", clip_outputs, true, rotational);
    fit.transmittance_ = in.map(m, "transmittance", 1, false, rotational);
    m.finish({"sensor_to_outer", "sensor_to_clip", "outer_to_sensor", "outer_to_clip", "transmittance"});
  }
  {
    JsonObjectReader e = in.object(top, "test_errors");
    LensFitErrors& x = fit.errors_;
    x.test_rays = in.integer(e, "test_rays", 0, 1 << 30);
    x.position_rms_um = in.finite(e, "position_rms_um");
    x.position_p99_um = in.finite(e, "position_p99_um");
    x.direction_rms_mrad = in.finite(e, "direction_rms_mrad");
    x.stop_rms_um = in.finite(e, "stop_rms_um");
    x.transmittance_rms = in.finite(e, "transmittance_rms");
    x.sensor_position_rms_um = in.finite(e, "sensor_position_rms_um");
    x.sensor_position_p99_um = in.finite(e, "sensor_position_p99_um");
    x.sensor_direction_rms_mrad = in.finite(e, "sensor_direction_rms_mrad");
    x.vignetting_mismatch = in.finite(e, "vignetting_mismatch");
    e.finish({"test_rays", "position_rms_um", "position_p99_um", "direction_rms_mrad", "stop_rms_um",
              "transmittance_rms", "sensor_position_rms_um", "sensor_position_p99_um", "sensor_direction_rms_mrad",
              "vignetting_mismatch"});
  }
  {
    JsonObjectReader t = in.object(top, "timing");
    fit.timing_.fit_seconds = in.finite(t, "fit_seconds");
    fit.timing_.exact_ns_per_ray = in.finite(t, "exact_ns_per_ray");
    fit.timing_.poly_ns_per_ray = in.finite(t, "poly_ns_per_ray");
    t.finish({"fit_seconds", "exact_ns_per_ray", "poly_ns_per_ray"});
  }
  std::vector<std::string> keys{"format", "version", "lens", "options", "sensor_plane_z_mm", "image_radius_mm", "clip_surfaces",
                                "scales", "pupils", "front_surface", "maps", "test_errors", "timing"};
  if (sections) keys.insert(keys.end(), {"symmetry", "pupils_x"});
  top.finish(keys);
  return fit;
}

}  // namespace lensmith

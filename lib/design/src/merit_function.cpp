// Variables, operands and the merit file (docs/optimize.md).
#include "lensmith/design/merit_function.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/core/located_json.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/text_file.h"
#include "lensmith/paraxial/paraxial_system.h"

namespace lensmith {

namespace {

// The glass map's extent (the built-in catalogues span nd 1.43-2.05 and Vd 17-95): the default bounds of a
// model-glass variable, so that the optimiser cannot choose a glass nobody makes.
constexpr double kGlassNdMin = 1.44, kGlassNdMax = 2.05;
constexpr double kGlassVdMin = 17.0, kGlassVdMax = 95.0;

constexpr int kMaxRings = 20;
constexpr int kMinGrid = 8, kMaxGrid = 64;

std::size_t asphere_index(int power) { return static_cast<std::size_t>(power / 2 - 1); }

const Surface& surface_of(const Prescription& lens, int surface) { return lens.surfaces.at(static_cast<std::size_t>(surface - 1)); }
Surface& surface_of(Prescription& lens, int surface) { return lens.surfaces.at(static_cast<std::size_t>(surface - 1)); }

}  // namespace

double DesignVariable::value(const Prescription& lens) const {
  const Surface& s = surface_of(lens, surface);
  switch (kind) {
    case Kind::Curvature: return s.curvature_per_mm;
    case Kind::Thickness: return s.thickness_mm;
    case Kind::Conic: return s.conic;
    case Kind::Asphere: return s.even_asphere.at(asphere_index(asphere_power));
    case Kind::GlassIndex: return s.medium.nd();
    case Kind::GlassAbbe: return s.medium.vd();
  }
  return 0.0;
}

void DesignVariable::apply(Prescription& lens, double v) const {
  Surface& s = surface_of(lens, surface);
  switch (kind) {
    case Kind::Curvature: s.curvature_per_mm = v; return;
    case Kind::Thickness: s.thickness_mm = v; return;
    case Kind::Conic: s.conic = v; return;
    case Kind::Asphere: s.even_asphere.at(asphere_index(asphere_power)) = v; return;
    case Kind::GlassIndex:
    case Kind::GlassAbbe: {
      const double nd = kind == Kind::GlassIndex ? v : s.medium.nd();
      const double vd = kind == Kind::GlassAbbe ? v : s.medium.vd();
      s.material = MaterialSpec::model(nd, vd);
      s.medium = Glass::model(nd, vd);
      return;
    }
  }
}

void EflSolve::apply(Prescription& lens) const {
  // The system power is affine in one surface's curvature (the surface's refraction enters the system matrix
  // once, linearly): two paraxial traces give it exactly.
  Surface& s = surface_of(lens, surface);
  const double c0 = s.curvature_per_mm;
  const double p0 = ParaxialSystem(lens).power_per_mm();
  s.curvature_per_mm = c0 + 1e-3 / std::max(1.0, std::abs(efl_mm));
  const double p1 = ParaxialSystem(lens).power_per_mm();
  const double slope = (p1 - p0) / (s.curvature_per_mm - c0);
  if (!(std::abs(slope) > 1e-12) || !std::isfinite(slope)) {
    s.curvature_per_mm = c0;
    throw ComputationError("the EFL solve on surface " + std::to_string(surface) + ": its curvature does not change the lens's power");
  }
  s.curvature_per_mm = c0 + (1.0 / efl_mm - p0) / slope;
}

std::string DesignVariable::name() const {
  const std::string at = " of surface " + std::to_string(surface);
  switch (kind) {
    case Kind::Curvature: return "curvature" + at;
    case Kind::Thickness: return "thickness after surface " + std::to_string(surface);
    case Kind::Conic: return "conic" + at;
    case Kind::Asphere: return "a" + std::to_string(asphere_power) + at;
    case Kind::GlassIndex: return "nd of the glass after surface " + std::to_string(surface);
    case Kind::GlassAbbe: return "Vd of the glass after surface " + std::to_string(surface);
  }
  return {};
}

std::string DesignVariable::unit() const {
  switch (kind) {
    case Kind::Curvature: return "1/mm";
    case Kind::Thickness: return "mm";
    case Kind::Asphere: return "mm^" + std::to_string(1 - asphere_power);
    default: return "";
  }
}

std::string Operand::label() const {
  const auto fields_and_wavelengths = [&] {
    std::string text = " (" + std::to_string(relative_fields.size()) + (relative_fields.size() == 1 ? " field" : " fields");
    if (!wavelengths_nm.empty()) text += ", " + std::to_string(wavelengths_nm.size()) + (wavelengths_nm.size() == 1 ? " wavelength" : " wavelengths");
    return text + ")";
  };
  switch (kind) {
    case Kind::Efl: return "EFL";
    case Kind::FNumber: return "f-number";
    case Kind::WorkingFNumber: return "working f-number";
    case Kind::Bfl: return "BFL";
    case Kind::TotalTrack: return "total track";
    case Kind::ImageDistance: return "image plane from paraxial focus";
    case Kind::Seidel: return "Seidel " + term;
    case Kind::SpotRms: return std::string("spot RMS") + (centroid_reference ? "" : " about the chief ray") + fields_and_wavelengths();
    case Kind::WavefrontRms: return "wavefront RMS" + fields_and_wavelengths();
    case Kind::Distortion: return "distortion at field " + format_number(relative_fields.front());
    case Kind::CentreThickness: return "centre thickness after surface " + std::to_string(surface);
    case Kind::EdgeThickness:
      return "edge thickness after surface " + std::to_string(surface) + (height_mm ? " at " + format_number(*height_mm) + " mm" : "");
    case Kind::RayHeight: return "ray height at surface " + std::to_string(surface) + fields_and_wavelengths();
  }
  return {};
}

std::string Operand::unit() const {
  switch (kind) {
    case Kind::FNumber:
    case Kind::WorkingFNumber: return "";
    case Kind::WavefrontRms: return "waves";
    case Kind::Distortion: return "%";
    default: return "mm";
  }
}

std::string Operand::goal() const {
  if (is_minimised()) return "min";
  if (target) return "= " + format_number(*target);
  if (min && max) return format_number(*min) + " to " + format_number(*max);
  if (min) return ">= " + format_number(*min);
  if (max) return "<= " + format_number(*max);
  return "?";
}

void MeritFunction::validate(const Prescription& lens) const {
  const int count = static_cast<int>(lens.surfaces.size());
  if (variables.empty()) throw OptionsError("merit function: no variables: nothing to optimise");
  if (operands.empty()) throw OptionsError("merit function: no operands: nothing to optimise for");
  if (field_angle_deg && !(*field_angle_deg > 0.0 && *field_angle_deg < 90.0)) {
    throw OptionsError("merit function: field_angle_deg = " + format_number(*field_angle_deg) + ": must be in (0, 90)");
  }
  std::set<std::tuple<int, int, int>> seen;
  for (std::size_t i = 0; i < variables.size(); ++i) {
    const DesignVariable& v = variables[i];
    const std::string where = "variables[" + std::to_string(i) + "] (" + v.name() + "): ";
    if (v.surface < 1 || v.surface > count) {
      throw OptionsError(where + "the lens has surfaces 1 to " + std::to_string(count));
    }
    const Surface& s = surface_of(lens, v.surface);
    const bool shape = v.kind == DesignVariable::Kind::Curvature || v.kind == DesignVariable::Kind::Conic ||
                       v.kind == DesignVariable::Kind::Asphere;
    if (shape && s.is_coordinate_break()) throw OptionsError(where + "surface " + std::to_string(v.surface) + " is a coordinate break: it has no shape");
    if (shape && !s.mirror) {
      const Glass& before = v.surface == 1 ? lens.object_medium : surface_of(lens, v.surface - 1).medium;
      if (before == s.medium) {
        throw OptionsError(where + "surface " + std::to_string(v.surface) + " has " + (s.medium.is_air() ? std::string("air") : s.medium.name()) +
                           " on both sides: its shape changes no ray");
      }
    }
    if (v.kind == DesignVariable::Kind::Asphere && (v.asphere_power < 4 || v.asphere_power > 16 || v.asphere_power % 2 != 0)) {
      throw OptionsError(where + "the even-asphere power must be 4, 6, ..., 16");
    }
    if (v.kind == DesignVariable::Kind::Thickness && v.surface == count && lens.image_at_paraxial_focus) {
      throw OptionsError(where + "the lens puts its image at the paraxial focus, so the last thickness is not used; "
                         "give the lens an image distance (\"image_at_paraxial_focus\": false) to vary it");
    }
    if (v.kind == DesignVariable::Kind::GlassIndex || v.kind == DesignVariable::Kind::GlassAbbe) {
      if (s.mirror || s.is_coordinate_break()) throw OptionsError(where + "surface " + std::to_string(v.surface) + " has no glass after it of its own");
      if (s.medium.is_air() || s.material.kind == MaterialSpec::Kind::Air) {
        throw OptionsError(where + "the medium after surface " + std::to_string(v.surface) + " is air: a glass variable changes a glass");
      }
      if (!std::isfinite(s.medium.vd())) {
        throw OptionsError(where + "the medium after surface " + std::to_string(v.surface) + " has no dispersion (" + s.material.to_string() +
                           "): give it a glass with an Abbe number to vary");
      }
    }
    if (v.min && v.max && !(*v.min < *v.max)) {
      throw OptionsError(where + "min " + format_number(*v.min) + " must be below max " + format_number(*v.max));
    }
    const double start = v.value(lens);
    if ((v.min && start < *v.min) || (v.max && start > *v.max)) {
      throw OptionsError(where + "starts at " + format_number(start) + ", outside its bounds [" + (v.min ? format_number(*v.min) : "-inf") + ", " +
                         (v.max ? format_number(*v.max) : "inf") + "]: the optimiser must start inside them");
    }
    if (!seen.insert({static_cast<int>(v.kind), v.surface, v.asphere_power}).second) throw OptionsError(where + "given twice");
    if (efl_solve && v.kind == DesignVariable::Kind::Curvature && v.surface == efl_solve->surface) {
      throw OptionsError(where + "is solved for the EFL: a curvature is either varied or solved");
    }
  }
  if (efl_solve) {
    const std::string where = "efl_solve: ";
    if (efl_solve->surface < 1 || efl_solve->surface > count) throw OptionsError(where + "the lens has surfaces 1 to " + std::to_string(count));
    const Surface& s = surface_of(lens, efl_solve->surface);
    if (s.is_coordinate_break() || s.kind != SurfaceKind::Standard) throw OptionsError(where + "surface " + std::to_string(efl_solve->surface) + " is not a standard surface");
    if (!(std::isfinite(efl_solve->efl_mm) && efl_solve->efl_mm != 0.0)) throw OptionsError(where + "efl_mm must be finite and nonzero");
  }
  const bool lens_has_field = lens.field.has_value() || field_angle_deg.has_value();
  for (std::size_t i = 0; i < operands.size(); ++i) {
    const Operand& o = operands[i];
    const std::string where = "operands[" + std::to_string(i) + "] (" + o.label() + "): ";
    if (!(std::isfinite(o.weight) && o.weight > 0.0)) throw OptionsError(where + "weight = " + format_number(o.weight) + ": must be > 0");
    if (o.is_minimised()) {
      if (o.target || o.min || o.max) throw OptionsError(where + "is minimised: it takes a weight, not a target or limits");
    } else {
      if (o.target && (o.min || o.max)) throw OptionsError(where + "give a target or limits (min, max), not both");
      if (!o.target && !o.min && !o.max) throw OptionsError(where + "needs a target or a limit (min, max)");
      if (o.min && o.max && !(*o.min < *o.max)) throw OptionsError(where + "min must be below max");
    }
    const bool needs_surface = o.kind == Operand::Kind::CentreThickness || o.kind == Operand::Kind::EdgeThickness || o.kind == Operand::Kind::RayHeight;
    if (needs_surface) {
      const int last = o.kind == Operand::Kind::EdgeThickness ? count - 1 : count;
      if (o.surface < 1 || o.surface > last) {
        throw OptionsError(where + "surface must be 1 to " + std::to_string(last) +
                           (o.kind == Operand::Kind::EdgeThickness ? " (the edge thickness lies between a surface and the next)" : ""));
      }
    }
    if (o.kind == Operand::Kind::EdgeThickness && !o.height_mm) {
      const Surface& a = surface_of(lens, o.surface);
      const Surface& b = surface_of(lens, o.surface + 1);
      if (!a.semi_diameter_mm && !b.semi_diameter_mm) throw OptionsError(where + "neither surface has a semi-diameter: give height_mm");
    }
    if (o.kind == Operand::Kind::Seidel) {
      static const std::vector<std::string> terms{"S1", "S2", "S3", "S4", "S5", "C1", "C2"};
      if (std::find(terms.begin(), terms.end(), o.term) == terms.end()) throw OptionsError(where + "term must be one of S1, S2, S3, S4, S5, C1, C2");
      if (const auto why = lens.why_not_rotationally_symmetric()) throw OptionsError(where + "Seidel sums need a rotationally symmetric lens: " + *why);
      if (o.term != "S1" && o.term != "C1" && !lens_has_field) throw OptionsError(where + "needs a field (the chief ray): give field_angle_deg");
    }
    if (o.relative_fields.empty()) throw OptionsError(where + "fields: give at least one relative field");
    for (double f : o.relative_fields) {
      if (!(f >= 0.0 && f <= 1.0)) throw OptionsError(where + "fields: " + format_number(f) + " is not a relative field in [0, 1]");
      const bool uses_fields = o.kind == Operand::Kind::SpotRms || o.kind == Operand::Kind::WavefrontRms || o.kind == Operand::Kind::RayHeight ||
                               o.kind == Operand::Kind::Distortion;
      if (uses_fields && f > 0.0 && !lens_has_field) throw OptionsError(where + "off-axis fields need the lens's field or field_angle_deg");
    }
    if (o.kind == Operand::Kind::Distortion && o.relative_fields.front() == 0.0) throw OptionsError(where + "distortion is defined off axis: field must be > 0");
    for (double w : o.wavelengths_nm) {
      if (!(w > 100.0 && w < 20000.0)) throw OptionsError(where + "wavelength " + format_number(w) + " nm: must be in (100, 20000)");
    }
    const auto check_weights = [&](const std::vector<double>& weights, std::size_t expected, const char* what) {
      if (weights.empty()) return;
      if (!o.is_minimised()) throw OptionsError(where + what + " apply to spot_rms and wavefront_rms only");
      if (weights.size() != expected) {
        throw OptionsError(where + what + ": " + std::to_string(weights.size()) + " weights for " + std::to_string(expected) + ": give one each");
      }
      double sum = 0.0;
      for (double w : weights) {
        if (!(std::isfinite(w) && w >= 0.0)) throw OptionsError(where + what + ": each weight must be >= 0");
        sum += w;
      }
      if (!(sum > 0.0)) throw OptionsError(where + what + ": at least one weight must be > 0");
    };
    check_weights(o.field_weights, o.relative_fields.size(), "field_weights");
    check_weights(o.wavelength_weights, o.wavelengths_nm.empty() ? lens.wavelengths_nm.size() : o.wavelengths_nm.size(), "wavelength_weights");
    if (o.rings < 1 || o.rings > kMaxRings) throw OptionsError(where + "rings must be 1 to " + std::to_string(kMaxRings));
    if (o.grid < kMinGrid || o.grid > kMaxGrid) throw OptionsError(where + "grid must be " + std::to_string(kMinGrid) + " to " + std::to_string(kMaxGrid));
  }
}

std::string MeritFunction::to_string() const {
  std::ostringstream os;
  os << "variables:\n";
  for (const DesignVariable& v : variables) {
    os << "  " << v.name();
    if (v.min || v.max) os << " in [" << (v.min ? format_number(*v.min) : "-inf") << ", " << (v.max ? format_number(*v.max) : "inf") << "]";
    os << "\n";
  }
  if (efl_solve) os << "solve: curvature of surface " << efl_solve->surface << " for EFL " << format_number(efl_solve->efl_mm) << " mm\n";
  os << "operands:\n";
  for (const Operand& o : operands) os << "  " << o.label() << " " << o.goal() << ", weight " << format_number(o.weight) << "\n";
  return os.str();
}

namespace {

class MeritReader {
 public:
  explicit MeritReader(const LocatedJson& doc) : doc_(doc) {}

  MeritFunction read() const {
    MeritFunction merit;
    JsonObjectReader root(doc_, "", "");
    root.get_optional_string("comment");
    if (const auto angle = root.get_optional_number("field_angle_deg")) {
      if (!(*angle > 0.0 && *angle < 90.0)) root.fail("field_angle_deg", "expected an angle in (0, 90) degrees");
      merit.field_angle_deg = angle;
    }
    const std::size_t variables = root.get_array_size("variables");
    if (variables == 0) root.fail("variables", "expected at least one variable");
    for (std::size_t i = 0; i < variables; ++i) read_variable(element(root, "variables", i), merit.variables);
    const std::size_t operands = root.get_array_size("operands");
    if (operands == 0) root.fail("operands", "expected at least one operand");
    for (std::size_t i = 0; i < operands; ++i) merit.operands.push_back(read_operand(element(root, "operands", i)));
    if (root.get("efl_solve") != nullptr) {
      JsonObjectReader solve(doc_, root.child_pointer("efl_solve"), root.child_path("efl_solve"));
      EflSolve e;
      e.surface = whole(solve, "surface", 1, 100000);
      e.efl_mm = solve.get_number("efl_mm");
      if (!std::isfinite(e.efl_mm) || e.efl_mm == 0.0) solve.fail("efl_mm", "expected a finite, nonzero focal length, mm");
      solve.finish({"surface", "efl_mm"});
      merit.efl_solve = e;
    }
    root.finish({"comment", "field_angle_deg", "variables", "operands", "efl_solve"});
    return merit;
  }

 private:
  JsonObjectReader element(const JsonObjectReader& parent, const std::string& key, std::size_t i) const {
    return JsonObjectReader(doc_, parent.child_pointer(key) + "/" + std::to_string(i), parent.child_path(key) + "[" + std::to_string(i) + "]");
  }

  static int whole(JsonObjectReader& r, const std::string& key, int min, int max) {
    const double v = r.get_number(key);
    if (v != std::floor(v) || v < min || v > max) r.fail(key, "expected a whole number " + std::to_string(min) + " to " + std::to_string(max));
    return static_cast<int>(v);
  }
  static std::optional<double> finite(JsonObjectReader& r, const std::string& key) {
    const auto v = r.get_optional_number(key);
    if (v && !std::isfinite(*v)) r.fail(key, "expected a finite number");
    return v;
  }

  std::vector<double> numbers(JsonObjectReader& r, const std::string& key) const {
    const std::size_t n = r.get_array_size(key);
    std::vector<double> values;
    for (std::size_t i = 0; i < n; ++i) {
      const std::string pointer = r.child_pointer(key) + "/" + std::to_string(i);
      const nlohmann::json& v = doc_.root().at(nlohmann::json::json_pointer(pointer));
      if (!v.is_number() || !std::isfinite(v.get<double>())) {
        throw FileError(doc_.where(pointer), r.child_path(key) + "[" + std::to_string(i) + "]: expected a finite number, got " + json_type_phrase(v));
      }
      values.push_back(v.get<double>());
    }
    return values;
  }

  void read_variable(JsonObjectReader r, std::vector<DesignVariable>& out) const {
    DesignVariable v;
    v.surface = whole(r, "surface", 1, 100000);
    const std::string parameter = r.get_string("parameter");
    v.min = finite(r, "min");
    v.max = finite(r, "max");
    r.finish({"surface", "parameter", "min", "max"});
    using K = DesignVariable::Kind;
    if (parameter == "curvature") {
      v.kind = K::Curvature;
    } else if (parameter == "thickness") {
      v.kind = K::Thickness;
    } else if (parameter == "conic") {
      v.kind = K::Conic;
    } else if (parameter.size() >= 2 && parameter[0] == 'a' && parse_finite_number(parameter.substr(1))) {
      const double power = *parse_finite_number(parameter.substr(1));
      if (power != std::floor(power) || power < 4 || power > 16 || static_cast<int>(power) % 2 != 0) {
        r.fail("parameter", "\"" + shown_text(parameter) + "\": the even-asphere coefficients are a4, a6, ..., a16 (a2 is a curvature: vary the curvature)");
      }
      v.kind = K::Asphere;
      v.asphere_power = static_cast<int>(power);
    } else if (parameter == "glass") {
      if (v.min || v.max) r.fail("parameter", "\"glass\" varies nd and Vd together within the glass map; to bound them, give glass_nd and glass_vd variables");
      DesignVariable nd = v, vd = v;
      nd.kind = K::GlassIndex;
      nd.min = kGlassNdMin;
      nd.max = kGlassNdMax;
      vd.kind = K::GlassAbbe;
      vd.min = kGlassVdMin;
      vd.max = kGlassVdMax;
      out.push_back(nd);
      out.push_back(vd);
      return;
    } else if (parameter == "glass_nd" || parameter == "glass_vd") {
      v.kind = parameter == "glass_nd" ? K::GlassIndex : K::GlassAbbe;
      if (!v.min) v.min = parameter == "glass_nd" ? kGlassNdMin : kGlassVdMin;
      if (!v.max) v.max = parameter == "glass_nd" ? kGlassNdMax : kGlassVdMax;
    } else {
      r.fail("parameter", "\"" + shown_text(parameter) + "\": expected curvature, thickness, conic, a4 ... a16, glass, glass_nd or glass_vd");
    }
    out.push_back(v);
  }

  Operand read_operand(JsonObjectReader r) const {
    Operand o;
    using K = Operand::Kind;
    static const std::vector<std::pair<std::string, K>> kinds{
        {"efl", K::Efl}, {"f_number", K::FNumber}, {"working_f_number", K::WorkingFNumber}, {"bfl", K::Bfl},
        {"total_track", K::TotalTrack}, {"image_distance", K::ImageDistance}, {"seidel", K::Seidel}, {"spot_rms", K::SpotRms},
        {"wavefront_rms", K::WavefrontRms}, {"distortion", K::Distortion}, {"centre_thickness", K::CentreThickness},
        {"edge_thickness", K::EdgeThickness}, {"ray_height", K::RayHeight}};
    const std::string type = r.get_string("type");
    const auto found = std::find_if(kinds.begin(), kinds.end(), [&](const auto& k) { return k.first == type; });
    if (found == kinds.end()) {
      std::string names;
      for (const auto& k : kinds) names += (names.empty() ? "" : ", ") + k.first;
      r.fail("type", "\"" + shown_text(type) + "\": expected one of " + names);
    }
    o.kind = found->second;
    std::vector<std::string> allowed{"type", "weight", "comment"};
    const auto allow = [&](std::initializer_list<const char*> keys) { allowed.insert(allowed.end(), keys.begin(), keys.end()); };
    r.get_optional_string("comment");
    if (const auto w = finite(r, "weight")) {
      if (*w <= 0.0) r.fail("weight", "expected a weight > 0");
      o.weight = *w;
    }
    if (!o.is_minimised()) {
      allow({"target", "min", "max"});
      o.target = finite(r, "target");
      o.min = finite(r, "min");
      o.max = finite(r, "max");
      if (o.target && (o.min || o.max)) r.fail("target", "give a target or limits (min, max), not both");
      if (!o.target && !o.min && !o.max) r.fail("", "expected a target or a limit (min, max)");
    }
    switch (o.kind) {
      case K::Seidel:
        allow({"term"});
        o.term = r.get_string("term");
        break;
      case K::SpotRms:
      case K::WavefrontRms:
      case K::RayHeight:
        allow({"fields", "wavelengths_nm"});
        if (r.has("fields")) o.relative_fields = numbers(r, "fields");
        if (r.has("wavelengths_nm")) o.wavelengths_nm = numbers(r, "wavelengths_nm");
        if (o.kind != K::RayHeight) {
          allow({"field_weights", "wavelength_weights"});
          if (r.has("field_weights")) o.field_weights = numbers(r, "field_weights");
          if (r.has("wavelength_weights")) o.wavelength_weights = numbers(r, "wavelength_weights");
        }
        if (o.kind == K::SpotRms) {
          allow({"rings", "reference"});
          if (r.has("rings")) o.rings = whole(r, "rings", 1, kMaxRings);
          if (const auto ref = r.get_optional_string("reference")) {
            if (*ref != "centroid" && *ref != "chief") r.fail("reference", "expected \"centroid\" or \"chief\"");
            o.centroid_reference = *ref == "centroid";
          }
        }
        if (o.kind == K::WavefrontRms) {
          allow({"grid"});
          if (r.has("grid")) o.grid = whole(r, "grid", kMinGrid, kMaxGrid);
        }
        if (o.kind == K::RayHeight) {
          allow({"surface"});
          o.surface = whole(r, "surface", 1, 100000);
        }
        break;
      case K::Distortion:
        allow({"field"});
        o.relative_fields = {r.get_number("field")};
        break;
      case K::CentreThickness:
      case K::EdgeThickness:
        allow({"surface"});
        o.surface = whole(r, "surface", 1, 100000);
        if (o.kind == K::EdgeThickness) {
          allow({"height_mm"});
          o.height_mm = finite(r, "height_mm");
          if (o.height_mm && *o.height_mm <= 0.0) r.fail("height_mm", "expected a height > 0, mm");
        }
        break;
      default: break;
    }
    r.finish(allowed);
    return o;
  }

  const LocatedJson& doc_;
};

}  // namespace

MeritFunction parse_merit_function(std::string_view text, const std::string& file_name) {
  const LocatedJson doc = LocatedJson::parse(text, file_name);
  if (!doc.root().is_object()) throw FileError(doc.where(""), "expected a merit function object {\"variables\": [...], \"operands\": [...]}");
  return MeritReader(doc).read();
}

MeritFunction read_merit_function(const std::string& path) {
  return parse_merit_function(decode_text(read_file_bytes(path), path), path);
}

}  // namespace lensmith

// Reader for the lentil lens database (github.com/zpelgrims/lentil, polynomial-optics/database/
// lenses.json, MIT licence): entries keyed by id, each with patent metadata and its surfaces front
// to rear in "optical-elements-patent". How each key is read, including lentil's aspheric terms
// (z = c r^2 / (1 + sqrt(1 - c^2 r^2)) + a4 r^4 + a6 r^6 + a8 r^8 + a10 r^10, from lentil's
// raytrace.h), is in docs/lens-formats-foreign.md, section "lentil".
#include "lensmith/core/ascii_text.h"
#include "lensmith/prescription/lentil_reader.h"

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "lensmith/core/errors.h"
#include "lensmith/core/located_json.h"

namespace lensmith {
namespace {

using nlohmann::json;

// lentil writes planes as a huge radius (99999, 100000, 999999, 1000000); no camera lens has a
// real radius that long, so it is read as a plane.
constexpr double kFlatRadiusMm = 99999.0;
// A named glass is taken from the catalogue only when its nd agrees with the entry's "ior" this
// well: lentil's names are sometimes of an older melt or a different vendor's glass.
constexpr double kCatalogueNdTolerance = 0.002;
constexpr double kMaxPlausibleIndex = 5.0;
constexpr std::size_t kMaxElements = 10000;
constexpr std::size_t kMaxListedIds = 50;
constexpr std::size_t kAsphericTerms = 4;  // a4, a6, a8, a10

const std::vector<std::string> kElementKeys = {"radius", "thickness",      "material",      "ior",
                                               "abbe",   "housing-radius", "lens-geometry", "aspherical-equation"};

// Glass names compared the way lentil writes them: "SLAH64" for OHARA's S-LAH64.
std::string normalized_glass_name(std::string_view s) {
  std::string out;
  for (char c : s) {
    if (c == '-' || c == ' ' || c == '_') continue;
    out += (c >= 'a' && c <= 'z') ? static_cast<char>(c - 'a' + 'A') : c;
  }
  return out;
}

// JSON pointer of an entry. (Built by append: GCC 12 warns falsely about "/" + std::string.)
std::string entry_pointer(const std::string& id) {
  std::string pointer("/");
  pointer += json_pointer_escape(id);
  return pointer;
}

std::string format_number(double v) {
  char buffer[32];
  const int n = std::snprintf(buffer, sizeof buffer, "%.6g", v);
  return n > 0 ? std::string(buffer, static_cast<std::size_t>(n)) : std::string("?");
}

// A string, or nothing for null or a missing key.
std::optional<std::string> string_or_null(JsonObjectReader& r, const std::string& key) {
  const json* v = r.get(key);
  if (v == nullptr || v->is_null()) return std::nullopt;
  if (!v->is_string()) r.fail(key, "expected a string or null, got " + json_type_phrase(*v));
  return v->get<std::string>();
}

// A finite number, or nothing for null or a missing key.
std::optional<double> number_or_null(JsonObjectReader& r, const std::string& key) {
  const json* v = r.get(key);
  if (v == nullptr || v->is_null()) return std::nullopt;
  if (!v->is_number()) r.fail(key, "expected a number or null, got " + json_type_phrase(*v));
  const double d = v->get<double>();
  if (!std::isfinite(d)) r.fail(key, "number out of range");
  return d;
}

double finite_number(JsonObjectReader& r, const std::string& key) {
  const double d = r.get_number(key);
  if (!std::isfinite(d)) r.fail(key, "number out of range");
  return d;
}

std::string year_text(double year) {
  if (std::abs(year) < 1e9 && year == std::floor(year)) return std::to_string(static_cast<long long>(year));
  return format_number(year);
}

const json& entries_object(const LocatedJson& doc) {
  if (!doc.root().is_object()) {
    throw FileError(doc.where(""),
                        "expected a JSON object of lens entries keyed by id, got " + json_type_phrase(doc.root()));
  }
  return doc.root();
}

// Whether lensmith can read an entry: one iris, no zoom thickness list.
bool entry_supported(const json& entry) {
  if (!entry.is_object()) return false;
  auto elements = entry.find("optical-elements-patent");
  if (elements == entry.end() || !elements->is_array() || elements->empty()) return false;
  int irises = 0;
  for (const json& e : *elements) {
    if (!e.is_object()) return false;
    auto geometry = e.find("lens-geometry");
    if (geometry != e.end() && geometry->is_string()) {
      const std::string g = geometry->get<std::string>();
      if (g != "spherical" && g != "aspherical" && g != "cyl-x" && g != "cyl-y") return false;
    }
    auto thickness = e.find("thickness");
    if (thickness == e.end() || !thickness->is_number()) return false;
    auto material = e.find("material");
    if (material != e.end() && material->is_string() && to_lower_ascii(material->get<std::string>()) == "iris") ++irises;
  }
  return irises == 1;
}

class LentilEntryReader {
 public:
  LentilEntryReader(const LocatedJson& doc, const std::string& id, const GlassCatalog& catalogue)
      : doc_(doc), catalogue_(catalogue), entry_(doc, entry_pointer(id), id) {}

  LensReadResult read() {
    LensReadResult result;
    Prescription& p = result.prescription;
    read_metadata(p);

    const std::string key = "optical-elements-patent";
    const std::size_t count = entry_.get_array_size(key);
    if (count == 0) entry_.fail(key, "no elements");
    if (count > kMaxElements) entry_.fail(key, "more than " + std::to_string(kMaxElements) + " elements");
    element_pointers_.reserve(count);
    for (std::size_t i = 0; i < count; ++i) {
      const std::string pointer = entry_.child_pointer(key) + "/" + std::to_string(i);
      const std::string path = entry_.child_path(key) + "[" + std::to_string(i) + "]";
      element_pointers_.push_back(pointer);
      JsonObjectReader element(doc_, pointer, path);
      p.surfaces.push_back(read_element(element, p));
    }
    if (stop_path_.empty()) entry_.fail(key, "no \"iris\" element: the aperture stop is missing");

    p.object_distance_mm = kInfinity;
    p.image_at_paraxial_focus = false;  // the last thickness is the patent's image distance
    p.aperture = ApertureSpec{ApertureSpec::Kind::FloatByStop, 0.0};

    try {
      p.resolve_materials(catalogue_);
    } catch (const GlassError& e) {
      throw FileError(location_for(e.subject()), e.what());
    }
    try {
      p.validate();
    } catch (const PrescriptionError& e) {
      throw FileError(location_for(e.subject()), e.what());
    }
    result.diagnostics = std::move(diagnostics_);
    return result;
  }

 private:
  void read_metadata(Prescription& p) {
    std::vector<std::string> name_parts;
    if (auto company = string_or_null(entry_, "company")) name_parts.push_back(*company);
    if (auto product = string_or_null(entry_, "product-name")) name_parts.push_back(*product);
    if (auto year = number_or_null(entry_, "year")) name_parts.push_back(year_text(*year));
    for (const std::string& part : name_parts) {
      if (part.empty()) continue;
      if (!p.name.empty()) p.name += ' ';
      p.name += part;
    }
    for (const char* key : {"patent-number", "patent-location"}) {
      if (auto s = string_or_null(entry_, key); s && !s->empty()) {
        if (!p.source.empty()) p.source += ", ";
        p.source += *s;
      }
    }
    if (auto notes = string_or_null(entry_, "notes")) p.notes = *notes;
  }

  Surface read_element(JsonObjectReader& e, const Prescription& p) {
    Surface s;
    const std::string geometry = e.get_string("lens-geometry");
    const bool cylinder = geometry == "cyl-x" || geometry == "cyl-y";
    if (geometry != "spherical" && geometry != "aspherical" && !cylinder) {
      e.fail("lens-geometry", "unknown geometry \"" + geometry + "\"; expected spherical, aspherical, cyl-x or cyl-y");
    }

    const json* thickness = e.get("thickness");
    if (thickness == nullptr) e.fail("thickness", "missing; expected a number");
    if (thickness->is_array()) {
      e.fail("thickness", "a zoom lens (thickness list [short, mid, long]) is not supported");
    }
    if (!thickness->is_number()) e.fail("thickness", "expected a number, got " + json_type_phrase(*thickness));
    s.thickness_mm = thickness->get<double>();
    if (!std::isfinite(s.thickness_mm) || s.thickness_mm < 0.0) {
      e.fail("thickness", "thickness = " + format_number(s.thickness_mm) + ": must be finite and >= 0");
    }

    const double radius = finite_number(e, "radius");
    if (radius == 0.0) e.fail("radius", "radius 0: lentil writes planes as 99999 or larger");
    const std::string material = e.get_string("material");
    const std::string kind = to_lower_ascii(material);
    const bool iris = kind == "iris";
    // An iris is a plane whatever radius lentil gives it (entry 0015 writes 9999).
    s.curvature_per_mm = iris || std::abs(radius) >= kFlatRadiusMm ? 0.0 : 1.0 / radius;
    if (cylinder && s.curvature_per_mm != 0.0) {
      // lentil's cylinders (Hanika's polynomial-optics tracer): "cyl-y" has its axis along y and is curved in x
      // (the horizontal power of a cinema anamorphic), "cyl-x" its axis along x, curved in y. A biconic with one
      // flat section.
      s.kind = SurfaceKind::Biconic;
      if (geometry == "cyl-y") {
        s.curvature_x_per_mm = s.curvature_per_mm;
        s.curvature_per_mm = 0.0;
      }
    }

    const double housing = finite_number(e, "housing-radius");
    if (!(housing > 0.0)) e.fail("housing-radius", "housing-radius = " + format_number(housing) + ": must be > 0");
    s.semi_diameter_mm = housing;
    // Some entries give a housing wider than the sphere itself (0015: radius 0.8146, housing 0.82).
    // No ray can pass beyond |R|, so lentil's own tracer loses nothing when the aperture stops there.
    const double curved = std::max(std::abs(s.curvature_per_mm), std::abs(s.curvature_x_per_mm));
    if (curved != 0.0 && housing > 1.0 / curved) {
      const double limit = 1.0 / curved;
      warn(e, "housing-radius",
           "housing-radius " + format_number(housing) + " exceeds |radius| " + format_number(limit) +
               "; the clear semi-diameter is limited to |radius|");
      s.semi_diameter_mm = limit;
    }

    const std::optional<double> ior = number_or_null(e, "ior");
    const std::optional<double> abbe = number_or_null(e, "abbe");
    if (iris) {
      if (!stop_path_.empty()) e.fail("material", "a second iris (aperture stop); the first is " + stop_path_);
      stop_path_ = e.path();
      s.is_stop = true;
      // lentil gives the iris the medium before it (air in every published entry).
      s.material = p.surfaces.empty() ? p.object_material : p.surfaces.back().material;
    } else if (kind == "air") {
      if (ior && *ior != 1.0) {
        warn(e, "ior", "air with ior = " + format_number(*ior) + " is read as n = 1");
      }
      s.material = MaterialSpec::air();
    } else {
      s.material = glass_material(e, material, kind, ior, abbe);
    }

    read_asphere(e, geometry, s);
    e.finish(kElementKeys);
    return s;
  }

  MaterialSpec glass_material(JsonObjectReader& e, const std::string& material, const std::string& kind,
                              std::optional<double> ior, std::optional<double> abbe) {
    if (ior && (*ior < 1.0 || *ior > kMaxPlausibleIndex)) {
      e.fail("ior", "ior = " + format_number(*ior) + ": must be in [1, 5]");
    }
    if (abbe && *abbe < 0.0) e.fail("abbe", "abbe = " + format_number(*abbe) + ": must be >= 0");
    // lentil writes abbe 0 or null for "no dispersion data".
    const std::optional<double> vd = abbe && *abbe > 0.0 ? abbe : std::nullopt;
    if (kind == "abbe") {
      if (!ior) e.fail("ior", "material \"abbe\" needs an ior (nd)");
      return MaterialSpec::model(*ior, vd);
    }
    bool by_normalized_name = false;
    const Glass* glass = catalogue_.find(material);
    if (glass == nullptr) {
      glass = find_normalized(material);
      by_normalized_name = glass != nullptr;
    }
    if (glass != nullptr) {
      const double catalogue_nd =
          std::isfinite(glass->catalog_nd()) && glass->catalog_nd() > 0.0 ? glass->catalog_nd() : glass->nd();
      if (!ior || std::abs(catalogue_nd - *ior) <= kCatalogueNdTolerance) {
        if (by_normalized_name) {
          note(e, "material", "glass \"" + material + "\" read as " + glass->vendor() + " " + glass->name());
        }
        return MaterialSpec::catalog(glass->name(), glass->vendor());
      }
      note(e, "material",
           "catalogue glass " + glass->vendor() + " " + glass->name() + " has nd " + format_number(catalogue_nd) +
               ", the entry's ior is " + format_number(*ior) + "; using a model glass from ior and abbe");
      return MaterialSpec::model(*ior, vd);
    }
    if (ior) {
      note(e, "material", "glass \"" + material + "\" is in no catalogue; using a model glass from ior and abbe");
      return MaterialSpec::model(*ior, vd);
    }
    std::string names;
    for (const std::string& n : catalogue_.closest_names(material)) names += (names.empty() ? "" : ", ") + n;
    e.fail("material", "unknown glass \"" + material + "\" and no ior to fall back on; closest catalogue names: " +
                           (names.empty() ? "(none)" : names));
  }

  // The catalogue glass whose name matches once dashes, blanks and case are ignored, first in the
  // catalogue's vendor order. The index is built once per entry, so the cost stays linear in the
  // number of elements.
  const Glass* find_normalized(const std::string& name) {
    if (!normalized_index_built_) {
      for (const std::string& vendor : catalogue_.vendors()) {
        for (const Glass& g : catalogue_.glasses()) {
          if (normalized_glass_name(g.vendor()) == normalized_glass_name(vendor)) {
            normalized_index_.emplace(normalized_glass_name(g.name()), &g);  // keeps the first vendor's glass
          }
        }
      }
      normalized_index_built_ = true;
    }
    auto it = normalized_index_.find(normalized_glass_name(name));
    return it == normalized_index_.end() ? nullptr : it->second;
  }

  void read_asphere(JsonObjectReader& e, const std::string& geometry, Surface& s) {
    const std::string key = "aspherical-equation";
    const json* terms = e.get(key);
    const bool has_terms = terms != nullptr && !terms->is_null();
    if (geometry != "aspherical") {
      if (has_terms) e.fail(key, "aspheric terms on a \"" + geometry + "\" element");
      return;
    }
    if (!has_terms) e.fail(key, "an aspherical element needs its four terms [a4, a6, a8, a10]");
    if (!terms->is_array() || terms->size() != kAsphericTerms) {
      e.fail(key, "expected an array of four numbers [a4, a6, a8, a10], got " + json_type_phrase(*terms));
    }
    for (std::size_t j = 0; j < kAsphericTerms; ++j) {
      const json& t = (*terms)[j];
      if (!t.is_number() || !std::isfinite(t.get<double>())) {
        e.fail(key, "term " + std::to_string(j) + ": expected a finite number, got " + json_type_phrase(t));
      }
      // lentil's terms are the r^4 .. r^10 coefficients; even_asphere[j] holds r^(2j+2).
      s.even_asphere[j + 1] = t.get<double>();
    }
  }

  void note(const JsonObjectReader& e, const std::string& key, const std::string& message) {
    diagnostics_.push_back(Diagnostic{Diagnostic::Severity::Note, e.where(key), e.path() + ": " + message});
  }
  void warn(const JsonObjectReader& e, const std::string& key, const std::string& message) {
    diagnostics_.push_back(Diagnostic{Diagnostic::Severity::Warning, e.where(key), e.path() + ": " + message});
  }

  // Where a PrescriptionError "surface N: ..." points: element N - 1.
  // Where a GlassError or PrescriptionError is about: its subject's element, else the entry.
  SourceLocation location_for(const ErrorSubject& subject) const {
    const int n = subject.surface;
    if (n >= 1 && n <= static_cast<int>(element_pointers_.size())) return doc_.where(element_pointers_[static_cast<std::size_t>(n - 1)]);
    return doc_.where(entry_.pointer());
  }

  const LocatedJson& doc_;
  const GlassCatalog& catalogue_;
  JsonObjectReader entry_;
  std::vector<std::string> element_pointers_;
  std::string stop_path_;
  Diagnostics diagnostics_;
  std::unordered_map<std::string, const Glass*> normalized_index_;
  bool normalized_index_built_ = false;
};

}  // namespace

std::vector<LentilEntrySummary> list_lentil_entries(std::string_view text, const std::string& file_name) {
  const LocatedJson doc = LocatedJson::parse(text, file_name);
  const json& root = entries_object(doc);
  std::vector<LentilEntrySummary> out;
  out.reserve(root.size());
  for (auto it = root.begin(); it != root.end(); ++it) {
    LentilEntrySummary s;
    s.id = it.key();
    JsonObjectReader entry(doc, entry_pointer(it.key()), it.key());
    s.company = string_or_null(entry, "company").value_or("");
    s.product_name = string_or_null(entry, "product-name").value_or("");
    if (auto year = number_or_null(entry, "year")) {
      if (std::abs(*year) < 1e9) s.year = static_cast<int>(*year);
    }
    s.patent_focal_length_mm = number_or_null(entry, "focal-length-mm-patent").value_or(0.0);
    s.production_ready = entry.get_optional_bool("production-ready").value_or(false);
    s.supported = entry_supported(it.value());
    out.push_back(std::move(s));
  }
  return out;
}

LensReadResult read_lentil(std::string_view text, const std::string& file_name, const std::string& id,
                           const GlassCatalog& catalogue) {
  const LocatedJson doc = LocatedJson::parse(text, file_name);
  const json& root = entries_object(doc);
  if (root.find(id) == root.end()) {
    std::string ids;
    std::size_t listed = 0;
    for (auto it = root.begin(); it != root.end() && listed < kMaxListedIds; ++it, ++listed) {
      ids += (ids.empty() ? "" : ", ") + it.key();
    }
    if (root.size() > kMaxListedIds) ids += ", ... (" + std::to_string(root.size()) + " in all)";
    throw FileError(doc.where(""),
                        "no lentil entry \"" + id + "\"; available ids: " + (ids.empty() ? "(none)" : ids));
  }
  LentilEntryReader reader(doc, id, catalogue);
  return reader.read();
}

}  // namespace lensmith

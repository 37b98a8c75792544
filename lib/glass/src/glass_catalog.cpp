// Glass catalogues: reading lensmith's compact JSON (docs/glass.md, written by
// tools/convert_glass_catalogs.py from the refractiveindex.info database) and looking glasses up
// by name. A name that is not found is an error listing the closest names; nothing is guessed.
#include "lensmith/core/ascii_text.h"
#include "lensmith/glass/glass_catalog.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <tuple>

#include "lensmith/core/embedded_file.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/located_json.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/text_file.h"
#include "lensmith/core/units.h"

namespace lensmith {

// Generated from lenses/glass/*.json by cmake/EmbedFiles.cmake (lib/glass/CMakeLists.txt).
std::span<const EmbeddedFile> embedded_glass_catalogues();

namespace {

constexpr std::string_view kFormatName = "lensmith-glass-catalog";
constexpr int kFormatVersion = 1;
// Search order when no vendor is named (docs/glass.md). SCHOTT comes first because bare names in
// patents and lens databases (SF5, F2, LAK9) usually mean Schott's glass; OHARA, HOYA, CDGM, HIKARI
// and SUMITA follow, so a SCHOTT name never resolves to another maker's namesake by accident.
constexpr std::string_view kDefaultVendorOrder[] = {"SCHOTT", "OHARA", "HOYA", "CDGM", "HIKARI", "SUMITA"};
constexpr std::size_t kDefaultSuggestions = 5;

// The form in which names are compared for suggestions: "n-bk7", "N BK7" and "NBK7" all become
// "NBK7", because lens files and patents write separators inconsistently.
std::string normalise(std::string_view name) {
  std::string out;
  out.reserve(name.size());
  for (char c : to_upper_ascii(name)) {
    if (c != '-' && c != ' ' && c != '_') out += c;
  }
  return out;
}

// Edit distance (insertions, deletions, substitutions each cost 1), two-row dynamic programme.
std::size_t levenshtein(std::string_view a, std::string_view b) {
  std::vector<std::size_t> previous(b.size() + 1);
  std::vector<std::size_t> current(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) previous[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    current[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t substitution = previous[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      current[j] = std::min({previous[j] + 1, current[j - 1] + 1, substitution});
    }
    std::swap(previous, current);
  }
  return previous[b.size()];
}

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& item : items) out += (out.empty() ? "" : ", ") + item;
  return out;
}

// A number for messages, as short as it can be written: "2", "2.5", "1e-07".
std::string number_text(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

// Catalogue wavelengths are printed in micrometres with at most 6 decimals. Rounding the converted
// value to 1e-6 nm removes the binary conversion error, so 0.32611 um becomes the double nearest
// 326.11 nm and a user who asks for exactly 326.11 nm is inside the range.
double nm_from_catalogue_um(double micrometres) {
  constexpr double kStepsPerNm = 1.0e6;
  return std::round(nm_from_um(micrometres) * kStepsPerNm) / kStepsPerNm;
}

// An array of numbers at `key`, with errors at the offending element.
std::vector<double> read_numbers(JsonObjectReader& reader, const std::string& key) {
  const std::size_t size = reader.get_array_size(key);
  const nlohmann::json& array = reader.value().at(key);
  std::vector<double> values;
  values.reserve(size);
  for (std::size_t i = 0; i < size; ++i) {
    const nlohmann::json& item = array[i];
    if (!item.is_number()) {
      throw FileError(reader.document().where(reader.child_pointer(key) + "/" + std::to_string(i)),
                          reader.child_path(key) + "[" + std::to_string(i) + "]: expected a number, got " +
                              json_type_phrase(item));
    }
    values.push_back(item.get<double>());
  }
  return values;
}

Glass::Status read_status(JsonObjectReader& reader) {
  const auto text = reader.get_optional_string("status");
  if (!text) return Glass::Status::Unspecified;
  for (auto status : {Glass::Status::Unspecified, Glass::Status::Standard, Glass::Status::Preferred,
                      Glass::Status::Obsolete, Glass::Status::Special}) {
    if (*text == Glass::status_name(status)) return status;
  }
  reader.fail("status", "\"" + *text + "\" is not one of standard, preferred, obsolete, special, unspecified");
}

Glass read_glass(const LocatedJson& doc, std::size_t index, const std::string& vendor) {
  JsonObjectReader reader(doc, "/glasses/" + std::to_string(index), "glasses[" + std::to_string(index) + "]");
  const std::string name = reader.get_string("name");
  if (name.empty()) reader.fail("name", "must not be empty");

  const double formula_number = reader.get_number("formula");
  if (formula_number != 1 && formula_number != 2 && formula_number != 3) {
    reader.fail("formula", "must be 1, 2 or 3 (refractiveindex.info formula numbers), got " + number_text(formula_number));
  }
  const auto formula = static_cast<Glass::Formula>(static_cast<int>(formula_number));

  const std::vector<double> coefficients = read_numbers(reader, "coefficients");
  if (coefficients.size() % 2 != 1) {
    reader.fail("coefficients", "has " + std::to_string(coefficients.size()) +
                                    " numbers; the formula needs C1 followed by pairs (an odd count)");
  }
  const std::vector<double> range_um = read_numbers(reader, "range_um");
  if (range_um.size() != 2 || !(range_um[0] > 0.0) || !(range_um[1] > range_um[0])) {
    reader.fail("range_um", "must be [min, max] in micrometres with 0 < min < max");
  }

  const auto nd = reader.get_optional_number("nd");
  const auto vd = reader.get_optional_number("vd");
  if (nd.has_value() != vd.has_value()) reader.fail(nd ? "nd" : "vd", "give both nd and vd, or neither");
  const Glass::Status status = read_status(reader);
  std::string replaced_by = reader.get_optional_string("replaced_by").value_or("");
  reader.finish({"name", "formula", "coefficients", "range_um", "nd", "vd", "status", "replaced_by"});

  constexpr double kNotGiven = std::numeric_limits<double>::quiet_NaN();
  Glass glass;
  try {
    glass = Glass::from_formula(name, vendor, formula, coefficients,
                                WavelengthRange{nm_from_catalogue_um(range_um[0]), nm_from_catalogue_um(range_um[1])},
                                nd.value_or(kNotGiven), vd.value_or(kNotGiven));
  } catch (const GlassError& e) {
    reader.fail("", e.what());
  }
  glass.set_catalog_status(status, std::move(replaced_by));
  return glass;
}

}  // namespace

namespace {

// The AGF formula number's glass: refractiveindex.info's formula 2 (Sellmeier) or 3 (polynomial)
// where one matches, else the AGF formula itself (Zemax OpticStudio manual, "Glass Catalogs").
std::pair<Glass::Formula, std::vector<double>> agf_formula(int number, const std::array<double, 10>& c) {
  using F = Glass::Formula;
  const auto polynomial = [&](std::initializer_list<double> exponents) {
    std::vector<double> out{c[0]};
    std::size_t i = 1;
    for (const double e : exponents) out.insert(out.end(), {c[i++], e});
    return out;
  };
  const auto sellmeier = [&](std::size_t terms) {
    std::vector<double> out{0.0};
    for (std::size_t i = 0; i < terms; ++i) out.insert(out.end(), {c[2 * i], c[2 * i + 1]});
    return out;
  };
  switch (number) {
    case 1: return {F::Polynomial, polynomial({2, -2, -4, -6, -8})};                     // Schott
    case 2: return {F::Sellmeier2, sellmeier(3)};                                         // Sellmeier 1
    case 3: return {F::Herzberger, {c[0], c[1], c[2], c[3], c[4], c[5]}};                // Herzberger
    case 4: return {F::AgfSellmeier2, {c[0], c[1], c[2], c[3], c[4]}};                   // Sellmeier 2
    case 5: return {F::Conrady, {c[0], c[1], c[2]}};                                      // Conrady
    case 6: return {F::Sellmeier2, sellmeier(4)};                                         // Sellmeier 3
    case 7: return {F::Handbook1, {c[0], c[1], c[2], c[3]}};                              // Handbook of Optics 1
    case 8: return {F::Handbook2, {c[0], c[1], c[2], c[3]}};                              // Handbook of Optics 2
    case 9: return {F::Sellmeier2, {c[0] - 1.0, c[1], c[2], c[3], c[4]}};                 // Sellmeier 4: n^2 = A + ...
    case 10: return {F::Polynomial, polynomial({2, -2, -4, -6, -8, -10, -12})};          // Extended
    case 11: return {F::Sellmeier2, sellmeier(5)};                                        // Sellmeier 5
    case 12: return {F::Polynomial, polynomial({2, -2, -4, -6, -8, 4, 6})};              // Extended 2
    case 13: return {F::Polynomial, polynomial({2, 4, -2, -4, -6, -8, -10, -12})};       // Extended 3
    default: return {F::Constant, {}};
  }
}

}  // namespace

GlassCatalog GlassCatalog::from_agf(std::string_view text, const std::string& file_name, const std::string& vendor) {
  struct Pending {
    std::string name;
    int formula = 0;
    double nd = 0.0, vd = 0.0;
    Glass::Status status = Glass::Status::Unspecified;
    std::array<double, 10> coefficients{};
    bool has_coefficients = false;
    std::optional<std::pair<double, double>> range_um;
    int line = 0;
  };
  GlassCatalog catalog;
  std::optional<Pending> pending;
  const auto finish = [&]() {
    if (!pending) return;
    const Pending& g = *pending;
    const SourceLocation at{file_name, g.line, 1};
    if (!g.has_coefficients) throw FileError(at, "glass " + g.name + " has no CD line (its dispersion coefficients)");
    if (!g.range_um) throw FileError(at, "glass " + g.name + " has no LD line (the wavelength range of its formula, micrometres)");
    const auto [formula, coefficients] = agf_formula(g.formula, g.coefficients);
    try {
      Glass glass = Glass::from_formula(g.name, vendor, formula, coefficients,
                                        WavelengthRange{nm_from_catalogue_um(g.range_um->first), nm_from_catalogue_um(g.range_um->second)},
                                        g.nd, g.vd);
      glass.set_catalog_status(g.status);
      catalog.add(std::move(glass));
    } catch (const GlassError& e) {
      throw FileError(at, e.what());
    }
    pending.reset();
  };
  int line_number = 0;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    std::string_view line = text.substr(start, end - start);
    start = end + 1;
    ++line_number;
    std::vector<std::string_view> words;
    for (std::size_t i = 0; i < line.size();) {
      while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      const std::size_t b = i;
      while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      if (i > b) words.push_back(line.substr(b, i - b));
    }
    if (words.empty()) continue;
    const SourceLocation at{file_name, line_number, 1};
    const auto number = [&](std::size_t i, const char* what) {
      const std::optional<double> v = i < words.size() ? parse_finite_number(words[i]) : std::nullopt;
      if (!v) throw FileError(at, std::string(words[0]) + ": expected " + what + " as field " + std::to_string(i) + ", got " +
                                          (i < words.size() ? "\"" + std::string(words[i]) + "\"" : std::string("nothing")));
      return *v;
    };
    const std::string_view key = words[0];
    if (key == "NM") {
      finish();
      Pending g;
      g.line = line_number;
      if (words.size() < 2) throw FileError(at, "NM: expected the glass name");
      g.name = std::string(words[1]);
      const double formula = number(2, "the dispersion formula number (1-13)");
      if (formula != std::floor(formula) || formula < 1 || formula > 13) {
        throw FileError(at, "NM " + g.name + ": dispersion formula " + format_number(formula) + " is not one of AGF's 1-13");
      }
      g.formula = static_cast<int>(formula);
      g.nd = words.size() > 4 ? number(4, "nd") : std::numeric_limits<double>::quiet_NaN();
      g.vd = words.size() > 5 ? number(5, "Vd") : std::numeric_limits<double>::quiet_NaN();
      if (words.size() > 7) {
        const double status = number(7, "the status (0 standard, 1 preferred, 2 obsolete, 3 special, 4 melt)");
        g.status = status == 0 ? Glass::Status::Standard : status == 1 ? Glass::Status::Preferred
                 : status == 2 ? Glass::Status::Obsolete : Glass::Status::Special;
      }
      pending = std::move(g);
    } else if (key == "CD") {
      if (!pending) throw FileError(at, "CD before any NM line (coefficients of no glass)");
      if (words.size() > 11) throw FileError(at, "CD: at most 10 coefficients, got " + std::to_string(words.size() - 1));
      for (std::size_t i = 1; i < words.size(); ++i) pending->coefficients[i - 1] = number(i, "a coefficient");
      pending->has_coefficients = true;
    } else if (key == "LD") {
      if (!pending) throw FileError(at, "LD before any NM line");
      const double lo = number(1, "the shortest wavelength (um)"), hi = number(2, "the longest wavelength (um)");
      if (!(lo > 0.0) || !(hi > lo)) throw FileError(at, "LD " + format_number(lo) + " " + format_number(hi) + ": expected 0 < min < max micrometres");
      pending->range_um = std::make_pair(lo, hi);
    } else if (key == "CC" || key == "GC" || key == "ED" || key == "TD" || key == "OD" || key == "IT" || key == "BD") {
      // Comments, thermal, other and transmission data: not used by lensmith.
    } else {
      throw FileError(at, "unknown AGF record \"" + std::string(key.substr(0, 16)) +
                                  "\" (expected NM, CD, LD, or CC, GC, ED, TD, OD, IT, BD)");
    }
  }
  finish();
  if (catalog.size() == 0) throw FileError({file_name, 0, 0}, "no glass (NM line) in this AGF catalogue");
  return catalog;
}

GlassCatalog GlassCatalog::read_file(const std::string& path) {
  const std::filesystem::path p(path);
  const std::string extension = to_lower_ascii(p.extension().string());
  const std::string text = decode_text(read_file_bytes(path), path);
  if (extension == ".agf") return from_agf(text, path, to_upper_ascii(p.stem().string()));
  if (extension == ".json") return from_json(text, path);
  throw GlassError(path + ": a glass catalogue is a Zemax .agf or a lensmith .json file");
}

namespace {

// Appends the catalogue files (or the .agf files of folders) of `paths` to `all`, refusing a vendor
// already present. `origin` prefixes errors ("LENSMITH_GLASS_CATALOGS: ").
void append_catalog_files(GlassCatalog& all, const std::vector<std::string>& paths, const std::string& origin) {
  for (const std::string& path : paths) {
    std::vector<std::string> files;
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) {
      for (const auto& entry : std::filesystem::directory_iterator(path, ec)) {
        if (to_lower_ascii(entry.path().extension().string()) == ".agf") files.push_back(entry.path().string());
      }
      std::sort(files.begin(), files.end());
      if (files.empty()) throw GlassError(origin + path + ": a folder without .agf glass catalogues");
    } else {
      files.push_back(path);
    }
    for (const std::string& file : files) {
      const GlassCatalog user = GlassCatalog::read_file(file);
      for (const std::string& vendor : user.vendors()) {
        if (std::find(all.vendors().begin(), all.vendors().end(), vendor) != all.vendors().end()) {
          throw GlassError(origin + file + ": catalogue vendor " + vendor + " is already present (built in, or given twice); name the " +
                           "file differently (e.g. " + vendor + "_2024.agf) and list that name on the lens file's GCAT line");
        }
      }
      all.merge(user);
    }
  }
}

GlassCatalog& mutable_builtin() {
  // A function-local static is initialised once, and thread-safely (C++11 [stmt.dcl]/4).
  static GlassCatalog catalog = [] {
    std::vector<GlassCatalog> parts;
    for (const EmbeddedFile& file : embedded_glass_catalogues()) {
      parts.push_back(GlassCatalog::from_json(file.text, "lenses/glass/" + std::string(file.path)));
    }
    // Default vendors in their fixed order; any other shipped catalogue after them, by vendor name.
    auto rank = [](const GlassCatalog& part) {
      const std::string& vendor = part.vendors().front();
      const auto* it = std::find(std::begin(kDefaultVendorOrder), std::end(kDefaultVendorOrder), vendor);
      return std::make_tuple(static_cast<std::size_t>(it - std::begin(kDefaultVendorOrder)), vendor);
    };
    std::sort(parts.begin(), parts.end(), [&](const auto& a, const auto& b) { return rank(a) < rank(b); });
    GlassCatalog all;
    for (const auto& part : parts) all.merge(part);
    // LENSMITH_GLASS_CATALOGS: the user's catalogue files or folders of .agf, separated by ':'.
    if (const char* env = std::getenv("LENSMITH_GLASS_CATALOGS"); env != nullptr && *env != '\0') {
      std::vector<std::string> paths;
      std::string_view list(env);
      while (!list.empty()) {
        const std::size_t colon = std::min(list.find(':'), list.size());
        if (colon > 0) paths.emplace_back(list.substr(0, colon));
        list.remove_prefix(std::min(colon + 1, list.size()));
      }
      append_catalog_files(all, paths, "LENSMITH_GLASS_CATALOGS: ");
    }
    return all;
  }();
  return catalog;
}

}  // namespace

void GlassCatalog::add_user_catalogs(const std::vector<std::string>& paths) { append_catalog_files(mutable_builtin(), paths, ""); }

const GlassCatalog& GlassCatalog::builtin() { return mutable_builtin(); }

GlassCatalog GlassCatalog::from_json(std::string_view json_text, const std::string& source_name) {
  const LocatedJson doc = LocatedJson::parse(json_text, source_name);
  JsonObjectReader root(doc, "", "");
  const std::string format = root.get_string("format");
  if (format != kFormatName) {
    root.fail("format", "expected \"" + std::string(kFormatName) + "\", got \"" + format + "\"");
  }
  const double version = root.get_number("version");
  if (version != kFormatVersion) {
    root.fail("version", "version " + number_text(version) + " is not supported; this lensmith reads version " +
                             std::to_string(kFormatVersion));
  }
  const std::string vendor = to_upper_ascii(root.get_string("vendor"));
  if (vendor.empty()) root.fail("vendor", "must not be empty");
  // Provenance, for people reading the file; lensmith does not interpret it.
  root.get_optional_string("source");
  root.get_optional_string("licence");
  const std::size_t count = root.get_array_size("glasses");
  root.finish({"format", "version", "vendor", "source", "licence", "glasses"});

  GlassCatalog catalog;
  catalog.vendors_.push_back(vendor);
  catalog.glasses_.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    Glass glass = read_glass(doc, i, vendor);
    if (catalog.find(glass.name(), vendor) != nullptr) {
      JsonObjectReader reader(doc, "/glasses/" + std::to_string(i), "glasses[" + std::to_string(i) + "]");
      reader.fail("name", "glass \"" + glass.name() + "\" appears twice in the " + vendor +
                              " catalogue (names are compared ignoring case)");
    }
    catalog.add(std::move(glass));
  }
  return catalog;
}

void GlassCatalog::merge(const GlassCatalog& other) {
  // Check first, so that a failed merge leaves this catalogue unchanged.
  for (const Glass& glass : other.glasses_) {
    if (find(glass.name(), glass.vendor()) != nullptr) {
      throw GlassError("cannot merge glass catalogues: " + glass.vendor() + " " + glass.name() +
                       " is in both (names are compared ignoring case)");
    }
  }
  for (const std::string& vendor : other.vendors_) {
    if (vendor_rank(vendor) == vendors_.size()) vendors_.push_back(vendor);
  }
  glasses_.reserve(glasses_.size() + other.glasses_.size());
  for (const Glass& glass : other.glasses_) add(glass);
}

void GlassCatalog::add(Glass glass) {
  if (vendor_rank(glass.vendor()) == vendors_.size()) vendors_.push_back(glass.vendor());
  by_name_[to_upper_ascii(glass.name())].push_back(glasses_.size());
  normalised_names_.push_back(normalise(glass.name()));
  glasses_.push_back(std::move(glass));
}

std::size_t GlassCatalog::vendor_rank(std::string_view vendor_upper) const {
  return static_cast<std::size_t>(std::find(vendors_.begin(), vendors_.end(), vendor_upper) - vendors_.begin());
}

const Glass* GlassCatalog::find(std::string_view name, std::string_view vendor,
                                std::span<const std::string> vendor_order) const {
  const auto it = by_name_.find(to_upper_ascii(name));
  if (it == by_name_.end()) return nullptr;
  const std::vector<std::size_t>& candidates = it->second;
  auto at_vendor = [&](std::string_view vendor_upper) -> const Glass* {
    for (std::size_t index : candidates) {
      if (glasses_[index].vendor() == vendor_upper) return &glasses_[index];
    }
    return nullptr;
  };
  if (!vendor.empty()) return at_vendor(to_upper_ascii(vendor));
  for (const std::string& preferred : vendor_order) {
    if (const Glass* glass = at_vendor(to_upper_ascii(preferred))) return glass;
  }
  // Default order: the candidate whose vendor comes first in vendors_.
  const auto best = std::min_element(candidates.begin(), candidates.end(), [&](std::size_t a, std::size_t b) {
    return vendor_rank(glasses_[a].vendor()) < vendor_rank(glasses_[b].vendor());
  });
  return &glasses_[*best];
}

const Glass& GlassCatalog::get(std::string_view name, std::string_view vendor,
                               std::span<const std::string> vendor_order) const {
  if (const Glass* glass = find(name, vendor, vendor_order)) return *glass;
  const std::string quoted = "\"" + std::string(name) + "\"";
  if (vendor.empty()) {
    const auto closest = closest_names(name, kDefaultSuggestions);
    throw GlassError("unknown glass " + quoted +
                     (closest.empty() ? "; the glass catalogue is empty" : "; closest catalogue names: " + join(closest)));
  }
  const std::string vendor_upper = to_upper_ascii(vendor);
  // The name may exist at another vendor (SF5 is SCHOTT and HIKARI, not HOYA): say where.
  std::vector<std::string> elsewhere;
  if (const auto it = by_name_.find(to_upper_ascii(name)); it != by_name_.end()) {
    for (std::size_t index : it->second) elsewhere.push_back(glasses_[index].name() + " (" + glasses_[index].vendor() + ")");
  }
  const std::string where_else = elsewhere.empty() ? "" : "; the name exists only as " + join(elsewhere);
  if (vendor_rank(vendor_upper) == vendors_.size()) {
    throw GlassError("unknown glass vendor \"" + std::string(vendor) + "\" for glass " + quoted +
                     "; catalogue vendors: " + join(vendors_) + where_else);
  }
  const auto closest = closest_names_at(name, vendor_upper, kDefaultSuggestions);
  throw GlassError("unknown glass " + quoted + " in the " + vendor_upper + " catalogue" + where_else +
                   (closest.empty() ? "" : "; closest " + vendor_upper + " names: " + join(closest)));
}

const Glass* GlassCatalog::successor(std::string_view obsolete_name) const {
  if (obsolete_name.empty() || find(obsolete_name) != nullptr) return nullptr;
  const std::string base = "N-" + to_upper_ascii(obsolete_name);
  for (const std::string& candidate : {base, base + "A"}) {
    if (const Glass* glass = find(candidate, "SCHOTT")) return glass;
  }
  return nullptr;
}

std::vector<std::string> GlassCatalog::closest_names(std::string_view name, std::size_t count) const {
  std::vector<std::string> names = closest_names_at(name, {}, count);
  if (const Glass* next = successor(name); next != nullptr && count > 0) {
    const std::string entry = next->name() + " (" + next->vendor() + ")";
    names.erase(std::remove(names.begin(), names.end(), entry), names.end());
    names.insert(names.begin(), entry);
    if (names.size() > count) names.resize(count);
  }
  return names;
}

std::vector<std::string> GlassCatalog::closest_names_at(std::string_view name, std::string_view vendor_upper,
                                                        std::size_t count) const {
  const std::string query = normalise(name);
  struct Candidate {
    std::size_t distance;
    std::string name_upper;
    std::size_t vendor_rank;
    std::size_t index;
  };
  std::vector<Candidate> candidates;
  candidates.reserve(glasses_.size());
  for (std::size_t i = 0; i < glasses_.size(); ++i) {
    if (!vendor_upper.empty() && glasses_[i].vendor() != vendor_upper) continue;
    // An exact match after normalising has distance 0 and so ranks first.
    candidates.push_back({levenshtein(query, normalised_names_[i]), to_upper_ascii(glasses_[i].name()),
                          vendor_rank(glasses_[i].vendor()), i});
  }
  const std::size_t kept = std::min(count, candidates.size());
  std::partial_sort(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(kept), candidates.end(),
                    [](const Candidate& a, const Candidate& b) {
                      return std::tie(a.distance, a.name_upper, a.vendor_rank, a.index) <
                             std::tie(b.distance, b.name_upper, b.vendor_rank, b.index);
                    });
  std::vector<std::string> out;
  out.reserve(kept);
  for (std::size_t i = 0; i < kept; ++i) {
    const Glass& glass = glasses_[candidates[i].index];
    out.push_back(glass.name() + " (" + glass.vendor() + ")");
  }
  return out;
}

}  // namespace lensmith

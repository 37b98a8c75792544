#include "lensmith/core/ascii_text.h"
#include "lensmith/prescription/lens_file.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "lensmith/core/text_file.h"
#include "lensmith/prescription/codev_reader.h"
#include "lensmith/prescription/lens_json.h"
#include "lensmith/prescription/lentil_reader.h"
#include "lensmith/prescription/pbrt_reader.h"
#include "lensmith/prescription/zemax_reader.h"

namespace lensmith {

namespace {

std::string lower_extension(const std::string& path) {
  const auto slash = path.find_last_of("/\\");
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return {};
  return to_lower_ascii(path.substr(dot));
}

// A lentil database is a JSON object of entries, each holding "optical-elements-patent"; a native
// lens file has "format": "lensmith-lens". Look at the text rather than parse it twice.
bool looks_like_lentil(std::string_view text) {
  return text.find("\"optical-elements-patent\"") != std::string_view::npos &&
         text.find("\"lensmith-lens\"") == std::string_view::npos;
}

}  // namespace

void resolve_and_validate(Prescription& lens, const GlassCatalog& catalogue, const std::string& file,
                          const std::function<int(const ErrorSubject& subject)>& line_of) {
  try {
    lens.resolve_materials(catalogue);
    lens.validate();
  } catch (const SubjectError& e) {  // GlassError, PrescriptionError
    throw FileError(SourceLocation{file, line_of(e.subject()), 0}, e.what());
  }
}

std::string lens_name_from_path(const std::string& path) {
  const std::size_t slash = path.find_last_of("/\\");
  std::string stem = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::size_t dot = stem.find_last_of('.');
  if (dot != std::string::npos && dot > 0) stem.resize(dot);
  return stem;
}

double radial_field_value(FieldSpec::Kind kind, double x, double y) {
  if (x == 0.0) return y;
  if (kind != FieldSpec::Kind::AngleDeg) return std::hypot(x, y);
  return deg_from_rad(std::atan(std::hypot(std::tan(rad_from_deg(x)), std::tan(rad_from_deg(y)))));
}

void UnknownKeywords::record(std::string_view keyword, int line) {
  const std::string key = shown_text(keyword);
  auto it = seen_.find(key);
  if (it != seen_.end()) {
    ++it->second.count;
  } else if (seen_.size() >= kMaxListed) {
    ++overflow_;
  } else {
    seen_.emplace(key, Seen{line, 1});
  }
}

void UnknownKeywords::report(Diagnostics& diagnostics, const std::string& file, const std::string& noun) const {
  for (const auto& [keyword, seen] : seen_) {
    diagnostics.push_back(Diagnostic{Diagnostic::Severity::Warning, SourceLocation{file, seen.first_line, 0},
                                     "unknown keyword " + keyword + " ignored" +
                                         (seen.count > 1 ? " (" + std::to_string(seen.count) + " " + noun + ")" : std::string())});
  }
  if (overflow_ > 0) {
    diagnostics.push_back(Diagnostic{Diagnostic::Severity::Warning, SourceLocation{file, 0, 0},
                                     std::to_string(overflow_) + " more " + noun + " with unknown keywords ignored"});
  }
}

LensFormat lens_format_from_path(const std::string& path) {
  const std::string ext = lower_extension(path.substr(0, path.find('#')));
  if (ext == ".json") return LensFormat::Json;
  if (ext == ".zmx") return LensFormat::Zemax;
  if (ext == ".dat") return LensFormat::Pbrt;
  if (ext == ".seq") return LensFormat::CodeV;
  throw FileError({path, 0, 0}, "unknown lens file type \"" + ext +
                                        "\"; expected .json (lensmith or lentil), .zmx (Zemax), .seq (CODE V) or .dat (pbrt)");
}

namespace {

LensReadResult read_any(const std::string& path_with_id, const GlassCatalog& catalogue);

}  // namespace

LensReadResult read_lens_file(const std::string& path_with_id, const GlassCatalog& catalogue) {
  LensReadResult result = read_any(path_with_id, catalogue);
  const std::string path = path_with_id.substr(0, path_with_id.rfind('#'));
  for (Diagnostic d : result.prescription.geometry_warnings()) {
    d.where.file = path;
    result.diagnostics.push_back(std::move(d));
  }
  return result;
}

namespace {

LensReadResult read_any(const std::string& path_with_id, const GlassCatalog& catalogue) {
  std::string path = path_with_id;
  std::string entry_id;
  if (auto hash = path_with_id.rfind('#'); hash != std::string::npos && lower_extension(path_with_id.substr(0, hash)) == ".json") {
    path = path_with_id.substr(0, hash);
    entry_id = path_with_id.substr(hash + 1);
  }
  const LensFormat format = lens_format_from_path(path);
  const std::string bytes = read_file_bytes(path);
  switch (format) {
    case LensFormat::Zemax: return read_zemax(bytes, path, catalogue);
    case LensFormat::CodeV: return read_codev(bytes, path, catalogue);
    case LensFormat::Pbrt: return read_pbrt(decode_text(bytes, path), path);
    case LensFormat::Json:
    case LensFormat::Lentil: {
      const std::string text = decode_text(bytes, path);
      if (looks_like_lentil(text)) {
        if (entry_id.empty()) {
          throw FileError({path, 0, 0}, "this is a lentil lens database; name an entry after '#', e.g. " + path + "#0001 "
                                            "(`lensmith lenses --lentil " + path + "` lists them)");
        }
        return read_lentil(text, path, entry_id, catalogue);
      }
      if (!entry_id.empty()) throw FileError({path, 0, 0}, "'#" + entry_id + "' given, but this is not a lentil database");
      return read_lens_json(text, path, catalogue);
    }
  }
  throw FileError({path, 0, 0}, "unsupported lens format");
}

}  // namespace

}  // namespace lensmith

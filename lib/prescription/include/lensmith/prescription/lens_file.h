// Reading a lens from a file of any supported format, and the result every reader returns.
#pragma once

#include <cstddef>
#include <functional>
#include <map>
#include <string>
#include <string_view>

#include "lensmith/core/diagnostic.h"
#include "lensmith/glass/glass_catalog.h"
#include "lensmith/prescription/prescription.h"

namespace lensmith {

// A prescription read from a file (validated and with materials resolved) and the warnings met
// on the way (e.g. a Zemax glass missing from every catalogue, replaced by its nd/Vd).
struct LensReadResult {
  Prescription prescription;
  Diagnostics diagnostics;
};

enum class LensFormat { Json, Zemax, Pbrt, Lentil, CodeV };

// The format a path names, from its extension: .json -> Json (or Lentil when the file is a
// lentil database; see read_lens_file), .zmx -> Zemax, .seq -> CodeV, .dat -> Pbrt. Throws FileError.
LensFormat lens_format_from_path(const std::string& path);

// Reads any supported lens file. For a lentil database the path takes the entry id after a '#':
// "lenses.json#0001". Throws IoError, FileError, GlassError or PrescriptionError.
LensReadResult read_lens_file(const std::string& path, const GlassCatalog& catalogue = GlassCatalog::builtin());

// For readers: resolves the materials of `lens` against `catalogue` and validates it, turning a
// GlassError or PrescriptionError into a FileError at `file`, on the line `line_of` finds for the
// error's subject (the surface or field it is about; 0 when unknown).
void resolve_and_validate(Prescription& lens, const GlassCatalog& catalogue, const std::string& file,
                          const std::function<int(const ErrorSubject& subject)>& line_of);

// For readers: the name of a lens whose file gives none, the file name without folder and extension
// ("lenses/US8427765.zmx" -> "US8427765").
std::string lens_name_from_path(const std::string& path);

// For readers: the field value of the point (x, y) that a rotationally symmetric lens sees, its
// distance from the axis: for angles (degrees) the angle whose tangent is the length of
// (tan x, tan y), for heights sqrt(x^2 + y^2). Units as given.
double radial_field_value(FieldSpec::Kind kind, double x, double y);

// For readers: keywords a reader does not know, reported once each as warnings after the file is
// read (at most kMaxListed of them; the rest are counted in one more warning).
class UnknownKeywords {
 public:
  static constexpr std::size_t kMaxListed = 50;
  void record(std::string_view keyword, int line);
  // Appends "unknown keyword FROB ignored (3 <noun>)" at each keyword's first line.
  void report(Diagnostics& diagnostics, const std::string& file, const std::string& noun) const;

 private:
  struct Seen {
    int first_line = 0;
    int count = 0;
  };
  std::map<std::string, Seen> seen_;
  std::size_t overflow_ = 0;
};

}  // namespace lensmith

// Reading a lens from a file of any supported format, and the result every reader returns.
#pragma once

#include <functional>
#include <string>

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

enum class LensFormat { Json, Zemax, Pbrt, Lentil };

// The format a path names, from its extension: .json -> Json (or Lentil when the file is a
// lentil database; see read_lens_file), .zmx -> Zemax, .dat -> Pbrt. Throws LensFileError.
LensFormat lens_format_from_path(const std::string& path);

// Reads any supported lens file. For a lentil database the path takes the entry id after a '#':
// "lenses.json#0001". Throws IoError, LensFileError, GlassError or PrescriptionError.
LensReadResult read_lens_file(const std::string& path, const GlassCatalog& catalogue = GlassCatalog::builtin());

// For readers: resolves the materials of `lens` against `catalogue` and validates it, turning a
// GlassError or PrescriptionError into a LensFileError at `file`, on the line `line_of` finds for the
// message (0 when unknown).
void resolve_and_validate(Prescription& lens, const GlassCatalog& catalogue, const std::string& file,
                          const std::function<int(const std::string& message)>& line_of);

}  // namespace lensmith

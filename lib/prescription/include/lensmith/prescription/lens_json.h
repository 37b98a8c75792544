// lensmith's native lens format (JSON), documented key by key in docs/lens-format.md.
// Reading is strict: unknown keys, wrong types and out-of-range values are errors with file:line:col.
// Writing then reading gives back an identical Prescription.
#pragma once

#include <string>
#include <string_view>

#include "lensmith/glass/glass_catalog.h"
#include "lensmith/prescription/lens_file.h"

namespace lensmith {

// The format version this build writes and the newest it reads.
inline constexpr int kLensFormatVersion = 1;

// Parses a native lens file. `file_name` is used in error messages.
LensReadResult read_lens_json(std::string_view text, const std::string& file_name,
                              const GlassCatalog& catalogue = GlassCatalog::builtin());

// Serialises a prescription in the native format (pretty-printed, stable key order, numbers written
// with enough digits to round-trip exactly).
std::string write_lens_json(const Prescription& prescription);

}  // namespace lensmith

// The lenses shipped with lensmith (lenses/*.json), compiled into the library, found by name.
#pragma once

#include <string>
#include <vector>

#include "lensmith/prescription/lens_file.h"

namespace lensmith {

struct ShippedLens {
  std::string id;      // file name without ".json", e.g. "smith-cooke-triplet"
  std::string name;    // the prescription's "name"
  std::string source;  // the prescription's "source"
};

class LensLibrary {
 public:
  // The shipped lenses, sorted by id.
  static std::vector<ShippedLens> list();
  // True when `id` names a shipped lens.
  static bool contains(const std::string& id);
  // Reads a shipped lens. Throws FileError naming the closest ids when `id` is unknown.
  static LensReadResult load(const std::string& id, const GlassCatalog& catalogue = GlassCatalog::builtin());
  // LENS as the CLI takes it: a path to an existing file, or else the id of a shipped lens.
  static LensReadResult load_path_or_name(const std::string& path_or_id,
                                          const GlassCatalog& catalogue = GlassCatalog::builtin());
};

}  // namespace lensmith

// Reader for the lentil lens database (github.com/zpelgrims/lentil, polynomial-optics/database/
// lenses.json, MIT licence): one JSON object of entries keyed by id.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "lensmith/glass/glass_catalog.h"
#include "lensmith/prescription/lens_file.h"

namespace lensmith {

struct LentilEntrySummary {
  std::string id;            // e.g. "0001"
  std::string company;
  std::string product_name;
  int year = 0;
  double patent_focal_length_mm = 0.0;  // 0 when unknown
  bool production_ready = false;
  bool supported = false;    // read_lentil() can read it: no zoom, exactly one iris
};

// Lists the entries of a lentil database.
std::vector<LentilEntrySummary> list_lentil_entries(std::string_view text, const std::string& file_name);

// Reads entry `id` ("optical-elements-patent", at patent scale). Materials: a glass name found in the
// catalogues whose nd lies within 0.002 of the entry's "ior" is used as that catalogue glass;
// otherwise a model glass from "ior" and "abbe" with a note. "iris" is the stop (its housing radius
// sets the aperture, which floats by the stop). Cylindrical surfaces and zoom thickness lists are
// errors naming the element. Throws FileError.
LensReadResult read_lentil(std::string_view text, const std::string& file_name, const std::string& id,
                           const GlassCatalog& catalogue = GlassCatalog::builtin());

}  // namespace lensmith

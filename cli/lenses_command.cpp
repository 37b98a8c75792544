// `lensmith lenses`: the shipped lenses, or the entries of a lentil lens database.
#include <iomanip>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "lensmith/core/json_text.h"
#include "lensmith/core/text_file.h"
#include "lensmith/prescription/lens_library.h"
#include "lensmith/prescription/lentil_reader.h"

namespace lensmith::cli {

int run_lenses(const LensesOptions& options, const GlobalOptions&) {
  if (!options.lentil_database.empty()) {
    const std::string text = decode_text(read_file_bytes(options.lentil_database), options.lentil_database);
    const auto entries = list_lentil_entries(text, options.lentil_database);
    if (options.json) {
      nlohmann::ordered_json out = nlohmann::ordered_json::array();
      for (const auto& e : entries) {
        out.push_back({{"id", e.id}, {"company", e.company}, {"product_name", e.product_name}, {"year", e.year},
                       {"patent_focal_length_mm", e.patent_focal_length_mm}, {"production_ready", e.production_ready},
                       {"supported", e.supported}});
      }
      std::cout << json_text(out, 2) << "\n";
      return kExitOk;
    }
    std::cout << std::left << std::setw(6) << "id" << std::setw(24) << "company" << std::setw(34) << "product" << std::setw(6) << "year"
              << "readable\n";
    for (const auto& e : entries) {
      std::cout << std::setw(6) << e.id << std::setw(24) << e.company << std::setw(34) << e.product_name << std::setw(6) << e.year
                << (e.supported ? "yes" : "no (no single iris, or a zoom)") << "\n";
    }
    std::cout << "read one with: lensmith info " << options.lentil_database << "#ID\n";
    return kExitOk;
  }
  const auto lenses = LensLibrary::list();
  if (options.json) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const auto& l : lenses) out.push_back({{"id", l.id}, {"name", l.name}, {"source", l.source}});
    std::cout << json_text(out, 2) << "\n";
    return kExitOk;
  }
  std::size_t width = 4;
  for (const auto& l : lenses) width = std::max(width, l.id.size() + 2);
  for (const auto& l : lenses) std::cout << std::left << std::setw(static_cast<int>(width)) << l.id << l.name << "\n";
  return kExitOk;
}

}  // namespace lensmith::cli

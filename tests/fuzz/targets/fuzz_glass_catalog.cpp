// libFuzzer target: the compact JSON glass-catalogue reader, and evaluating what it accepts.
#include <cstdint>
#include <string_view>

#include "lensmith/core/errors.h"
#include "lensmith/glass/glass_catalog.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto catalogue = lensmith::GlassCatalog::from_json(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.json");
    volatile double sink = 0.0;
    for (const auto& g : catalogue.glasses()) sink = sink + g.index(550.0);
    (void)catalogue.find("N-BK7");
    (void)catalogue.closest_names("NBK7");
  } catch (const lensmith::Error&) {
  }
  return 0;
}

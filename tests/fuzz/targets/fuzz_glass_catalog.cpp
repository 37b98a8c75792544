// libFuzzer target: glass catalogue readers, lensmith's compact JSON and Zemax .agf (the same bytes
// through both).
#include <cstdint>
#include <string_view>

#include "lensmith/core/errors.h"
#include "lensmith/glass/glass_catalog.h"

namespace {

void use(const lensmith::GlassCatalog& catalogue) {
  volatile double sink = 0.0;
  for (const auto& g : catalogue.glasses()) sink = sink + g.index(550.0);
  (void)catalogue.find("N-BK7");
  (void)catalogue.closest_names("NBK7");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    use(lensmith::GlassCatalog::from_json(text, "fuzz.json"));
  } catch (const lensmith::Error&) {
  }
  try {
    use(lensmith::GlassCatalog::from_agf(text, "fuzz.agf", "FUZZ"));
  } catch (const lensmith::Error&) {
  }
  return 0;
}

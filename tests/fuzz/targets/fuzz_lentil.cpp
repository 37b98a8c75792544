// libFuzzer target: lentil lens-database reader: list the entries, then read each (a bounded number).
#include <cstdint>
#include <string_view>

#include "json_output_check.h"
#include "lensmith/core/errors.h"
#include "lensmith/prescription/lentil_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto entries = lensmith::list_lentil_entries(text, "fuzz.json");
    std::size_t tried = 0;
    for (const auto& e : entries) {
      if (++tried > 8) break;
      try {
        check_json_output(lensmith::read_lentil(text, "fuzz.json", e.id));
      } catch (const lensmith::Error&) {
      }
    }
    lensmith::read_lentil(text, "fuzz.json", "no-such-id");
  } catch (const lensmith::Error&) {
  }
  return 0;
}

// libFuzzer target: lensmith's native JSON lens reader, and the writer on whatever it accepts.
#include <cstdint>
#include <string_view>

#include "lensmith/core/errors.h"
#include "lensmith/prescription/lens_json.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto result = lensmith::read_lens_json(text, "fuzz.json");
    // Whatever is accepted must round-trip.
    const auto again = lensmith::read_lens_json(lensmith::write_lens_json(result.prescription), "again.json");
    if (!(again.prescription == result.prescription)) __builtin_trap();
  } catch (const lensmith::Error&) {
  }
  return 0;
}

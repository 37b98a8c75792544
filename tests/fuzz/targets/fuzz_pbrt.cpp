// libFuzzer target: pbrt .dat reader in all three convention modes.
#include <cstdint>
#include <string_view>

#include "json_output_check.h"
#include "lensmith/core/errors.h"
#include "lensmith/prescription/pbrt_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  for (auto convention : {lensmith::PbrtConvention::Auto, lensmith::PbrtConvention::ThicknessToNext,
                          lensmith::PbrtConvention::SeparationFromPrevious}) {
    try {
      check_json_output(lensmith::read_pbrt(text, "fuzz.dat", convention));
    } catch (const lensmith::Error&) {
    }
  }
  return 0;
}

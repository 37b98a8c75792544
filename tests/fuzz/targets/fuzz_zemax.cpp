// libFuzzer target: Zemax .zmx reader (UTF-8 and UTF-16 input).
#include <cstdint>
#include <string_view>

#include "json_output_check.h"
#include "lensmith/core/errors.h"
#include "lensmith/prescription/zemax_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    check_json_output(lensmith::read_zemax(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.zmx"));
  } catch (const lensmith::Error&) {
  }
  return 0;
}

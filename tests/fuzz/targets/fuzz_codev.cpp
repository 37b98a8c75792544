// libFuzzer target: CODE V .seq reader (any text encoding decode_text accepts).
#include <cstdint>
#include <string_view>

#include "json_output_check.h"
#include "lensmith/core/errors.h"
#include "lensmith/prescription/codev_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    check_json_output(lensmith::read_codev(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.seq"));
  } catch (const lensmith::Error&) {
  }
  return 0;
}

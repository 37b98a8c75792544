// What every lens reader's fuzz target also checks: a lens it reads can be written as lensmith JSON,
// and that JSON is valid UTF-8 that parses back (an ANSI lens name once made `info --json` and
// `convert` die with nlohmann's type_error 316, an internal error). A lensmith::Error from the writer
// is the caller's to catch; anything else reaches libFuzzer as a crash.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "lensmith/core/text_file.h"
#include "lensmith/prescription/lens_json.h"

inline void check_json_output(const lensmith::LensReadResult& result) {
  const std::string text = lensmith::write_lens_json(result.prescription);
  if (!lensmith::is_valid_utf8(text)) __builtin_trap();
  (void)nlohmann::json::parse(text);
}

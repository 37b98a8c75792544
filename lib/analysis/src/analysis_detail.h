// Helpers shared by the analysis sources (not installed).
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "lensmith/core/errors.h"

namespace lensmith::analysis_detail {

// `count` evenly spaced values from 0 to 1, both ends included (count >= 2).
inline std::vector<double> relative_field_samples(int count) {
  std::vector<double> out;
  for (int i = 0; i < count; ++i) out.push_back(static_cast<double>(i) / (count - 1));
  return out;
}

inline void check_count(const char* name, int value, int min, int max) {
  if (value < min || value > max) {
    throw OptionsError(std::string(name) + " = " + std::to_string(value) + ": must be " + std::to_string(min) + " to " +
                       std::to_string(max));
  }
}

inline std::string fixed(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

}  // namespace lensmith::analysis_detail

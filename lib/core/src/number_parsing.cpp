#include "lensmith/core/number_parsing.h"

#include <charconv>
#include <cmath>
#include <system_error>

namespace lensmith {

std::optional<double> parse_finite_number(std::string_view s) {
  // std::from_chars takes no leading '+'; a doubled sign stays an error.
  if (s.size() >= 2 && s.front() == '+' && s[1] != '-' && s[1] != '+') s.remove_prefix(1);
  if (s.empty()) return std::nullopt;
  double v = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v, std::chars_format::general);
  if (ec != std::errc() || end != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::string format_number(double value) {
  char buffer[32];  // the longest shortest-form double is 24 characters
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  return ec == std::errc() ? std::string(buffer, end) : std::string("?");
}

std::string format_rounded(double value, int significant_digits) {
  char buffer[48];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::general,
                                       significant_digits < 1 ? 1 : significant_digits > 17 ? 17 : significant_digits);
  return ec == std::errc() ? std::string(buffer, end) : std::string("?");
}

}  // namespace lensmith

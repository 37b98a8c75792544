// Locale-free ASCII helpers for the readers of text files and file names: the blanks between the
// fields of a line, trimming, case. Lens, glass and image formats are ASCII where these matter
// (keywords, extensions, channel names); other bytes (UTF-8 names) pass through unchanged.
#pragma once

#include <string>
#include <string_view>

namespace lensmith {

// Space, tab, carriage return, form feed, vertical tab: the blanks between fields on one line (not
// the line break '\n').
constexpr bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

// `s` without its leading and trailing blanks.
constexpr std::string_view trim_blanks(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

// `s` with A-Z turned to a-z (to_lower_ascii) or a-z to A-Z (to_upper_ascii).
inline std::string to_lower_ascii(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c;
  return out;
}
inline std::string to_upper_ascii(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = c >= 'a' && c <= 'z' ? static_cast<char>(c - 'a' + 'A') : c;
  return out;
}

}  // namespace lensmith

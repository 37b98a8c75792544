// Numbers in user text files and messages: strict, locale-free parsing that never accepts what C
// runtimes print for overflow or invalid values, and the shortest text that reads back exactly.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace lensmith {

// The whole token as a finite decimal number (a leading '+' allowed). Rejects "nan", "inf",
// OpticStudio's "1.#INF" / "-1.#IND", trailing characters and values out of double range.
std::optional<double> parse_finite_number(std::string_view token);

// The shortest decimal text that parses back to exactly `value` ("0.1", "-2", "1e-05", "nan", "inf"),
// for messages that quote a value from the user's file.
std::string format_number(double value);
// `value` to at most `significant_digits` (1..17) significant digits, trailing zeros dropped ("2.03",
// "0.5", "1.2e+06"), for prose that states a computed value.
std::string format_rounded(double value, int significant_digits);

}  // namespace lensmith

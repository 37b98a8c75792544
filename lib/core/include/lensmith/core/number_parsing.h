// Parsing numbers from the tokens of user text files (Zemax, pbrt): strict, locale-free, and never
// accepting what C runtimes print for overflow or invalid values.
#pragma once

#include <optional>
#include <string_view>

namespace lensmith {

// The whole token as a finite decimal number (a leading '+' allowed). Rejects "nan", "inf",
// OpticStudio's "1.#INF" / "-1.#IND", trailing characters and values out of double range.
std::optional<double> parse_finite_number(std::string_view token);

}  // namespace lensmith

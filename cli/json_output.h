// Small helpers shared by the subcommands' --json output.
#pragma once

#include <cmath>

#include <nlohmann/json.hpp>

namespace lensmith::cli {

using ojson = nlohmann::ordered_json;

// JSON has no infinity or NaN: a non-finite number (a distance at infinity, a ray that died) is null.
inline ojson number_or_null(double v) { return std::isfinite(v) ? ojson(v) : ojson(nullptr); }

}  // namespace lensmith::cli

// The subcommands' --json: the library's one schema (lensmith/report/json_report.h).
#pragma once

#include "lensmith/report/json_report.h"

namespace lensmith::cli {

using lensmith::number_or_null;
using lensmith::ojson;

}  // namespace lensmith::cli

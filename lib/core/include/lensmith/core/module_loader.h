// lensmith's modules: shared objects the command line loads the first time a command needs them
// (liblensmith_ceres.so for the solvers, liblensmith_ocio.so for colour management), so that a
// process that needs neither does not load the libraries behind them (Ceres' 17, OpenColorIO's 4:
// about 8 ms of every process's start-up, docs/performance.md). Programs that link lensmith's
// libraries get the same code linked in and load nothing.
//
// Where a module is looked for: in $LENSMITH_MODULE_DIR alone where that is set; else beside the
// program (the build tree) and in <libdir>/lensmith relative to the program's folder (an install).
// Module and program are built together by the same compiler from the same sources; each module's
// table of functions starts with an int ABI number, which must match the program's.
#pragma once

namespace lensmith {

// The table `entry` returns in module `file` (e.g. "liblensmith_ceres.so"), loaded once and kept for
// the process's life, after checking that it starts with `abi`. Throws IoError naming every place
// it looked and why each failed, `purpose` saying what the module is for ("its solver").
const void* load_module(const char* file, const char* entry, int abi, const char* purpose);

}  // namespace lensmith

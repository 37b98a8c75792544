// The command line's TIFF module (liblensmith_tiff.so): tiff_codec.cpp and libtiff in a shared object
// of their own, which the command line loads the first time a command reads or writes a TIFF
// (tiff_module_client.cpp, lensmith/core/module_loader.h). libtiff and the five libraries it brings
// (libwebp, libzstd, liblzma, libLerc, libjbig) cost every process about 0.7 ms to load otherwise:
// `lensmith --version` 4.24 -> 3.55 ms, medians of 101 (docs/performance.md), which is 1-2 % of a
// 600 x 400 bokeh render's whole process. Programs that link lensmith::imageio get tiff_codec.cpp
// linked in and load nothing.
//
// Module and program are built together by the same compiler from the same sources: the table
// passes C++ types as they are, and the errors tiff_codec.cpp throws (ImageFileError, IoError) reach
// the program's handlers as they are (as the Ceres module's do, ceres_module.h). kTiffModuleAbi
// guards against a module of another build that changed the table.
#pragma once

#include "codecs.h"

namespace lensmith::codecs {

// Raised whenever TiffModuleApi changes.
inline constexpr int kTiffModuleAbi = 1;

struct TiffModuleApi {
  int abi = kTiffModuleAbi;  // first: load_module checks it
  RasterInfo (*read_tiff_info)(const fs::path&) = nullptr;
  Decoded (*read_tiff)(const fs::path&) = nullptr;
  Metadata (*read_tiff_metadata)(const fs::path&) = nullptr;
  void (*write_tiff_file)(const fs::path&, const std::string&, const PixelsView<std::uint16_t>&, const std::vector<ImageAttribute>&) = nullptr;
};

// The module's one exported symbol.
inline constexpr const char* kTiffModuleEntry = "lensmith_tiff_module_api";
// The module's file name: beside the command line in the build tree, in <libdir>/lensmith installed.
inline constexpr const char* kTiffModuleFile = "liblensmith_tiff.so";

}  // namespace lensmith::codecs

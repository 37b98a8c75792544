// The command line's PNG and JPEG module (liblensmith_png_jpeg.so): png_codec.cpp, jpeg_codec.cpp,
// libpng and libjpeg-turbo in a shared object of their own, which the command line loads the first
// time a command reads a PNG's chunks, writes a PNG or decodes a JPEG (png_jpeg_module_client.cpp,
// lensmith/core/module_loader.h), as it loads libtiff (tiff_module.h). Loaded at start-up, the two
// libraries cost every process about 17 page faults (`lensmith --version`: 265 -> 248), which on the
// KVM guest of docs/performance.md cost up to 40 us each, in a 600 x 400 EXR-to-EXR render that
// touches neither format. (stb_image, compiled into lensmith::imageio, still decodes PNG pixels and
// writes JPEG.) Programs that link lensmith::imageio get the codecs linked in and load nothing.
//
// Module and program are built together by the same compiler from the same sources: the table
// passes C++ types as they are, and the errors the codecs throw (ImageFileError, IoError) reach the
// program's handlers as they are (as the TIFF module's do). kPngJpegModuleAbi guards against a
// module of another build that changed the table.
#pragma once

#include "codecs.h"

namespace lensmith::codecs {

// Raised whenever PngJpegModuleApi changes.
inline constexpr int kPngJpegModuleAbi = 1;

struct PngJpegModuleApi {
  int abi = kPngJpegModuleAbi;  // first: load_module checks it
  PngChunks (*read_png_chunks)(const fs::path&) = nullptr;
  void (*write_png_file)(const fs::path&, const std::string&, const PixelsView<std::uint8_t>&, const std::vector<ImageAttribute>&) = nullptr;
  RasterInfo (*read_jpeg_info)(const fs::path&) = nullptr;
  Decoded (*read_jpeg)(const fs::path&) = nullptr;
};

// The module's one exported symbol.
inline constexpr const char* kPngJpegModuleEntry = "lensmith_png_jpeg_module_api";
// The module's file name: beside the command line in the build tree, in <libdir>/lensmith installed.
inline constexpr const char* kPngJpegModuleFile = "liblensmith_png_jpeg.so";

}  // namespace lensmith::codecs

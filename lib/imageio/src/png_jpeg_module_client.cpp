// The command line's libpng and libjpeg functions (codecs.h): the same functions, forwarded to the PNG
// and JPEG module (png_jpeg_module.h), which is loaded on the first call (lensmith/core/module_loader.h).
// Linked into the command line as objects, so that the linker finds these definitions before
// lensmith::imageio's png_codec.cpp and jpeg_codec.cpp (which would pull libpng and libjpeg in).
#include "lensmith/core/module_loader.h"
#include "png_jpeg_module.h"

namespace lensmith::codecs {

namespace {

const PngJpegModuleApi& module() {
  return *static_cast<const PngJpegModuleApi*>(load_module(kPngJpegModuleFile, kPngJpegModuleEntry, kPngJpegModuleAbi, "PNG and JPEG pictures"));
}

}  // namespace

PngChunks read_png_chunks(const fs::path& path) { return module().read_png_chunks(path); }

void write_png_file(const fs::path& path, const std::string& file, const PixelsView<std::uint8_t>& pixels,
                    const std::vector<ImageAttribute>& attributes) {
  module().write_png_file(path, file, pixels, attributes);
}

RasterInfo read_jpeg_info(const fs::path& path) { return module().read_jpeg_info(path); }

Decoded read_jpeg(const fs::path& path) { return module().read_jpeg(path); }

}  // namespace lensmith::codecs

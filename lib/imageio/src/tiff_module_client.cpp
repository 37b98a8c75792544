// The command line's TIFF functions (codecs.h): the same functions, forwarded to the TIFF module
// (tiff_module.h), which is loaded on the first call (lensmith/core/module_loader.h). Linked into the
// command line as objects, so that the linker finds these definitions before lensmith::imageio's
// tiff_codec.cpp (which would pull libtiff in).
#include "lensmith/core/module_loader.h"
#include "tiff_module.h"

namespace lensmith::codecs {

namespace {

const TiffModuleApi& module() {
  return *static_cast<const TiffModuleApi*>(load_module(kTiffModuleFile, kTiffModuleEntry, kTiffModuleAbi, "TIFF pictures"));
}

}  // namespace

RasterInfo read_tiff_info(const fs::path& path) { return module().read_tiff_info(path); }

Decoded read_tiff(const fs::path& path) { return module().read_tiff(path); }

Metadata read_tiff_metadata(const fs::path& path) { return module().read_tiff_metadata(path); }

void write_tiff_file(const fs::path& path, const std::string& file, const PixelsView<std::uint16_t>& pixels,
                     const std::vector<ImageAttribute>& attributes) {
  module().write_tiff_file(path, file, pixels, attributes);
}

}  // namespace lensmith::codecs

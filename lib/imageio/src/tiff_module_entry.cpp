// The TIFF module's entry point (tiff_module.h): the table of tiff_codec.cpp's functions. The module
// is built with hidden visibility and -Bsymbolic, so that these addresses are the module's own
// functions and not the command line's stand-ins of the same names (tiff_module_client.cpp).
#include "tiff_module.h"

extern "C" __attribute__((visibility("default"))) const void* lensmith_tiff_module_api() {
  namespace c = lensmith::codecs;
  static const c::TiffModuleApi api{c::kTiffModuleAbi, &c::read_tiff_info, &c::read_tiff, &c::read_tiff_metadata, &c::write_tiff_file};
  return &api;
}

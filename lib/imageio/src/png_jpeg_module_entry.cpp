// The PNG and JPEG module's entry point (png_jpeg_module.h): the table of the codecs' functions. The
// module is built with hidden visibility and -Bsymbolic, so that these addresses are the module's own
// functions and not the command line's stand-ins of the same names (png_jpeg_module_client.cpp).
#include "png_jpeg_module.h"

extern "C" __attribute__((visibility("default"))) const void* lensmith_png_jpeg_module_api() {
  namespace c = lensmith::codecs;
  static const c::PngJpegModuleApi api{c::kPngJpegModuleAbi, &c::read_png_chunks, &c::write_png_file, &c::read_jpeg_info, &c::read_jpeg};
  return &api;
}

// The OpenColorIO module's entry point (ocio_backend.h): the table of ocio_backend.cpp's functions.
// The module is built with hidden visibility and -Bsymbolic, so that this is the module's own table
// and not the command line's stand-in of the same name (ocio_module_client.cpp).
#include "ocio_backend.h"

extern "C" __attribute__((visibility("default"))) const void* lensmith_ocio_module_api() {
  return &lensmith::color_detail::ocio_backend();
}

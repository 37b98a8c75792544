# Finds OpenColorIO 2 and defines the imported target OpenColorIO::OpenColorIO.
#
# Debian 12's libopencolorio-dev installs its CMake package file in /usr/share/cmake/ itself, where
# find_package's config search does not look, and that file computes its include directory from its
# own location as "/include", which does not exist; so lensmith finds the header and the library
# itself (the same result OpenColorIO's own file means to give).
find_path(OpenColorIO_INCLUDE_DIR OpenColorIO/OpenColorIO.h)
find_library(OpenColorIO_LIBRARY NAMES OpenColorIO)
if(OpenColorIO_INCLUDE_DIR AND EXISTS "${OpenColorIO_INCLUDE_DIR}/OpenColorIO/OpenColorABI.h")
  file(STRINGS "${OpenColorIO_INCLUDE_DIR}/OpenColorIO/OpenColorABI.h" _ocio_version REGEX "^#define OCIO_VERSION_STR +\"[0-9.]+\"")
  string(REGEX REPLACE ".*\"([0-9.]+)\".*" "\\1" OpenColorIO_VERSION "${_ocio_version}")
  unset(_ocio_version)
endif()
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(OpenColorIO REQUIRED_VARS OpenColorIO_LIBRARY OpenColorIO_INCLUDE_DIR VERSION_VAR OpenColorIO_VERSION)
if(OpenColorIO_FOUND AND NOT TARGET OpenColorIO::OpenColorIO)
  add_library(OpenColorIO::OpenColorIO UNKNOWN IMPORTED)
  set_target_properties(OpenColorIO::OpenColorIO PROPERTIES
    IMPORTED_LOCATION "${OpenColorIO_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${OpenColorIO_INCLUDE_DIR}")
endif()
mark_as_advanced(OpenColorIO_INCLUDE_DIR OpenColorIO_LIBRARY)

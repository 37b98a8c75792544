# The command line must not load Ceres, OpenColorIO, libtiff, libpng, libjpeg and the shared libraries
# they bring when it starts: they are loaded from lensmith's modules when a command first solves
# something, converts colour spaces or reads or writes a TIFF, a PNG's chunks or a JPEG's pixels
# (lensmith/core/module_loader.h; about 8 ms of every process otherwise, docs/performance.md).
# Reads the binary's DT_NEEDED entries with readelf and fails naming any of them; also fails when a
# module is not beside the binary.
execute_process(COMMAND ${READELF} -d ${BINARY} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${READELF} -d ${BINARY} failed (${rc}): ${err}")
endif()
string(REGEX MATCHALL "\\(NEEDED\\)[^\n]*\\[[^]\n]+\\]" needed "${out}")
if(NOT needed)
  message(FATAL_ERROR "no NEEDED entries read from ${BINARY}:\n${out}")
endif()
foreach(library glog gflags cholmod spqr cxsparse lapack blas ceres OpenColorIO yaml-cpp pystring expat tiff webp zstd lzma Lerc jbig png16 jpeg)
  foreach(entry ${needed})
    if(entry MATCHES "\\[lib${library}[.-]")
      message(FATAL_ERROR "${BINARY} loads ${entry} at start-up; it belongs to a module")
    endif()
  endforeach()
endforeach()
get_filename_component(folder ${BINARY} DIRECTORY)
foreach(module liblensmith_ceres.so liblensmith_ocio.so liblensmith_tiff.so liblensmith_png_jpeg.so)
  if(NOT EXISTS ${folder}/${module})
    message(FATAL_ERROR "no ${folder}/${module} beside ${BINARY}")
  endif()
endforeach()
list(LENGTH needed count)
message(STATUS "${count} shared libraries at start-up, none of Ceres', OpenColorIO's, libtiff's, libpng's or libjpeg's")

# Installs the build into a fresh prefix and builds examples/lens_camera against it with
# find_package(lensmith), as a user of the installed package would, then runs it, and runs the installed
# command line's optimiser (its Ceres module). Fails when any step fails or the picture it writes is not
# a 240 x 160 binary PPM.

# Runs one command (a list), failing with its output when it fails; its output in `out`.
function(run_step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${ARGN} failed (${rc}):\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE ${WORK})
foreach(step
    "${CMAKE_COMMAND};--install;${BUILD_DIR};--prefix;${WORK}/prefix"
    "${CMAKE_COMMAND};-S;${SOURCE};-B;${WORK}/build;-G;${GENERATOR};-DCMAKE_BUILD_TYPE=Release;-DCMAKE_CXX_COMPILER=${CXX};-DCMAKE_PREFIX_PATH=${WORK}/prefix"
    "${CMAKE_COMMAND};--build;${WORK}/build"
    "${WORK}/build/lens_camera_example;${WORK}/out.ppm")
  run_step(${step})
endforeach()
message(STATUS "${out}")
# The installed command line finds its Ceres module (lib/solve/src/ceres_module.h) in <libdir>/lensmith
# relative to itself: one optimiser iteration needs it.
run_step(${WORK}/prefix/bin/lensmith optimize ${SOURCE}/../optimize/rough-triplet.json --merit ${SOURCE}/../optimize/triplet-merit.json
         --iterations 1 --threads 2 -o ${WORK}/optimised.json)
if(NOT EXISTS ${WORK}/optimised.json)
  message(FATAL_ERROR "the installed lensmith optimize wrote no ${WORK}/optimised.json")
endif()
file(SIZE ${WORK}/out.ppm bytes)
file(READ ${WORK}/out.ppm head LIMIT 15)
if(NOT head STREQUAL "P6\n240 160\n255\n" OR NOT bytes EQUAL 115215)
  message(FATAL_ERROR "${WORK}/out.ppm: ${bytes} bytes, header '${head}': expected a 240 x 160 binary PPM")
endif()

# Every library the package exports, linked by one more consumer: a static library carries its
# private dependencies (OpenEXR, libjpeg, Ceres, ...), so each must be found by lensmithConfig.cmake
# or configuring fails ("target JPEG::JPEG not found" once imageio took libjpeg and the config did not
# look for it; lens_camera links lensmith::camera only and did not see it).
file(MAKE_DIRECTORY ${WORK}/all)
file(WRITE ${WORK}/all/CMakeLists.txt [=[
cmake_minimum_required(VERSION 3.22)
project(every_lensmith_library LANGUAGES CXX)
find_package(lensmith REQUIRED)
get_property(imported DIRECTORY PROPERTY IMPORTED_TARGETS)
list(FILTER imported INCLUDE REGEX "^lensmith::")
if(NOT imported MATCHES "lensmith::render")
  message(FATAL_ERROR "the package exports no lensmith::render (it has: ${imported})")
endif()
add_executable(every_library main.cpp)
target_link_libraries(every_library PRIVATE ${imported})
]=])
file(WRITE ${WORK}/all/main.cpp "int main() { return 0; }\n")
foreach(step
    "${CMAKE_COMMAND};-S;${WORK}/all;-B;${WORK}/all/build;-G;${GENERATOR};-DCMAKE_BUILD_TYPE=Release;-DCMAKE_CXX_COMPILER=${CXX};-DCMAKE_PREFIX_PATH=${WORK}/prefix"
    "${CMAKE_COMMAND};--build;${WORK}/all/build")
  run_step(${step})
endforeach()

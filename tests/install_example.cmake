# Installs the build into a fresh prefix and builds examples/lens_camera against it with
# find_package(lensmith), as a user of the installed package would, then runs it. Fails when any
# step fails or the picture it writes is not a 240 x 160 binary PPM.
file(REMOVE_RECURSE ${WORK})
foreach(step
    "${CMAKE_COMMAND};--install;${BUILD_DIR};--prefix;${WORK}/prefix"
    "${CMAKE_COMMAND};-S;${SOURCE};-B;${WORK}/build;-G;${GENERATOR};-DCMAKE_BUILD_TYPE=Release;-DCMAKE_CXX_COMPILER=${CXX};-DCMAKE_PREFIX_PATH=${WORK}/prefix"
    "${CMAKE_COMMAND};--build;${WORK}/build"
    "${WORK}/build/lens_camera_example;${WORK}/out.ppm")
  execute_process(COMMAND ${step} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${step} failed (${rc}):\n${out}\n${err}")
  endif()
endforeach()
message(STATUS "${out}")
file(SIZE ${WORK}/out.ppm bytes)
file(READ ${WORK}/out.ppm head LIMIT 15)
if(NOT head STREQUAL "P6\n240 160\n255\n" OR NOT bytes EQUAL 115215)
  message(FATAL_ERROR "${WORK}/out.ppm: ${bytes} bytes, header '${head}': expected a 240 x 160 binary PPM")
endif()

# lensmith_add_library(NAME SOURCES ... DEPENDS ...)
# One library per optical concept. Its public headers live in lib/NAME/include/lensmith/NAME/,
# so a target sees only its own headers and those of the layers it links: the build enforces
# the layering (trace/ cannot include render/ because render's include dir is not on its path).
function(lensmith_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPENDS;PRIVATE_DEPENDS" ${ARGN})
  add_library(lensmith_${name} ${ARG_SOURCES})
  add_library(lensmith::${name} ALIAS lensmith_${name})
  set_target_properties(lensmith_${name} PROPERTIES EXPORT_NAME ${name} OUTPUT_NAME lensmith_${name}
    POSITION_INDEPENDENT_CODE ON)
  target_compile_features(lensmith_${name} PUBLIC cxx_std_20)
  target_include_directories(lensmith_${name} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(lensmith_${name} PUBLIC ${ARG_DEPENDS} PRIVATE ${ARG_PRIVATE_DEPENDS}
    $<BUILD_INTERFACE:lensmith_warnings>)
  install(TARGETS lensmith_${name} EXPORT lensmithTargets)
  install(DIRECTORY include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endfunction()

# lensmith_add_module(name SOURCES ... DEPENDS ... CLIENT client.cpp): one of the command line's modules
# (lensmith/core/module_loader.h), liblensmith_<name>.so, and the client objects that load it
# (lensmith_<name>_client, linked into the command line). The module binds its own functions inside
# itself (hidden visibility, -Bsymbolic), so that its table holds them and not the command line's
# stand-ins of the same names, and keeps the symbols of static libraries linked into it to itself
# (--exclude-libs); it lies beside the command line in the build tree and in <libdir>/lensmith installed.
function(lensmith_add_module name)
  cmake_parse_arguments(ARG "" "CLIENT" "SOURCES;DEPENDS" ${ARGN})
  add_library(lensmith_${name}_module MODULE ${ARG_SOURCES})
  set_target_properties(lensmith_${name}_module PROPERTIES OUTPUT_NAME lensmith_${name} CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON LIBRARY_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR})
  target_compile_features(lensmith_${name}_module PRIVATE cxx_std_20)
  target_include_directories(lensmith_${name}_module PRIVATE include)
  target_link_libraries(lensmith_${name}_module PRIVATE ${ARG_DEPENDS} lensmith_warnings)
  target_link_options(lensmith_${name}_module PRIVATE LINKER:-Bsymbolic LINKER:--exclude-libs,ALL)
  install(TARGETS lensmith_${name}_module LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/lensmith)

  add_library(lensmith_${name}_client OBJECT ${ARG_CLIENT})
  target_compile_features(lensmith_${name}_client PRIVATE cxx_std_20)
  target_include_directories(lensmith_${name}_client PUBLIC include)
  target_link_libraries(lensmith_${name}_client PUBLIC lensmith::core PRIVATE lensmith_warnings)
endfunction()

# lensmith_embed_files(OUT_CPP NAMESPACE_FN FILES ...)
# Generates a .cpp that defines `std::span<const EmbeddedFile> FN()` holding the bytes of FILES,
# so the library carries its glass catalogues and shipped lenses and needs no data directory.
function(lensmith_embed_files out_cpp function_name)
  cmake_parse_arguments(ARG "" "BASE_DIR" "FILES" ${ARGN})
  add_custom_command(OUTPUT ${out_cpp}
    COMMAND ${CMAKE_COMMAND} -DOUT=${out_cpp} -DFUNCTION=${function_name} -DBASE_DIR=${ARG_BASE_DIR}
            "-DFILES=${ARG_FILES}" -P ${PROJECT_SOURCE_DIR}/cmake/EmbedFiles.cmake
    DEPENDS ${ARG_FILES} ${PROJECT_SOURCE_DIR}/cmake/EmbedFiles.cmake
    COMMENT "Embedding ${function_name} data" VERBATIM)
endfunction()

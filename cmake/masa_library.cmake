# masa_library(<target> FOLDER <dir> [SOURCES <files>...] [DEPENDS <masa libraries>...] [EXTERNAL <targets>...])
#
# One folder, one library: the target compiles <dir>/*.cpp (not its subfolders, which are libraries
# of their own) unless SOURCES names the files. DEPENDS are the masa libraries below it, EXTERNAL
# the packages it uses. Every call is recorded in <build>/masa_layers.txt, which the layering check
# (tests/tools/check_layers.py) reads: a file in <dir> may include only headers of its own library
# and of the libraries it depends on, directly or through them. An include that points up a layer
# fails the test suite, so the folders keep saying what the build does.
function(masa_library target)
  cmake_parse_arguments(L "" "FOLDER" "SOURCES;DEPENDS;EXTERNAL" ${ARGN})
  if(NOT L_FOLDER)
    message(FATAL_ERROR "masa_library(${target}): FOLDER is required")
  endif()
  if(NOT L_SOURCES)
    file(GLOB L_SOURCES CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/${L_FOLDER}/*.cpp)
  endif()
  add_library(${target} STATIC ${L_SOURCES})
  if(MASA_BUILD_PYTHON)  # linked into the Python module, a shared object
    set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  endif()
  target_include_directories(${target} PUBLIC ${CMAKE_SOURCE_DIR})
  target_link_libraries(${target} PUBLIC ${L_DEPENDS} ${L_EXTERNAL})
  if(TARGET masa.core AND NOT target STREQUAL "masa.core")
    target_precompile_headers(${target} REUSE_FROM masa.core)  # the headers every library parses (CMakeLists.txt)
  endif()
  list(JOIN L_DEPENDS " " deps)
  set_property(GLOBAL APPEND PROPERTY MASA_LAYERS "${target} ${L_FOLDER} ${deps}")
endfunction()

# A library whose headers are made at build time (lcm-gen's message types): its include prefix and
# the folder of its sources, for the layering check.
function(masa_record_generated_library target folder include_prefix)
  set_property(GLOBAL APPEND PROPERTY MASA_LAYERS "${target} ${folder} GENERATED:${include_prefix}")
endfunction()

# Writes the record once every library is declared (called at the end of the top-level CMakeLists).
function(masa_write_layers)
  get_property(layers GLOBAL PROPERTY MASA_LAYERS)
  string(REPLACE ";" "\n" text "${layers}")
  # Each line: <target> <folder> <dependency targets...> (or GENERATED:<include prefix>).
  file(WRITE ${CMAKE_BINARY_DIR}/masa_layers.txt "${text}\n")
endfunction()

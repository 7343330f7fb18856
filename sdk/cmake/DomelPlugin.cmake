# domel_add_plugin(<name> SOURCES <files...>)
# Builds a domel plugin: a shared library linked only against domel::sdk,
# with hidden symbols except the one entry point, and no "lib" prefix games.
function(domel_add_plugin name)
  cmake_parse_arguments(ARG "" "OUTPUT_DIRECTORY" "SOURCES" ${ARGN})
  add_library(${name} MODULE ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE domel::sdk)
  set_target_properties(${name} PROPERTIES
    CXX_VISIBILITY_PRESET hidden
    C_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON
    PREFIX "lib")
  # Export only entry symbols (domel_plugin_entry_v<major>): a version script also hides the weak
  # C++ standard-library instantiations that -fvisibility=hidden leaves visible.
  if(CMAKE_SYSTEM_NAME STREQUAL "Linux")
    set(map ${CMAKE_CURRENT_BINARY_DIR}/${name}.exports.map)
    file(WRITE ${map} "{ global: domel_plugin_entry_v*; local: *; };\n")
    target_link_options(${name} PRIVATE "LINKER:--version-script=${map}")
    set_property(TARGET ${name} APPEND PROPERTY LINK_DEPENDS ${map})
  endif()
  # The flags domel's own kernels are built with (docs/sdk-guide.md, "Fast batch kernels"): sqrt without the
  # errno path and no floating-point traps, so that branch-free loops over a batch vectorise. Neither
  # changes a value (no re-association, no contraction).
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${name} PRIVATE $<$<COMPILE_LANGUAGE:CXX>:-fno-math-errno -fno-trapping-math>)
  endif()
  if(ARG_OUTPUT_DIRECTORY)
    set_target_properties(${name} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${ARG_OUTPUT_DIRECTORY})
  endif()
endfunction()

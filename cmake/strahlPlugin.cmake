# strahl_add_plugin(NAME SOURCES src.c... [SHADERS dir]): a strahl plugin
# (a MODULE library named NAME.so, hidden visibility, linked to strahl),
# built into <build>/modules/. The same call builds the in-tree plugins
# (modules/NAME/CMakeLists.txt, where strahl::strahl is the framework target)
# and a plugin against an installed strahl (find_package(strahl)).
# Its GLSL, if any, goes beside the .so as shaders/NAME/ (in the build folder
# and on install), where strahl's loader finds it; the plugin loads its
# shaders as "NAME/file" and may include strahl's "common/..." files.
# Every plugin defined is appended to the global property STRAHL_PLUGINS.

# Without a build type a plugin would be built unoptimised; strahl's own
# build is Release, and a plugin built the same way computes the same.
if(NOT CMAKE_BUILD_TYPE AND NOT CMAKE_CONFIGURATION_TYPES)
  set(CMAKE_BUILD_TYPE Release)
endif()

function(strahl_add_plugin name)
  cmake_parse_arguments(P "" "SHADERS" "SOURCES" ${ARGN})
  set(out ${CMAKE_BINARY_DIR}/modules)
  add_library(${name} MODULE ${P_SOURCES})
  target_link_libraries(${name} PRIVATE strahl::strahl)
  set_target_properties(${name} PROPERTIES PREFIX "" OUTPUT_NAME "${name}"
    C_VISIBILITY_PRESET hidden CXX_VISIBILITY_PRESET hidden LIBRARY_OUTPUT_DIRECTORY ${out})
  if(NOT DEFINED CMAKE_C_STANDARD) # strahl's headers are C11
    set_target_properties(${name} PROPERTIES C_STANDARD 11 C_STANDARD_REQUIRED ON C_EXTENSIONS OFF)
  endif()
  install(TARGETS ${name} LIBRARY DESTINATION lib/strahl/modules)
  if(P_SHADERS)
    get_filename_component(dir ${P_SHADERS} ABSOLUTE)
    add_custom_command(TARGET ${name} POST_BUILD
      COMMAND ${CMAKE_COMMAND} -E copy_directory ${dir} ${out}/shaders/${name})
    install(DIRECTORY ${dir}/ DESTINATION lib/strahl/modules/shaders/${name})
  endif()
  set_property(GLOBAL APPEND PROPERTY STRAHL_PLUGINS ${name})
endfunction()

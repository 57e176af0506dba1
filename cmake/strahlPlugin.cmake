# strahl_add_plugin(NAME SOURCES src.c... [SHADERS dir]): a strahl plugin
# (a MODULE library named NAME.so, hidden visibility, linked to strahl).
# Its GLSL, if any, goes beside the .so as shaders/NAME/ (in the build folder
# and on install), where strahl's loader finds it; the plugin loads its
# shaders as "NAME/file" and may include strahl's "common/..." files.
function(strahl_add_plugin name)
  cmake_parse_arguments(P "" "SHADERS" "SOURCES" ${ARGN})
  set(out ${CMAKE_BINARY_DIR}/modules)
  add_library(${name} MODULE ${P_SOURCES})
  target_link_libraries(${name} PRIVATE strahl::strahl)
  set_target_properties(${name} PROPERTIES PREFIX "" OUTPUT_NAME "${name}"
    C_VISIBILITY_PRESET hidden CXX_VISIBILITY_PRESET hidden LIBRARY_OUTPUT_DIRECTORY ${out})
  install(TARGETS ${name} LIBRARY DESTINATION lib/strahl/modules)
  if(P_SHADERS)
    get_filename_component(dir ${P_SHADERS} ABSOLUTE)
    add_custom_command(TARGET ${name} POST_BUILD
      COMMAND ${CMAKE_COMMAND} -E copy_directory ${dir} ${out}/shaders/${name})
    install(DIRECTORY ${dir}/ DESTINATION lib/strahl/modules/shaders/${name})
  endif()
endfunction()

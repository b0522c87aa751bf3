# swarmsim_kilobot_program(NAME SOURCE [CC_FLAGS flag...])
#
# Builds the Kilobot program SOURCE (C, written for kilolib, unchanged) with
# `swarmsim kilobot build` into build/plugins/NAME.so, whose native
# controller NAME a world runs with `plugins: [NAME]` and
# `native_controller: NAME` (plugins/ beside the swarmsim program is where
# worlds look for NAME.so). Rebuilt when the source, kilolib's headers, the
# runtime or the program change.
function(swarmsim_kilobot_program name source)
  cmake_parse_arguments(ARG "" "" "CC_FLAGS" ${ARGN})
  get_filename_component(source_path ${source} ABSOLUTE)
  set(output ${CMAKE_BINARY_DIR}/plugins/${name}.so)
  file(GLOB runtime_files ${SWARMSIM_KILOBOT_DIR}/include/*.h ${SWARMSIM_KILOBOT_DIR}/runtime/*)
  add_custom_command(
    OUTPUT ${output}
    COMMAND $<TARGET_FILE:swarmsim> kilobot build ${source_path} -o ${output} --name ${name}
            --quiet -- ${ARG_CC_FLAGS}
    DEPENDS swarmsim ${source_path} ${runtime_files} ${PROJECT_SOURCE_DIR}/framework/plugin_api.h
    COMMENT "Kilobot program ${name} (${source})"
    VERBATIM)
  add_custom_target(kilobot_program_${name} ALL DEPENDS ${output})
endfunction()

# Beside the driver ARTICULA, a link articula-<stage> to it for each stage
# of its table (`articula stages --json`); run after each build of it.
execute_process(COMMAND ${ARTICULA} stages --json OUTPUT_VARIABLE table RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${ARTICULA} stages --json exited ${rc}")
endif()
get_filename_component(folder ${ARTICULA} DIRECTORY)
get_filename_component(driver ${ARTICULA} NAME)
string(JSON count LENGTH "${table}" stages)
math(EXPR last "${count} - 1")
foreach(i RANGE ${last})
  string(JSON stage GET "${table}" stages ${i} name)
  execute_process(COMMAND ${CMAKE_COMMAND} -E create_symlink ${driver} ${folder}/articula-${stage} COMMAND_ERROR_IS_FATAL ANY)
endforeach()

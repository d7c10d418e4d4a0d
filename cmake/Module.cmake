# A module of lib/: its library articula_<name>, its public headers in
# include/, its links, the project's warnings.
#   articula_module(<name> SOURCES src/a.cpp ... [PUBLIC deps...] [PRIVATE deps...])
function(articula_module name)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "" "" "SOURCES;PUBLIC;PRIVATE")
  add_library(articula_${name} ${ARG_SOURCES})
  target_include_directories(articula_${name} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include)
  target_link_libraries(articula_${name} PUBLIC ${ARG_PUBLIC} PRIVATE ${ARG_PRIVATE})
  articula_warnings(articula_${name})
endfunction()

# Version and git commit baked into lib/core, so every result file carries
# them. The commit is read at every build (not only at configure time), and
# version.cpp is rewritten only when it changes.
set(ARTICULA_VERSION_CPP ${CMAKE_BINARY_DIR}/generated/version.cpp)
add_custom_target(articula_version_info
  COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${CMAKE_SOURCE_DIR} -DVERSION=${PROJECT_VERSION}
          -DTEMPLATE=${CMAKE_SOURCE_DIR}/lib/core/src/version.cpp.in -DOUTPUT=${ARTICULA_VERSION_CPP}
          -P ${CMAKE_SOURCE_DIR}/cmake/GenerateVersion.cmake
  BYPRODUCTS ${ARTICULA_VERSION_CPP}
  COMMENT "Reading the git commit")

# Simbody's own contact is the peer measured in the same run.
target_link_libraries(${target} PRIVATE SimTKsimbody)
# The foot scenes are read from the source tree.
target_compile_definitions(${target} PRIVATE ARTICULA_SCENES_DIR="${PROJECT_SOURCE_DIR}/scenes")

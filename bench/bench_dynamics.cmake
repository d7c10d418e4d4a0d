# Simbody's own contact is the peer measured in the same run.
target_link_libraries(${target} PRIVATE SimTKsimbody)

# Peers measured in the same run as our solver (see docs/benchmarks.md).
target_link_libraries(${target} PRIVATE SimTKsimbody ccd fcl PkgConfig::BULLET64)

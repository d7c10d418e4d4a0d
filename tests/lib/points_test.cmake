# The legacy .vtk tests write meshes with VTK's writer and read them with VTK's reader to compare.
target_link_libraries(${test_name} PRIVATE VTK::CommonCore VTK::CommonDataModel VTK::FiltersCore VTK::IOLegacy)

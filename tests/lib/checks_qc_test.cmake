target_link_libraries(${test_name} PRIVATE articula_geometry)

# The slice images' test reads the PNG's deflate stream back with zlib.
find_package(ZLIB REQUIRED)
target_link_libraries(${test_name} PRIVATE ZLIB::ZLIB)

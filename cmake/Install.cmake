# `cmake --install`: the libraries, the public headers, the CMake package (fretbuzz::fretbuzz),
# a pkg-config file, the program, its man page and the built-in cases.
include(CMakePackageConfigHelpers)
set(FRETBUZZ_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/fretbuzz)

install(TARGETS fretbuzz fretbuzz_shared EXPORT fretbuzzTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY include/fretbuzz ${FRETBUZZ_GENERATED_INCLUDE}/fretbuzz DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT fretbuzzTargets NAMESPACE fretbuzz:: DESTINATION ${FRETBUZZ_CMAKE_DIR})

configure_package_config_file(cmake/fretbuzzConfig.cmake.in ${CMAKE_BINARY_DIR}/fretbuzzConfig.cmake
  INSTALL_DESTINATION ${FRETBUZZ_CMAKE_DIR} PATH_VARS CMAKE_INSTALL_DATADIR)
write_basic_package_version_file(${CMAKE_BINARY_DIR}/fretbuzzConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/fretbuzzConfig.cmake ${CMAKE_BINARY_DIR}/fretbuzzConfigVersion.cmake
  DESTINATION ${FRETBUZZ_CMAKE_DIR})

# The Python package's data files (the page templates, the studio's script and style sheet),
# installed next to its modules in <prefix>/<libdir>/fretbuzz/python/fretbuzz.
if(FRETBUZZ_BUILD_PYTHON)
  install(DIRECTORY python/fretbuzz/ DESTINATION ${CMAKE_INSTALL_LIBDIR}/fretbuzz/python/fretbuzz
    FILES_MATCHING PATTERN "*.j2" PATTERN "*.js" PATTERN "*.css")
endif()

# Relocatable: the prefix is found from the .pc file's own place (pkg-config's pcfiledir).
file(RELATIVE_PATH FRETBUZZ_PC_TO_PREFIX /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
configure_file(cmake/fretbuzz.pc.in ${CMAKE_BINARY_DIR}/fretbuzz.pc @ONLY)
install(FILES ${CMAKE_BINARY_DIR}/fretbuzz.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

install(DIRECTORY cases/ DESTINATION ${CMAKE_INSTALL_DATADIR}/fretbuzz/cases)

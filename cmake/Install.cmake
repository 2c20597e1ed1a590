# `cmake --install`: the libraries, the public headers, the CMake package (fretbuzz::fretbuzz),
# a pkg-config file, the program, its man page, the built-in cases and, with the Python
# module built, the Python package the program runs (setup, sweep --scheduler).
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
install(FILES LICENSE DESTINATION ${CMAKE_INSTALL_DOCDIR})

# The Python package for the installed program: <prefix>/<libdir>/fretbuzz/python/fretbuzz,
# private to fretbuzz (the program finds it from its own place, cli/PythonScript.cpp; it is
# built for the interpreter the program runs, /usr/bin/python3 unless Python_EXECUTABLE
# says otherwise). `pip install .` installs the same package for a Python environment.
set(FRETBUZZ_PYTHON_INSTALL_DIR ${CMAKE_INSTALL_LIBDIR}/fretbuzz/python)
if(FRETBUZZ_BUILD_PYTHON)
  install(FILES $<TARGET_FILE:fretbuzz_python> DESTINATION ${FRETBUZZ_PYTHON_INSTALL_DIR}/fretbuzz)
  install(DIRECTORY python/fretbuzz/ DESTINATION ${FRETBUZZ_PYTHON_INSTALL_DIR}/fretbuzz
    FILES_MATCHING PATTERN "*.py" PATTERN "*.pyi" PATTERN "py.typed" PATTERN "__pycache__" EXCLUDE)
endif()

# The consumer test: install this build into a fresh prefix, build tests/consumer against
# it (CMake package and pkg-config), run both programs, and check the installed extras.
# Usage: cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... [-DLAUNCHER=ccache] -P ConsumerTest.cmake
function(step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "failed (${status}): ${ARGN}")
  endif()
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
step(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
foreach(expected bin/fretbuzz include/fretbuzz/Case.hpp include/fretbuzz/Version.hpp share/man/man1/fretbuzz.1
                 share/fretbuzz/cases/bass-pop.toml share/fretbuzz/cases/data/bass_fretted_modes.csv)
  if(NOT EXISTS ${prefix}/${expected})
    message(FATAL_ERROR "not installed: ${expected}")
  endif()
endforeach()
file(GLOB_RECURSE configs ${prefix}/*/fretbuzzConfig.cmake ${prefix}/*/fretbuzzConfigVersion.cmake ${prefix}/*/fretbuzz.pc
     ${prefix}/*/libfretbuzz.a ${prefix}/*/libfretbuzz.so)
list(LENGTH configs found)
if(NOT found EQUAL 5)
  message(FATAL_ERROR "expected the config, version, .pc and both libraries, found: ${configs}")
endif()

file(GLOB_RECURSE pc_file ${prefix}/*/fretbuzz.pc)
get_filename_component(pc_dir ${pc_file} DIRECTORY)
set(ENV{PKG_CONFIG_PATH} ${pc_dir})
set(extra)
if(LAUNCHER)
  set(extra -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER})
endif()
step(${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/consumer -B ${WORK_DIR}/build -DCMAKE_PREFIX_PATH=${prefix} ${extra})
step(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
step(${WORK_DIR}/build/consumer)
step(${WORK_DIR}/build/consumer_pkgconfig)
step(${WORK_DIR}/build/consumer_static)
step(${WORK_DIR}/build/consumer_pkgconfig_static)
step(${prefix}/bin/fretbuzz show bass-pop)

# The installed program runs the installed Python package (setup, sweep --scheduler), not
# the build's: Python's import log (PYTHONVERBOSE) must name the package under the prefix
# only. An unreachable scheduler: the package imports, reads the spec, then refuses (exit 2).
if(EXISTS ${BUILD_DIR}/python/module/fretbuzz/__init__.py)
  file(GLOB_RECURSE package_init ${prefix}/*/fretbuzz/python/fretbuzz/__init__.py)
  file(GLOB_RECURSE package_core ${prefix}/*/fretbuzz/python/fretbuzz/_core*.so)
  if(NOT package_init OR NOT package_core)
    message(FATAL_ERROR "the Python package is not installed under ${prefix}/<libdir>/fretbuzz/python")
  endif()
  file(WRITE ${WORK_DIR}/spec.toml "[sweep]\ncase = \"bass-pluck\"\n[[parameter]]\nkey = \"contact.K\"\nvalues = [1e12]\n")
  execute_process(COMMAND ${CMAKE_COMMAND} -E env PYTHONVERBOSE=1 --unset=FRETBUZZ_PYTHONPATH
                          ${prefix}/bin/fretbuzz sweep ${WORK_DIR}/spec.toml --out ${WORK_DIR}/sweep
                          --scheduler tcp://127.0.0.1:9 --scheduler-timeout 2
                  RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT status EQUAL 2 OR NOT err MATCHES "--scheduler tcp://127.0.0.1:9")
    message(FATAL_ERROR "the installed program's sweep --scheduler: exit ${status}, expected 2 (no scheduler):\n${err}")
  endif()
  string(FIND "${err}" "${prefix}/" at_prefix)
  string(FIND "${err}" "${BUILD_DIR}/python/module" at_build)
  if(at_prefix EQUAL -1 OR NOT at_build EQUAL -1)
    message(FATAL_ERROR "the installed program did not import the installed package (import log):\n${err}")
  endif()
endif()

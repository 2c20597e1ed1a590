# The LV2 bundle goes where hosts look: lib/lv2 under a system prefix, ~/.lv2 for a prefix in
# the home folder. Run by ctest: cmake -P Lv2InstallDirTest.cmake
cmake_minimum_required(VERSION 3.25)
include(${CMAKE_CURRENT_LIST_DIR}/Lv2InstallDir.cmake)
foreach(entry IN ITEMS "/usr|/home/ann|lib/lv2" "/usr/local|/home/ann|lib/lv2" "/opt/fretbuzz|/home/ann|lib/lv2"
                       "/home/ann/.local|/home/ann|/home/ann/.lv2" "/home/ann|/home/ann|/home/ann/.lv2"
                       "/home/ann/apps/../.local|/home/ann/|/home/ann/.lv2" "/home/anna/.local|/home/ann|lib/lv2"
                       "/usr/local||lib/lv2" "/usr|/|lib/lv2")
  string(REPLACE "|" ";" entry "${entry}")
  list(GET entry 0 prefix)
  list(GET entry 1 home)
  list(GET entry 2 expected)
  fretbuzz_lv2_install_dir(dir "${prefix}" "${home}")
  cmake_path(COMPARE "${dir}" EQUAL "${expected}" same)
  if(NOT same)
    message(FATAL_ERROR "prefix ${prefix}, home '${home}': the bundle would go to ${dir}, not ${expected}")
  endif()
endforeach()
message(STATUS "every prefix gives the folder hosts search")

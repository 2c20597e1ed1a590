# fretbuzz_lv2_install_dir(OUT PREFIX HOME): the folder an LV2 bundle installed under PREFIX
# belongs in, where hosts find it: HOME/.lv2 if PREFIX lies in the home folder HOME (hosts do
# not search ~/.local/lib/lv2), else lib/lv2 under the prefix (a relative path).
function(fretbuzz_lv2_install_dir out prefix home)
  set(dir lib/lv2)
  if(NOT home STREQUAL "" AND NOT home STREQUAL "/")
    cmake_path(IS_PREFIX home "${prefix}" NORMALIZE inside)
    if(inside)
      set(dir "${home}/.lv2")
    endif()
  endif()
  set(${out} "${dir}" PARENT_SCOPE)
endfunction()

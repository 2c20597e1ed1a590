# The man page: help2man on the program's --help and --version, with a COMMANDS section
# holding each subcommand's own --help, so the page documents every option.
# Usage: cmake -DPROGRAM=... -DHELP2MAN=... -DOUTPUT=fretbuzz.1 -P ManPage.cmake
execute_process(COMMAND ${PROGRAM} --help OUTPUT_VARIABLE help RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "${PROGRAM} --help failed")
endif()
string(REGEX REPLACE ".*Subcommands:\n" "" listing "${help}")
string(REGEX MATCHALL "\n?  [a-z][a-z-]*" names "${listing}")
set(sections "[COMMANDS]\n")
foreach(name IN LISTS names)
  string(STRIP "${name}" name)
  execute_process(COMMAND ${PROGRAM} ${name} --help OUTPUT_VARIABLE sub)
  string(REPLACE "${PROGRAM}" "fretbuzz" sub "${sub}")
  string(APPEND sections ".SS ${name}\n.nf\n${sub}\n.fi\n")
endforeach()
file(WRITE ${OUTPUT}.include "${sections}")
execute_process(COMMAND ${HELP2MAN} --no-info --name "simulate strings vibrating against obstacles"
                        --include ${OUTPUT}.include --output ${OUTPUT} ${PROGRAM} RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "help2man failed")
endif()

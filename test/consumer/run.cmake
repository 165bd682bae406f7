# CTest script: install the built planarvo into a scratch prefix, move the installed tree
# elsewhere (an installed package must not depend on where it was installed), then configure,
# build and run test/consumer against the moved tree through find_package and through
# pkg-config, and build the same program with nothing but `cc $(pkg-config --cflags --libs
# planarvo)`, as a Makefile user would, and the installed C example the same way.
# Variables: BUILD_DIR (planarvo's build), SOURCE_DIR (test/consumer), WORK_DIR (scratch),
# C_COMPILER, CONSUMER_C_FLAGS (the sanitizer flags when planarvo is built with them).
file(REMOVE_RECURSE ${WORK_DIR})
set(installed ${WORK_DIR}/installed)
set(prefix ${WORK_DIR}/moved)
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
  set(run_output "${out}" PARENT_SCOPE)
endfunction()
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${installed})
file(RENAME ${installed} ${prefix})
# The licence and the user documentation are installed with the package.
foreach(doc LICENSE README.md formats.md conventions.md outputs.md examples/README.md
           examples/c/track_and_calibrate.c examples/python/track_and_calibrate.py)
  if(NOT EXISTS ${prefix}/share/doc/planarvo/${doc})
    message(FATAL_ERROR "not installed: share/doc/planarvo/${doc}")
  endif()
endforeach()
file(GLOB_RECURSE pcfile ${prefix}/*/planarvo.pc)
get_filename_component(pcdir "${pcfile}" DIRECTORY)
get_filename_component(libdir "${pcdir}" DIRECTORY)

# Plain pkg-config, no --define-prefix: the flags must point into the moved tree.
find_program(PKG_CONFIG pkg-config pkgconf REQUIRED)
run(${CMAKE_COMMAND} -E env PKG_CONFIG_PATH=${pcdir} ${PKG_CONFIG} --cflags --libs planarvo)
string(STRIP "${run_output}" flags)
string(FIND "${flags}" "-I${prefix}/" at_include)
string(FIND "${flags}" "-L${prefix}/" at_lib)
if(at_include EQUAL -1 OR at_lib EQUAL -1)
  message(FATAL_ERROR "pkg-config flags do not point into ${prefix}: ${flags}")
endif()
separate_arguments(flags UNIX_COMMAND "${flags}")
separate_arguments(c_flags UNIX_COMMAND "${CONSUMER_C_FLAGS}")
run(${C_COMPILER} ${c_flags} ${SOURCE_DIR}/consumer.c -o ${WORK_DIR}/consumer_cc ${flags})
run(${CMAKE_COMMAND} -E env LD_LIBRARY_PATH=${libdir} ${WORK_DIR}/consumer_cc)
# The installed example builds as examples/README.md says.
run(${C_COMPILER} ${c_flags} ${prefix}/share/doc/planarvo/examples/c/track_and_calibrate.c
    -o ${WORK_DIR}/track_and_calibrate -lm ${flags})

run(${CMAKE_COMMAND} -E env PKG_CONFIG_PATH=${pcdir}
    ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR}/build -DCMAKE_PREFIX_PATH=${prefix}
    -DCMAKE_C_COMPILER=${C_COMPILER} "-DCMAKE_C_FLAGS=${CONSUMER_C_FLAGS}")
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run(${CMAKE_COMMAND} -E env LD_LIBRARY_PATH=${libdir} ${WORK_DIR}/build/consumer)
run(${CMAKE_COMMAND} -E env LD_LIBRARY_PATH=${libdir} ${WORK_DIR}/build/consumer_pkgconfig)
# The installed tool finds its library through its RPATH, with no environment help.
run(${prefix}/bin/planarvo version)

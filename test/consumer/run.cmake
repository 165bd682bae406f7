# CTest script: install the built planarvo into a scratch prefix, then configure, build and run
# test/consumer against it through find_package and through pkg-config.
# Variables: BUILD_DIR (planarvo's build), SOURCE_DIR (test/consumer), WORK_DIR (scratch),
# CONSUMER_C_FLAGS (the sanitizer flags when planarvo is built with them).
file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
endfunction()
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
file(GLOB_RECURSE pcfile ${prefix}/*/planarvo.pc)
get_filename_component(pcdir "${pcfile}" DIRECTORY)
run(${CMAKE_COMMAND} -E env PKG_CONFIG_PATH=${pcdir}
    ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR}/build -DCMAKE_PREFIX_PATH=${prefix}
    -DPKG_CONFIG_ARGN=--define-prefix "-DCMAKE_C_FLAGS=${CONSUMER_C_FLAGS}")
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
get_filename_component(libdir "${pcdir}" DIRECTORY)
run(${CMAKE_COMMAND} -E env LD_LIBRARY_PATH=${libdir} ${WORK_DIR}/build/consumer)
run(${CMAKE_COMMAND} -E env LD_LIBRARY_PATH=${libdir} ${WORK_DIR}/build/consumer_pkgconfig)
# The installed tool finds its library through its RPATH, with no environment help.
run(${prefix}/bin/planarvo version)

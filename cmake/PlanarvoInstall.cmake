# Installation: the library with an exported target planarvo::planarvo, a CMake package
# (planarvoConfig.cmake + version file), a pkg-config file, the CLI, the built-in texture and the
# Python package.
include(CMakePackageConfigHelpers)

install(TARGETS planarvo EXPORT planarvoTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  PUBLIC_HEADER DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/planarvo)
# The vision module (src/capi/README.md), found by the library relative to itself.
install(TARGETS planarvo_vision LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/planarvo)
# One RUNPATH for the build tree and the installed tool, both relative to the binary: the library
# beside it (build tree) or in ../lib (install). Letting CMake rewrite a build-tree RUNPATH at
# install instead leaves an empty entry in the build tree's (".../build:", room for the rewrite),
# which the loader reads as the current directory: a build-tree `planarvo` looked for every
# library in the working directory first (a dozen failed opens per library at start-up, and a
# library planted there would be loaded).
set_target_properties(planarvo_cli PROPERTIES
  BUILD_WITH_INSTALL_RPATH ON
  INSTALL_RPATH "$ORIGIN/../${CMAKE_INSTALL_LIBDIR}:$ORIGIN")
install(TARGETS planarvo_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# The licence and the user documentation (file formats, conventions, outputs) go where Debian
# puts a package's: <prefix>/share/doc/planarvo.
install(FILES ${PROJECT_SOURCE_DIR}/LICENSE ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(FILES ${PROJECT_SOURCE_DIR}/data/textures/asphalt_01.png
        DESTINATION ${CMAKE_INSTALL_DATADIR}/planarvo/textures)
# The Python package (python/README.md) where Debian's python3 finds packages of a prefix:
# <prefix>/lib/python3/dist-packages (PYTHONPATH for a prefix other than /usr and /usr/local). It
# loads the library from <prefix>/lib or <prefix>/lib/<multiarch>, relative to itself.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/python/planarvo/
        DESTINATION lib/python3/dist-packages/planarvo
        FILES_MATCHING PATTERN "*.py" PATTERN "py.typed" PATTERN "__pycache__" EXCLUDE)

set(PLANARVO_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/planarvo)
install(EXPORT planarvoTargets NAMESPACE planarvo:: DESTINATION ${PLANARVO_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/planarvoConfig.cmake.in
  ${PROJECT_BINARY_DIR}/planarvoConfig.cmake INSTALL_DESTINATION ${PLANARVO_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/planarvoConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/planarvoConfig.cmake
              ${PROJECT_BINARY_DIR}/planarvoConfigVersion.cmake
        DESTINATION ${PLANARVO_CMAKE_DIR})

# A relocatable pkg-config file: prefix is found from the .pc file's own directory
# (${pcfiledir}, e.g. ${pcfiledir}/../.. for lib/pkgconfig, one more .. for a multiarch
# lib/x86_64-linux-gnu), and libdir and includedir are relative to prefix, so the installed tree
# works wherever it is put (`cmake --install --prefix`, DESTDIR, a moved or unpacked tree) with
# no `--define-prefix`. A LIBDIR or INCLUDEDIR given as an absolute path stays absolute (and an
# absolute LIBDIR makes prefix CMAKE_INSTALL_PREFIX): such a layout cannot move.
set(PLANARVO_PC_DIR ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}")
  set(PLANARVO_PC_PREFIX "${CMAKE_INSTALL_PREFIX}")
else()
  file(RELATIVE_PATH up "/prefix/${PLANARVO_PC_DIR}" "/prefix")
  string(REGEX REPLACE "/$" "" up "${up}")
  set(PLANARVO_PC_PREFIX "\${pcfiledir}/${up}")
endif()
foreach(kind LIBDIR INCLUDEDIR)
  if(IS_ABSOLUTE "${CMAKE_INSTALL_${kind}}")
    set(PLANARVO_PC_${kind} "${CMAKE_INSTALL_FULL_${kind}}")
  else()
    set(PLANARVO_PC_${kind} "\${prefix}/${CMAKE_INSTALL_${kind}}")
  endif()
endforeach()
configure_file(${PROJECT_SOURCE_DIR}/cmake/planarvo.pc.in ${PROJECT_BINARY_DIR}/planarvo.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/planarvo.pc DESTINATION ${PLANARVO_PC_DIR})

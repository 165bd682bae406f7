# Installation: the library with an exported target planarvo::planarvo, a CMake package
# (planarvoConfig.cmake + version file), a pkg-config file, the CLI and the built-in texture.
include(CMakePackageConfigHelpers)

install(TARGETS planarvo EXPORT planarvoTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  PUBLIC_HEADER DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/planarvo)
set_target_properties(planarvo_cli PROPERTIES INSTALL_RPATH "$ORIGIN/../${CMAKE_INSTALL_LIBDIR}")
install(TARGETS planarvo_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(FILES ${PROJECT_SOURCE_DIR}/data/textures/asphalt_01.png
        DESTINATION ${CMAKE_INSTALL_DATADIR}/planarvo/textures)

set(PLANARVO_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/planarvo)
install(EXPORT planarvoTargets NAMESPACE planarvo:: DESTINATION ${PLANARVO_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/planarvoConfig.cmake.in
  ${PROJECT_BINARY_DIR}/planarvoConfig.cmake INSTALL_DESTINATION ${PLANARVO_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/planarvoConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/planarvoConfig.cmake
              ${PROJECT_BINARY_DIR}/planarvoConfigVersion.cmake
        DESTINATION ${PLANARVO_CMAKE_DIR})

# Paths relative to ${prefix} where the install layout allows, so that `pkg-config
# --define-prefix` relocates the package; absolute (CMAKE_INSTALL_FULL_*) otherwise.
foreach(kind LIBDIR INCLUDEDIR)
  if(IS_ABSOLUTE "${CMAKE_INSTALL_${kind}}")
    set(PLANARVO_PC_${kind} "${CMAKE_INSTALL_FULL_${kind}}")
  else()
    set(PLANARVO_PC_${kind} "\${prefix}/${CMAKE_INSTALL_${kind}}")
  endif()
endforeach()
configure_file(${PROJECT_SOURCE_DIR}/cmake/planarvo.pc.in ${PROJECT_BINARY_DIR}/planarvo.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/planarvo.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

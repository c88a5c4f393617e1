# Installation: `cmake --install build --prefix PREFIX` puts the tools in PREFIX/bin, the library
# and its headers in PREFIX/lib and PREFIX/include/nrslam, and a CMake package, so that another
# project builds on the library with
#   find_package(nrslam 0.1 REQUIRED)
#   target_link_libraries(my_program PRIVATE nrslam::nrslam)
# (CMAKE_PREFIX_PATH=PREFIX when PREFIX is not a standard one). The manifests and the
# documentation go to PREFIX/share, so an installed nrslam_eval can run the shipped suites.
include(CMakePackageConfigHelpers)  # GNUInstallDirs is included before the library's folder

set(NRSLAM_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/nrslam)

install(TARGETS nrslam EXPORT nrslamTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/nrslam/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/nrslam
        FILES_MATCHING PATTERN "*.h")
# A shared build (-DBUILD_SHARED_LIBS=ON): the installed programs find libnrslam.so relative to
# themselves, wherever the prefix is.
if(BUILD_SHARED_LIBS)
  set_target_properties(${NRSLAM_TOOLS} PROPERTIES INSTALL_RPATH "$ORIGIN/../${CMAKE_INSTALL_LIBDIR}")
endif()
install(TARGETS ${NRSLAM_TOOLS} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/data_manifests DESTINATION ${CMAKE_INSTALL_DATADIR}/nrslam)
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs DESTINATION ${CMAKE_INSTALL_DOCDIR})

install(EXPORT nrslamTargets NAMESPACE nrslam:: DESTINATION ${NRSLAM_INSTALL_CMAKEDIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/nrslamConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/nrslamConfig.cmake
                              INSTALL_DESTINATION ${NRSLAM_INSTALL_CMAKEDIR}
                              PATH_VARS CMAKE_INSTALL_INCLUDEDIR)
# 0.x: a minor version may change the API, so only the same minor version is compatible.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/nrslamConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/nrslamConfig.cmake ${PROJECT_BINARY_DIR}/nrslamConfigVersion.cmake
        DESTINATION ${NRSLAM_INSTALL_CMAKEDIR})

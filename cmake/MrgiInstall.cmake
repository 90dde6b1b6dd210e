# `cmake --install`: what an app needs to build against mrgi and nothing more.
#   include/mrgi/*.h, include/mrgi/platform/*.h   the public API (runtime/include, platform/include,
#                                                 and the generated mrgi/version.h)
#   lib/libmrgi.so, lib/libmrgi_platform.so       the runtime (shaders compiled in) and the inputs
#   lib/cmake/mrgi/                               find_package(mrgi): targets mrgi::mrgi, mrgi::platform
#   lib/pkgconfig/mrgi.pc, mrgi-platform.pc       pkg-config mrgi
#   bin/mrgi                                      the command-line tool
# The shaders are SPIR-V arrays inside libmrgi (shaders/CMakeLists.txt): nothing else to ship.
# Internal headers (runtime/src, runtime/internal: nlohmann-based JSON reading) are not installed.
include(CMakePackageConfigHelpers)

set(MRGI_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/mrgi)
install(TARGETS mrgi mrgi_platform EXPORT mrgiTargets
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS mrgi_tool RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${CMAKE_SOURCE_DIR}/runtime/include/mrgi ${CMAKE_BINARY_DIR}/runtime/generated/include/mrgi
        ${CMAKE_SOURCE_DIR}/platform/include/mrgi
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} FILES_MATCHING PATTERN "*.h")
install(EXPORT mrgiTargets NAMESPACE mrgi:: DESTINATION ${MRGI_INSTALL_CMAKEDIR})
# The export names the libraries by their target names; the namespace makes them mrgi::mrgi
# and mrgi::mrgi_platform, and mrgiConfig.cmake adds mrgi::platform as the documented name.
configure_package_config_file(${CMAKE_SOURCE_DIR}/cmake/install/mrgiConfig.cmake.in
                              ${CMAKE_BINARY_DIR}/cmake/mrgiConfig.cmake
                              INSTALL_DESTINATION ${MRGI_INSTALL_CMAKEDIR})
write_basic_package_version_file(${CMAKE_BINARY_DIR}/cmake/mrgiConfigVersion.cmake
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/cmake/mrgiConfig.cmake ${CMAKE_BINARY_DIR}/cmake/mrgiConfigVersion.cmake
        DESTINATION ${MRGI_INSTALL_CMAKEDIR})
# Relative to the .pc file, so the prefix given to `cmake --install --prefix` is the one found.
file(RELATIVE_PATH MRGI_PC_TO_PREFIX /p/${CMAKE_INSTALL_LIBDIR}/pkgconfig /p)
foreach(pc mrgi mrgi-platform)
  configure_file(${CMAKE_SOURCE_DIR}/cmake/install/${pc}.pc.in ${CMAKE_BINARY_DIR}/pkgconfig/${pc}.pc @ONLY)
  install(FILES ${CMAKE_BINARY_DIR}/pkgconfig/${pc}.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endforeach()

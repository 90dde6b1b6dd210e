# `cmake --install`: what an app needs to build against mrgi and nothing more.
#   include/mrgi/*.h, include/mrgi/platform/*.h   the public API (runtime/include, platform/include,
#                                                 and the generated mrgi/version.h)
#   lib/libmrgi.so, lib/libmrgi_platform.so       the runtime (shaders compiled in) and the inputs,
#                                                 SONAME libmrgi.so.MAJOR.MINOR, without debug info
#   lib/debug/*.debug                             their debug info (and the tool's), found by gdb
#                                                 through each file's .gnu_debuglink
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
# Debug info split out of the installed binaries (a RelWithDebInfo libmrgi is 80 MB, 4 MB
# without): kept beside them under lib/debug/ and linked by .gnu_debuglink, so a crash in an app
# can still be read. MRGI_INSTALL_SPLIT_DEBUG=OFF installs the binaries as built.
option(MRGI_INSTALL_SPLIT_DEBUG "Install binaries without debug info, the debug info in lib/debug/" ON)
if(MRGI_INSTALL_SPLIT_DEBUG AND MRGI_SHARED_LIBS AND CMAKE_OBJCOPY AND CMAKE_STRIP)
  install(CODE "
    set(prefix \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}\")
    file(MAKE_DIRECTORY \"\${prefix}/${CMAKE_INSTALL_LIBDIR}/debug\")
    foreach(f \"${CMAKE_INSTALL_LIBDIR}/$<TARGET_FILE_NAME:mrgi>\" \"${CMAKE_INSTALL_LIBDIR}/$<TARGET_FILE_NAME:mrgi_platform>\"
              \"${CMAKE_INSTALL_BINDIR}/$<TARGET_FILE_NAME:mrgi_tool>\")
      get_filename_component(name \"\${f}\" NAME)
      set(debug \"\${prefix}/${CMAKE_INSTALL_LIBDIR}/debug/\${name}.debug\")
      execute_process(COMMAND \"${CMAKE_OBJCOPY}\" --only-keep-debug \"\${prefix}/\${f}\" \"\${debug}\"
                      COMMAND_ERROR_IS_FATAL ANY)
      execute_process(COMMAND \"${CMAKE_STRIP}\" --strip-debug \"\${prefix}/\${f}\" COMMAND_ERROR_IS_FATAL ANY)
      execute_process(COMMAND \"${CMAKE_OBJCOPY}\" --add-gnu-debuglink=\${debug} \"\${prefix}/\${f}\"
                      COMMAND_ERROR_IS_FATAL ANY)
      message(STATUS \"Split debug info: \${f} -> ${CMAKE_INSTALL_LIBDIR}/debug/\${name}.debug\")
    endforeach()
  ")
endif()
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

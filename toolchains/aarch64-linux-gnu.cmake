# Cross-compiling mrgi for aarch64 Linux tablets and HMDs from a Debian 12 host.
# The sysroot: scripts/make-aarch64-sysroot.sh assembles one from Debian's arm64 packages into
# build-aarch64-sysroot/ (the default here); MRGI_SYSROOT (environment) points at another one, a
# device image's root for instance. The cross compiler is Debian's g++-aarch64-linux-gnu.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
if(DEFINED ENV{MRGI_SYSROOT})
  set(_mrgi_sysroot "$ENV{MRGI_SYSROOT}")
else()
  get_filename_component(_mrgi_sysroot "${CMAKE_CURRENT_LIST_DIR}/../build-aarch64-sysroot" ABSOLUTE)
endif()
if(NOT EXISTS "${_mrgi_sysroot}/usr/include")
  message(FATAL_ERROR "mrgi: no aarch64 sysroot at ${_mrgi_sysroot}: run scripts/make-aarch64-sysroot.sh "
                      "(or set MRGI_SYSROOT to a device image's root)")
endif()
set(CMAKE_SYSROOT "${_mrgi_sysroot}")
set(CMAKE_FIND_ROOT_PATH "${_mrgi_sysroot}")
# Programs (glslangValidator compiles the shaders) are the host's; everything linked is the sysroot's.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
# pkg-config must read the sysroot's .pc files only and prefix their paths with the sysroot.
set(ENV{PKG_CONFIG_SYSROOT_DIR} "${_mrgi_sysroot}")
set(ENV{PKG_CONFIG_LIBDIR}
    "${_mrgi_sysroot}/usr/lib/aarch64-linux-gnu/pkgconfig:${_mrgi_sysroot}/usr/lib/pkgconfig:${_mrgi_sysroot}/usr/share/pkgconfig")
set(ENV{PKG_CONFIG_PATH} "")
# The libraries' own dependencies (libvulkan's, libOpenEXR's) are found in the sysroot at link time.
set(CMAKE_EXE_LINKER_FLAGS_INIT "-Wl,-rpath-link,${_mrgi_sysroot}/usr/lib/aarch64-linux-gnu")
set(CMAKE_SHARED_LINKER_FLAGS_INIT "-Wl,-rpath-link,${_mrgi_sysroot}/usr/lib/aarch64-linux-gnu")

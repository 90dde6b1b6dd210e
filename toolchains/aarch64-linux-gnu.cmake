# Cross-compiling mrgi for aarch64 Linux tablets and HMDs from a Debian host.
# Host set-up: apt-get install g++-aarch64-linux-gnu and the :arm64 -dev packages of
# scripts/install-deps.sh (dpkg --add-architecture arm64), or point CMAKE_SYSROOT at a device image.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
if(DEFINED ENV{MRGI_SYSROOT})
  set(CMAKE_SYSROOT $ENV{MRGI_SYSROOT})
endif()
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
set(ENV{PKG_CONFIG_LIBDIR} "/usr/lib/aarch64-linux-gnu/pkgconfig:/usr/share/pkgconfig")

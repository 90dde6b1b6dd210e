# Every dependency is a Debian 12 package installed by scripts/install-deps.sh.
# A missing one fails configuration with the package name to install.
find_package(Threads REQUIRED)
find_package(Vulkan REQUIRED)
find_package(PkgConfig REQUIRED)
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(TinyGLTF REQUIRED)
find_package(meshoptimizer REQUIRED)
# Debian's package exports TinyGLTF::TinyGLTF (a shared library that holds the implementation);
# the project links it under the upstream-style name.
if(TARGET TinyGLTF::TinyGLTF AND NOT TARGET tinygltf::tinygltf)
  add_library(tinygltf::tinygltf ALIAS TinyGLTF::TinyGLTF)
endif()
find_package(tinyexr REQUIRED)
# OpenEXR reads what tinyexr cannot decode (DWAA/DWAB compression, as in Blender's HDRI maps).
find_package(OpenEXR 3 REQUIRED)
find_package(embree 3 REQUIRED)
find_package(CLI11 QUIET)
find_package(PNG REQUIRED)
# glTF textures decode through libpng and libjpeg-turbo (image/texture_decode.h), not stb.
find_package(JPEG REQUIRED)
# SPIR-V reflection (gpu/reflect.h): a shader's GLSL declarations are the one source of its
# descriptor layout and of the names a pass binds by. The C API's shared library (Debian has no
# position-independent build of the C++ one).
find_package(spirv_cross_c_shared QUIET)
if(NOT TARGET spirv-cross-c-shared)
  message(FATAL_ERROR "mrgi: SPIRV-Cross not found: install Debian package libspirv-cross-c-shared-dev (scripts/install-deps.sh)")
endif()

find_program(GLSLANG_VALIDATOR glslangValidator REQUIRED)

function(mrgi_require_header header package)
  find_path(_mrgi_hdr_${package} ${header})
  if(NOT _mrgi_hdr_${package})
    message(FATAL_ERROR "mrgi: header ${header} not found: install Debian package ${package} (scripts/install-deps.sh)")
  endif()
endfunction()
mrgi_require_header(glm/glm.hpp libglm-dev)
mrgi_require_header(stb/stb_image.h libstb-dev)
mrgi_require_header(CLI/CLI.hpp libcli11-dev)

pkg_check_modules(APRILTAG REQUIRED IMPORTED_TARGET apriltag)
pkg_check_modules(LIBUSB REQUIRED IMPORTED_TARGET libusb-1.0)
pkg_check_modules(LIBV4L2 REQUIRED IMPORTED_TARGET libv4l2)
pkg_check_modules(LIBCAMERA REQUIRED IMPORTED_TARGET libcamera)
find_path(OPENNI2_INCLUDE_DIR OpenNI.h PATH_SUFFIXES openni2 OpenNI2)
find_library(OPENNI2_LIBRARY OpenNI2)
if(NOT OPENNI2_INCLUDE_DIR OR NOT OPENNI2_LIBRARY)
  message(FATAL_ERROR "mrgi: OpenNI2 not found: install Debian package libopenni2-dev")
endif()

if(NOT TARGET glm::glm)
  add_library(glm::glm INTERFACE IMPORTED)
  target_compile_definitions(glm::glm INTERFACE GLM_ENABLE_EXPERIMENTAL GLM_FORCE_DEPTH_ZERO_TO_ONE)
endif()

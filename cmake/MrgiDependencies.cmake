# Every dependency is a Debian 12 package installed by scripts/install-deps.sh.
# The runtime's (Vulkan, GLM and what libmrgi links itself) are required: a missing one fails
# configuration with the package name to install. The input adapters and the path tracer are
# optional (mrgi_optional below).
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

# Optional parts: MRGI_WITH_<NAME> is AUTO (on where the package is found, off with a message
# where not), ON (a missing package fails configuration) or OFF (left out). A left-out input
# adapter answers every call with an error naming its option and package
# (platform/src/absent/); `mrgi devices` lists what this build has.
function(mrgi_optional name package description)
  set(MRGI_WITH_${name} AUTO CACHE STRING "${description}: AUTO (where ${package} is found), ON or OFF")
  set_property(CACHE MRGI_WITH_${name} PROPERTY STRINGS AUTO ON OFF)
  set(found ${ARGN})
  if(MRGI_WITH_${name} STREQUAL "OFF")
    set(on OFF)
  elseif(found)
    set(on ON)
  elseif(MRGI_WITH_${name} STREQUAL "ON")
    message(FATAL_ERROR "mrgi: MRGI_WITH_${name}=ON but ${description} needs Debian package ${package}, not found")
  else()
    message(STATUS "mrgi: ${description} left out: ${package} not found (MRGI_WITH_${name}=AUTO)")
    set(on OFF)
  endif()
  set(MRGI_HAVE_${name} ${on} PARENT_SCOPE)
endfunction()
macro(mrgi_optional_pkg name module package description)
  if(NOT MRGI_WITH_${name} STREQUAL "OFF")
    pkg_check_modules(${name} QUIET IMPORTED_TARGET ${module})
  endif()
  mrgi_optional(${name} ${package} "${description}" ${${name}_FOUND})
endmacro()
mrgi_optional_pkg(APRILTAG apriltag libapriltag-dev "AprilTag marker tracking")
mrgi_optional_pkg(LIBUSB libusb-1.0 libusb-1.0-0-dev "USB sensor discovery")
mrgi_optional_pkg(V4L2 libv4l2 libv4l-dev "the V4L2 camera adapter")
mrgi_optional_pkg(LIBCAMERA libcamera libcamera-dev "the libcamera adapter")
set(_mrgi_openni2_found FALSE)
if(NOT MRGI_WITH_OPENNI2 STREQUAL "OFF")
  find_path(OPENNI2_INCLUDE_DIR OpenNI.h PATH_SUFFIXES openni2 OpenNI2)
  find_library(OPENNI2_LIBRARY OpenNI2)
  if(OPENNI2_INCLUDE_DIR AND OPENNI2_LIBRARY)
    set(_mrgi_openni2_found TRUE)
  endif()
endif()
mrgi_optional(OPENNI2 libopenni2-dev "the OpenNI2 adapter (Kinect, Xtion, .oni files)" ${_mrgi_openni2_found})
set(_mrgi_embree_found FALSE)
if(NOT MRGI_WITH_REFERENCE STREQUAL "OFF")
  find_package(embree 3 QUIET)
  set(_mrgi_embree_found ${embree_FOUND})
endif()
mrgi_optional(REFERENCE libembree-dev "the path-traced reference (mrgi synth)" ${_mrgi_embree_found})

if(NOT TARGET glm::glm)
  add_library(glm::glm INTERFACE IMPORTED)
  target_compile_definitions(glm::glm INTERFACE GLM_ENABLE_EXPERIMENTAL GLM_FORCE_DEPTH_ZERO_TO_ONE)
endif()

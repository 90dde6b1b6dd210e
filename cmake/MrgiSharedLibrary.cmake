# mrgi_shared_library_abi(TARGET): what an installed shared library of mrgi's carries.
# - VERSION and SOVERSION libNAME.so.MAJOR.MINOR: before 1.0 a minor version may change the ABI
#   (mrgiConfigVersion's SameMinorVersion says the same), so the SONAME carries both.
# - The version script cmake/hide-third-party.map: the third-party code built into it is not
#   exported, even where its headers ask for default visibility (mrgi's own code is compiled
#   hidden: mrgi_hidden_visibility below). GNU ld and lld; CMake 3.25 does not name the linker,
#   so an unnamed one is taken as GNU ld, Debian's default.
# Nothing for a static build.
function(mrgi_shared_library_abi target)
  if(NOT MRGI_SHARED_LIBS)
    return()
  endif()
  set_target_properties(${target} PROPERTIES VERSION ${PROJECT_VERSION}
                                             SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
  if(CMAKE_CXX_COMPILER_LINKER_ID MATCHES "GNU|LLD" OR NOT CMAKE_CXX_COMPILER_LINKER_ID)
    set(map ${PROJECT_SOURCE_DIR}/cmake/hide-third-party.map)
    target_link_options(${target} PRIVATE -Wl,--version-script=${map})
    # Every symbol resolved at link time: a function the library uses from libmrgi.so that
    # libmrgi.so does not export (hidden) fails the build here, not an app's link. Not in the
    # sanitizer and fuzz builds, whose runtimes are linked into the executables only.
    if(NOT MRGI_SANITIZE AND NOT MRGI_FUZZ)
      target_link_options(${target} PRIVATE -Wl,--no-undefined)
    endif()
    set_property(TARGET ${target} APPEND PROPERTY LINK_DEPENDS ${map})
  endif()
endfunction()

# mrgi_hidden_visibility(TARGET): compile TARGET's sources with hidden visibility, so only what
# mrgi/export.h's MRGI_API marks is exported from a shared library they are linked into (and
# the third-party code compiled into them, stb_image's functions say, is not). Position
# independent, for the same reason: the objects go into a shared library.
function(mrgi_hidden_visibility target)
  set_target_properties(${target} PROPERTIES CXX_VISIBILITY_PRESET hidden C_VISIBILITY_PRESET hidden
                                             VISIBILITY_INLINES_HIDDEN ON POSITION_INDEPENDENT_CODE ON)
endfunction()

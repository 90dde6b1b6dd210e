// What an input adapter left out of this build answers (CMake's MRGI_WITH_<ADAPTER>,
// cmake/MrgiDependencies.cmake): every entry point fails with ErrorKind::NotFound ("an adapter is absent") naming the
// adapter, the option and the package, so an app asking for it learns why instead of crashing.
#pragma once
#include <string>

#include "mrgi/expected.h"

namespace mrgi::platform_absent {

inline Error absent(const char* adapter, const char* option, const char* package) {
  return Error{ErrorKind::NotFound, std::string("this mrgi was built without the ") + adapter + " adapter (" + option +
                                           "=OFF at configure: " + package + " not found or switched off)"};
}

}  // namespace mrgi::platform_absent

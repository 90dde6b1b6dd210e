#include "mrgi/version.h"

namespace mrgi {

const char* version() { return MRGI_VERSION_STRING; }

Version version_numbers() { return {MRGI_VERSION_MAJOR, MRGI_VERSION_MINOR, MRGI_VERSION_PATCH}; }

}  // namespace mrgi

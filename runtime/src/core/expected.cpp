#include "mrgi/expected.h"

namespace mrgi {

const char* to_string(ErrorKind kind) {
  switch (kind) {
    case ErrorKind::BadInput: return "bad input";
    case ErrorKind::BadUsage: return "bad usage";
    case ErrorKind::NotFound: return "not found";
    case ErrorKind::Device: return "device error";
    case ErrorKind::Timeout: return "timeout";
    case ErrorKind::EndOfStream: return "end of stream";
    case ErrorKind::NotImplemented: return "not implemented";
    case ErrorKind::Internal: return "internal error";
  }
  return "unknown error";
}

}  // namespace mrgi

/// \file
/// Errors by kind, returned as values. C++20 has no std::expected, so mrgi carries a small one.
/// Every loader, adapter and factory returns Expected<T>; nothing is printed and ignored.
#pragma once
#include <cassert>
#include <string>
#include <utility>
#include <variant>

#include "mrgi/export.h"

namespace mrgi {

enum class ErrorKind {
  BadInput,     ///< a file or value breaks a documented rule (exit code 1 in the tool)
  BadUsage,     ///< wrong command-line use or settings out of range (exit code 2)
  NotFound,     ///< a file, device or adapter is absent
  Device,       ///< Vulkan or sensor failure at run time
  Timeout,      ///< a bounded wait ran out (sensor stopped sending)
  EndOfStream,  ///< a stream ended normally
  NotImplemented,
  Internal,
};

MRGI_API const char* to_string(ErrorKind kind);

struct Error {
  ErrorKind kind = ErrorKind::Internal;
  std::string message;  ///< names the file, the field or line, and the rule
};

/// Builds an Error; used as `return fail(ErrorKind::BadInput, path + ": ...")`.
inline Error fail(ErrorKind kind, std::string message) { return Error{kind, std::move(message)}; }

template <class T>
class [[nodiscard]] Expected {
 public:
  Expected(T value) : v_(std::move(value)) {}
  Expected(Error error) : v_(std::move(error)) {}
  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }
  T& value() & { assert(ok()); return std::get<0>(v_); }
  const T& value() const& { assert(ok()); return std::get<0>(v_); }
  T&& value() && { assert(ok()); return std::get<0>(std::move(v_)); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  const Error& error() const { assert(!ok()); return std::get<1>(v_); }

 private:
  std::variant<T, Error> v_;
};

/// Expected<void>: success or an Error.
struct Ok {};
using Status = Expected<Ok>;
inline Status ok_status() { return Ok{}; }

}  // namespace mrgi

/// Propagates an error from an expression returning Expected<...>/Status.
#define MRGI_TRY(expr)                                        \
  do {                                                        \
    auto&& mrgi_try_result_ = (expr);                         \
    if (!mrgi_try_result_.ok()) return mrgi_try_result_.error(); \
  } while (0)

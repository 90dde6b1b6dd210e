/// \file
/// MRGI_API marks what libmrgi.so and libmrgi_platform.so export: the public API declared in
/// the installed headers and nothing else. Both libraries are compiled with hidden visibility by
/// default (runtime/CMakeLists.txt), so their internal functions and the third-party code built
/// into them stay inside (tests/install/exported_symbols_test.sh lists what they export).
#pragma once

#if defined(__GNUC__) || defined(__clang__)
#define MRGI_API __attribute__((visibility("default")))
#else
#define MRGI_API
#endif

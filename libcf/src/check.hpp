#pragma once
// Checks that stay on in every build type (Release compiles `assert` out), after Drake's
// DRAKE_DEMAND / DRAKE_THROW_UNLESS:
//   CF_DEMAND(cond)            an internal invariant: failing is a bug in libcf, so it says
//                              where and aborts.
//   CF_REQUIRE(cond, message)  a precondition of the public API that a caller's argument can
//                              break (an id out of range): throws cf::Error(message); the
//                              message expression is evaluated only on failure.
// Both must stay cheap (a comparison or two); an expensive check is an `assert`.

#include <cf/types.hpp>

#include <cstdio>
#include <cstdlib>

namespace cf::internal {

[[noreturn]] inline void demand_failed(const char* condition, const char* file, int line) {
  std::fprintf(stderr, "libcf: internal check failed: %s at %s:%d\n", condition, file, line);
  std::abort();
}

}  // namespace cf::internal

#define CF_DEMAND(cond)                                                                         \
  do {                                                                                          \
    if (__builtin_expect(!(cond), 0)) ::cf::internal::demand_failed(#cond, __FILE__, __LINE__); \
  } while (false)

#define CF_REQUIRE(cond, message)                                 \
  do {                                                            \
    if (__builtin_expect(!(cond), 0)) throw ::cf::Error(message); \
  } while (false)

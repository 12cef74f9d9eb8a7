#pragma once
// Checks that throw (never abort) with the failed condition, a message, and file:line.
//
//   IHS_CHECK(index < size, "index " << index << " out of range");        // InternalError
//   IHS_CHECK_ARG(voxel_mm > 0, "voxel_mm must be positive, got " << v);  // std::invalid_argument
//
// The message is a stream expression, evaluated only when the check fails.

#include <sstream>
#include <string>

#include "core/errors.h"

namespace ihs::internal {

/// Throws InternalError describing a failed IHS_CHECK.
[[noreturn]] void ThrowCheckFailure(const char* file, int line, const char* condition,
                                    const std::string& message);
/// Throws std::invalid_argument describing a failed IHS_CHECK_ARG.
[[noreturn]] void ThrowArgumentFailure(const char* file, int line, const char* condition,
                                       const std::string& message);

}  // namespace ihs::internal

#define IHS_INTERNAL_CHECK_IMPL(thrower, condition, message)            \
  do {                                                                  \
    if (!(condition)) {                                                 \
      std::ostringstream ihs_check_stream_;                             \
      ihs_check_stream_ << message;                                     \
      thrower(__FILE__, __LINE__, #condition, ihs_check_stream_.str()); \
    }                                                                   \
  } while (false)

/// Throws ihs::InternalError when `condition` is false: for invariants of the program itself.
#define IHS_CHECK(condition, message) \
  IHS_INTERNAL_CHECK_IMPL(::ihs::internal::ThrowCheckFailure, condition, message)

/// Throws std::invalid_argument when `condition` is false: for options and arguments.
#define IHS_CHECK_ARG(condition, message) \
  IHS_INTERNAL_CHECK_IMPL(::ihs::internal::ThrowArgumentFailure, condition, message)

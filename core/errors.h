#pragma once
// Typed exceptions for bad input that a user can act on. The application maps each to one line on
// stderr and an exit code; bad options throw std::invalid_argument (see check.h).

#include <stdexcept>
#include <string>

namespace ihs {

/// An input (file, directory, recording) is missing, unreadable or malformed.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An output cannot be written (unwritable folder, full disk).
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A capture device is absent, not accessible, busy or failed during capture.
class DeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A broken internal invariant: a bug in the program, not in its input.
class InternalError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

}  // namespace ihs

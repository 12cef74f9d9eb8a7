#include "core/check.h"

#include <filesystem>
#include <stdexcept>

namespace ihs::internal {
namespace {

std::string Describe(const char* file, int line, const char* condition,
                     const std::string& message) {
  std::ostringstream text;
  if (message.empty()) {
    text << "check failed: " << condition;
  } else {
    text << message;
  }
  text << " [" << std::filesystem::path(file).filename().string() << ":" << line << ": "
       << condition << "]";
  return text.str();
}

}  // namespace

void ThrowCheckFailure(const char* file, int line, const char* condition,
                       const std::string& message) {
  throw InternalError(Describe(file, line, condition, message));
}

void ThrowArgumentFailure(const char* file, int line, const char* condition,
                          const std::string& message) {
  throw std::invalid_argument(Describe(file, line, condition, message));
}

}  // namespace ihs::internal

#include "core/exit_codes.h"

#include <cstdio>
#include <exception>
#include <stdexcept>

#include "core/errors.h"

namespace ihs {

std::string ExitCodesHelp() {
  return "Exit codes: 0 ok, 1 internal error, 2 bad usage or options, 3 input unreadable, "
         "4 device problem, 5 a stage failed (partial result saved), 6 output not writable.";
}

int RunReportingErrors(const std::string& program, const std::function<int()>& body) {
  auto report = [&](const char* what, int code) {
    std::fprintf(stderr, "%s: error: %s\n", program.c_str(), what);
    return code;
  };
  try {
    return body();
  } catch (const std::invalid_argument& error) {
    return report(error.what(), kExitUsage);
  } catch (const InputError& error) {
    return report(error.what(), kExitInput);
  } catch (const DeviceError& error) {
    return report(error.what(), kExitDevice);
  } catch (const OutputError& error) {
    return report(error.what(), kExitOutput);
  } catch (const std::exception& error) {
    return report(error.what(), kExitInternal);
  } catch (...) {
    return report("unknown exception", kExitInternal);
  }
}

}  // namespace ihs

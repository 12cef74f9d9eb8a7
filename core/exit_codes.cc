#include "core/exit_codes.h"

#include <cstdio>
#include <exception>
#include <filesystem>
#include <stdexcept>

#include "core/errors.h"

namespace ihs {

std::string ExitCodesHelp() {
  return "Exit codes: 0 ok, 1 internal error, 2 bad usage or options, 3 input unreadable, "
         "4 device problem, 5 a stage failed (partial result saved), 6 output not writable.";
}

std::string OneLine(const std::string& message) {
  // Runs of whitespace with a line break become "; ", other runs one space; none at the ends.
  // Other control bytes (a file header's escape sequences) become '?'.
  std::string line;
  bool pending_space = false, pending_break = false;
  for (const char ch : message) {
    const auto byte = static_cast<unsigned char>(ch);
    if (ch == '\n' || ch == '\r') {
      pending_break = true;
    } else if (ch == ' ' || ch == '\t') {
      pending_space = true;
    } else {
      if (!line.empty() && pending_break) {
        line += "; ";
      } else if (!line.empty() && pending_space) {
        line += ' ';
      }
      pending_space = pending_break = false;
      line += (byte < 0x20 || byte == 0x7f) ? '?' : ch;
    }
  }
  if (line.size() > kMaxLineBytes) {
    // Cut at a character boundary (not inside a UTF-8 sequence).
    std::size_t cut = kMaxLineBytes;
    while (cut > 0 && (static_cast<unsigned char>(line[cut]) & 0xC0) == 0x80) --cut;
    line = line.substr(0, cut) + " [" + std::to_string(line.size() - cut) + " more bytes]";
  }
  return line;
}

int RunReportingErrors(const std::string& program, const std::function<int()>& body) {
  auto report = [&](const char* what, int code) {
    std::fprintf(stderr, "%s: error: %s\n", program.c_str(), OneLine(what).c_str());
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
  } catch (const std::filesystem::filesystem_error& error) {
    // A path the program was given that the file system cannot resolve (a symlink loop, a
    // name too long, no permission), met before a reader could say so in its own words.
    return report(error.what(), kExitInput);
  } catch (const std::exception& error) {
    return report(error.what(), kExitInternal);
  } catch (...) {
    return report("unknown exception", kExitInternal);
  }
}

}  // namespace ihs

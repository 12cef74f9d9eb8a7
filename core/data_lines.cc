#include "core/data_lines.h"

#include <sstream>

#include "core/atomic_file.h"

namespace ihs {

std::vector<DataLine> ReadDataLines(const std::filesystem::path& path) {
  std::istringstream stream(ReadFileToString(path));
  std::vector<DataLine> lines;
  std::string text;
  int number = 0;
  while (std::getline(stream, text)) {
    ++number;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    const size_t first = text.find_first_not_of(" \t");
    if (first == std::string::npos || text[first] == '#') continue;
    lines.push_back({number, std::move(text)});
  }
  return lines;
}

std::vector<std::string> SplitFields(const std::string& text, char separator) {
  std::vector<std::string> fields(1);
  for (char c : text) {
    if (c == separator) {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

}  // namespace ihs

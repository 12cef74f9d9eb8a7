#include "app/option_registry.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "core/atomic_file.h"
#include "core/errors.h"

namespace ihs::app {
namespace {

std::string Trim(const std::string& text) {
  const auto begin = text.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  const auto end = text.find_last_not_of(" \t\r");
  return text.substr(begin, end - begin + 1);
}

// Shortest text that reads back as the same double.
std::string FormatDouble(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

// A number of the field's type; for floating point a finite one (no option means anything by
// nan or inf, and they pass every range check written as a comparison).
template <typename T>
bool ParseNumber(const std::string& text, T* value) {
  const std::string trimmed = Trim(text);
  if (trimmed.empty()) return false;
  const char* end = trimmed.data() + trimmed.size();
  T parsed{};
  const auto result = std::from_chars(trimmed.data(), end, parsed);
  if (result.ec != std::errc() || result.ptr != end) return false;
  if constexpr (std::is_floating_point_v<T>) {
    if (!std::isfinite(parsed)) return false;
  }
  *value = parsed;
  return true;
}

}  // namespace

void OptionRegistry::AddEntry(Entry entry) {
  for (const Entry& existing : entries_) {
    if (existing.name == entry.name)
      throw std::logic_error("option registered twice: " + entry.name);
  }
  entries_.push_back(std::move(entry));
}

void OptionRegistry::Add(const std::string& name, double* field, const std::string& help) {
  AddEntry({name, help, [field] { return FormatDouble(*field); },
            [field](const std::string& text) { return ParseNumber(text, field); }});
}

void OptionRegistry::Add(const std::string& name, int* field, const std::string& help) {
  AddEntry({name, help, [field] { return std::to_string(*field); },
            [field](const std::string& text) { return ParseNumber(text, field); }});
}

void OptionRegistry::Add(const std::string& name, std::uint32_t* field, const std::string& help) {
  AddEntry({name, help, [field] { return std::to_string(*field); },
            [field](const std::string& text) { return ParseNumber(text, field); }});
}

void OptionRegistry::Add(const std::string& name, bool* field, const std::string& help) {
  AddEntry({name, help, [field] { return std::string(*field ? "true" : "false"); },
            [field](const std::string& text) {
              const std::string value = Trim(text);
              if (value == "true" || value == "1" || value == "on" || value == "yes") {
                *field = true;
              } else if (value == "false" || value == "0" || value == "off" || value == "no") {
                *field = false;
              } else {
                return false;
              }
              return true;
            }});
}

void OptionRegistry::Add(const std::string& name, std::string* field, const std::string& help) {
  AddEntry({name, help, [field] { return *field; },
            [field](const std::string& text) {
              std::string value = Trim(text);
              if (value.size() >= 2 && value.front() == '"' && value.back() == '"') {
                value = value.substr(1, value.size() - 2);
              }
              *field = value;
              return true;
            }});
}

void OptionRegistry::Add(const std::string& name, Eigen::Vector3d* field, const std::string& help) {
  AddEntry({name, help,
            [field] {
              return FormatDouble(field->x()) + "," + FormatDouble(field->y()) + "," +
                     FormatDouble(field->z());
            },
            [field](const std::string& text) {
              std::vector<std::string> parts;
              std::stringstream stream(text);
              for (std::string part; std::getline(stream, part, ',');) parts.push_back(part);
              if (parts.size() != 3) return false;
              Eigen::Vector3d value;
              for (int i = 0; i < 3; ++i) {
                if (!ParseNumber(parts[i], &value[i])) return false;
              }
              *field = value;
              return true;
            }});
}

const OptionRegistry::Entry& OptionRegistry::Find(const std::string& name) const {
  for (const Entry& entry : entries_) {
    if (entry.name == name) return entry;
  }
  throw std::invalid_argument("unknown option '" + name + "' (inhandscan config lists them all)");
}

void OptionRegistry::Set(const std::string& name, const std::string& value) {
  const Entry& entry = Find(Trim(name));
  const std::string before = entry.get();
  if (!entry.set(value)) {
    entry.set(before);
    throw std::invalid_argument("option '" + entry.name + "': cannot read '" + Trim(value) +
                                "' (now " + before + ")");
  }
}

void OptionRegistry::SetAssignment(const std::string& assignment) {
  const auto equals = assignment.find('=');
  if (equals == std::string::npos) {
    throw std::invalid_argument("'" + assignment + "' is not NAME=VALUE");
  }
  Set(assignment.substr(0, equals), assignment.substr(equals + 1));
}

void OptionRegistry::Load(const std::filesystem::path& path) {
  LoadText(ReadFileToString(path, kMaxConfigBytes), path.string());
}

void OptionRegistry::LoadText(const std::string& text, const std::string& source) {
  std::istringstream file(text);
  std::string section;
  int line_number = 0;
  for (std::string line; std::getline(file, line);) {
    ++line_number;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    line = Trim(line);
    if (line.empty()) continue;
    const std::string where = source + ":" + std::to_string(line_number) + ": ";
    if (line.front() == '[') {
      if (line.back() != ']') throw std::invalid_argument(where + "unclosed section header");
      section = Trim(line.substr(1, line.size() - 2));
      continue;
    }
    const auto equals = line.find('=');
    if (equals == std::string::npos) throw std::invalid_argument(where + "expected NAME = VALUE");
    const std::string name = Trim(line.substr(0, equals));
    try {
      Set(section.empty() ? name : section + "." + name, line.substr(equals + 1));
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument(where + error.what());
    }
  }
}

std::string OptionRegistry::Describe() const {
  std::string text;
  for (const Entry& entry : entries_) {
    text += "# " + entry.help + "\n" + entry.name + " = " + entry.get() + "\n";
  }
  return text;
}

std::string OptionRegistry::Get(const std::string& name) const { return Find(name).get(); }

std::vector<std::string> OptionRegistry::Names() const {
  std::vector<std::string> names;
  for (const Entry& entry : entries_) names.push_back(entry.name);
  return names;
}

}  // namespace ihs::app

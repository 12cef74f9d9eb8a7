#pragma once
// Every option of every stage under one dotted name ("fusion.icp.max_distance_mm"), so that a
// config file, `--set NAME=VALUE` on the command line and `inhandscan config` all speak of the
// same fields. The registry points into an options struct; it owns nothing.

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace ihs::app {

/// Named, documented pointers into an options struct.
class OptionRegistry {
 public:
  /// Registers a field. `name` is dotted lower_snake_case and unique; `help` is one line.
  void Add(const std::string& name, double* field, const std::string& help);
  void Add(const std::string& name, int* field, const std::string& help);
  void Add(const std::string& name, std::uint32_t* field, const std::string& help);
  void Add(const std::string& name, bool* field, const std::string& help);
  void Add(const std::string& name, std::string* field, const std::string& help);
  /// A 3-vector, written "x,y,z".
  void Add(const std::string& name, Eigen::Vector3d* field, const std::string& help);

  /// Sets the field `name` from text. Throws std::invalid_argument naming the option when the
  /// name is unknown or the value does not parse as the field's type (floating point: a finite
  /// number; nan and inf are refused). Ranges are the options structs' Check().
  void Set(const std::string& name, const std::string& value);
  /// Sets from "NAME=VALUE".
  void SetAssignment(const std::string& assignment);

  /// Reads a config file: `name = value` lines, `#` comments, blank lines, and `[section]`
  /// headers that prefix the names below them with "section.". Throws ihs::InputError when the
  /// file cannot be read, is not a regular file (a folder, a FIFO, /dev/zero) or is larger than
  /// `kMaxConfigBytes`; std::invalid_argument (with file and line) for a bad line.
  static constexpr std::uintmax_t kMaxConfigBytes = 1 << 20;
  void Load(const std::filesystem::path& path);
  /// The same for the text of a config file; `source` names it in error messages.
  void LoadText(const std::string& text, const std::string& source);

  /// Every option with its current value and help, as a config file that Load reads back.
  std::string Describe() const;

  /// The current value of `name` as text; throws std::invalid_argument when unknown.
  std::string Get(const std::string& name) const;
  /// Names in registration order.
  std::vector<std::string> Names() const;

 private:
  struct Entry {
    std::string name;
    std::string help;
    std::function<std::string()> get;
    std::function<bool(const std::string&)> set;  // False: the text does not parse.
  };
  void AddEntry(Entry entry);
  const Entry& Find(const std::string& name) const;

  std::vector<Entry> entries_;
};

}  // namespace ihs::app

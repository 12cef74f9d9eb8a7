#pragma once
// Reading small line-oriented text files (lists, trajectories, profiles): the meaningful lines
// with their numbers, for parsers that report "file: line N: ..." errors.

#include <filesystem>
#include <string>
#include <vector>

namespace ihs {

/// One line of a text file that holds data.
struct DataLine {
  /// 1-based line number in the file.
  int number = 0;
  /// The line without its line end (LF or CRLF).
  std::string text;
};

/// The lines of `path` that are neither blank nor comments ('#' as first non-blank character).
/// Throws ihs::InputError naming the path when it cannot be read.
std::vector<DataLine> ReadDataLines(const std::filesystem::path& path);

/// The fields of `text` between `separator`s ("a,,b" gives "a", "", "b"; "" gives one empty field).
std::vector<std::string> SplitFields(const std::string& text, char separator = ',');

}  // namespace ihs

// libFuzzer target for the TUM RGB-D folder reader (sensor/tum_directory.h): the input is split
// at its first two NUL bytes into depth.txt, rgb.txt and associations.txt (absent when there is
// no third part) of a folder in /dev/shm, which is then listed and read (the images it names do
// not exist or are the folder's own lists: each frame must be skipped and counted). The only
// failure it may report is ihs::InputError.

#include <unistd.h>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/errors.h"
#include "sensor/tum_directory.h"

namespace {

std::filesystem::path Folder() {
  static const std::filesystem::path folder = [] {
    const std::filesystem::path base =
        std::filesystem::exists("/dev/shm") ? "/dev/shm" : std::filesystem::temp_directory_path();
    const auto path = base / ("ihs-tum-fuzz-" + std::to_string(getpid()));
    std::filesystem::create_directories(path);
    return path;
  }();
  return folder;
}

void Write(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  const auto first = input.find('\0');
  const auto second = first == std::string::npos ? first : input.find('\0', first + 1);
  const std::filesystem::path folder = Folder();
  Write(folder / "depth.txt", input.substr(0, first));
  Write(folder / "rgb.txt",
        first == std::string::npos ? "" : input.substr(first + 1, second - first - 1));
  std::filesystem::remove(folder / "associations.txt");
  if (second != std::string::npos) Write(folder / "associations.txt", input.substr(second + 1));
  try {
    ihs::sensor::TumDirectorySource source(folder);
    source.Start();
    for (int i = 0; i < 64; ++i) {
      if (source.Next(std::chrono::milliseconds(0)).status != ihs::sensor::SourceStatus::kFrame)
        break;
    }
  } catch (const ihs::InputError&) {
    // The one failure the reader may report.
  }
  return 0;
}

#pragma once
// Helpers shared by the test binaries.

#include <cstdint>
#include <filesystem>
#include <random>
#include <string>

namespace ihs::test {

/// The seed of this test run: IHS_TEST_SEED if set, else a fixed value. The shared main seeds
/// std::srand with it and prints it, so a failure can be reproduced.
std::uint32_t Seed();

/// A random generator seeded from Seed() and `stream`, so that tests draw independent sequences.
std::mt19937 Rng(std::uint32_t stream = 0);

/// A fresh empty folder under the system temp folder, removed with its contents on destruction.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  /// `path() / name`.
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

/// The shared data folder (`../shared/data` beside the checkout, or $IHS_SHARED_DIR/data), or
/// an empty path when it is absent: tests that need it then GTEST_SKIP with that reason.
std::filesystem::path SharedDataDir();

/// The real Kinect v1 recording in the shared data, or an empty path when it is absent.
std::filesystem::path KinectRecording();

/// The real hand data (shared/data/hand-iccv15), or an empty path when it is absent.
std::filesystem::path HandDataDir();

/// The result of running a shell command.
struct CommandResult {
  int exit_code = -1;
  std::string out;  ///< Standard output.
  std::string err;  ///< Standard error.
};

/// Runs `command` with /bin/sh, capturing stdout and stderr separately.
CommandResult RunCommand(const std::string& command);

/// Reads a whole file; empty if it cannot be read.
std::string ReadFileString(const std::filesystem::path& path);

/// An Xvfb server on a free display of `width`×`height` pixels for the object's lifetime (for
/// tests of windows). Not ok() when Xvfb is missing or fails to start.
class VirtualDisplay {
 public:
  VirtualDisplay(int width, int height);
  ~VirtualDisplay();
  VirtualDisplay(const VirtualDisplay&) = delete;
  VirtualDisplay& operator=(const VirtualDisplay&) = delete;
  bool ok() const { return pid_ > 0; }
  /// The display's name for $DISPLAY (":71").
  const std::string& name() const { return name_; }

 private:
  void Stop();
  std::string name_;
  int pid_ = -1;
};

/// Writes `bytes` to `path` (plain, non-atomic), for preparing test inputs.
void WriteBytes(const std::filesystem::path& path, const std::string& bytes);

}  // namespace ihs::test

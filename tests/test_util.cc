#include "tests/test_util.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <thread>

namespace ihs::test {

std::uint32_t Seed() {
  static const std::uint32_t seed = [] {
    const char* text = std::getenv("IHS_TEST_SEED");
    return text ? static_cast<std::uint32_t>(std::strtoul(text, nullptr, 10)) : 20151213u;
  }();
  return seed;
}

std::mt19937 Rng(std::uint32_t stream) {
  std::seed_seq sequence{Seed(), stream};
  return std::mt19937(sequence);
}

TempDir::TempDir() {
  static std::atomic<int> counter{0};
  path_ = std::filesystem::temp_directory_path() /
          ("ihs-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  std::filesystem::remove_all(path_);
  std::filesystem::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::filesystem::path SharedDataDir() {
  const char* shared = std::getenv("IHS_SHARED_DIR");
  std::filesystem::path data = shared ? std::filesystem::path(shared) / "data" : "";
  std::error_code ec;
  if (data.empty() || !std::filesystem::is_directory(data, ec)) return {};
  return std::filesystem::canonical(data, ec);
}

std::filesystem::path KinectRecording() {
  const std::filesystem::path data = SharedDataDir();
  return data.empty() ? data : data / "oni" / "kinect1-room-12frames.oni";
}

std::filesystem::path HandDataDir() {
  const std::filesystem::path data = SharedDataDir();
  return data.empty() ? data : data / "hand-iccv15";
}

CommandResult RunCommand(const std::string& command) {
  const TempDir dir;
  const std::string full = command + " 2>'" + (dir / "stderr").string() + "'";
  CommandResult result;
  FILE* pipe = popen(full.c_str(), "r");
  if (!pipe) return result;
  char buffer[4096];
  while (size_t n = fread(buffer, 1, sizeof(buffer), pipe)) result.out.append(buffer, n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.err = ReadFileString(dir / "stderr");
  return result;
}

std::string ReadFileString(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void WriteBytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("cannot write test file " + path.string());
}

VirtualDisplay::VirtualDisplay(int width, int height) {
  const std::string screen = std::to_string(width) + "x" + std::to_string(height) + "x24";
  for (int display = 70 + getpid() % 100; display < 300 && pid_ <= 0; ++display) {
    const std::string socket = "/tmp/.X11-unix/X" + std::to_string(display);
    if (std::filesystem::exists(socket)) continue;
    name_ = ":" + std::to_string(display);
    pid_ = fork();
    if (pid_ == 0) {
      execlp("Xvfb", "Xvfb", name_.c_str(), "-screen", "0", screen.c_str(), "-nolisten", "tcp",
             static_cast<char*>(nullptr));
      _exit(127);
    }
    // Xvfb makes its socket when it is ready to serve.
    for (int i = 0; i < 100 && !std::filesystem::exists(socket); ++i) {
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {  // Xvfb is missing or failed.
        pid_ = -1;
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    if (!std::filesystem::exists(socket)) Stop();
  }
}

VirtualDisplay::~VirtualDisplay() { Stop(); }

void VirtualDisplay::Stop() {
  if (pid_ <= 0) return;
  kill(pid_, SIGTERM);
  waitpid(pid_, nullptr, 0);
  pid_ = -1;
}

}  // namespace ihs::test

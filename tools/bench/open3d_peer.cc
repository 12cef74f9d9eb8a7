#include "tools/bench/open3d_peer.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/mesh_io.h"
#include "core/trajectory_io.h"
#include "sensor/open_input.h"
#include "tools/evaluation.h"

extern char** environ;

namespace ihs::bench {
namespace {

namespace fs = std::filesystem;

// The last non-empty line of the peer's log, for the reason it failed.
std::string LastLine(const fs::path& log) {
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  }
  return last.empty() ? "(nothing in " + log.string() + ")" : last;
}

// Starts the peer with its output in `log`; returns its pid.
pid_t Spawn(const Open3dPeerJob& job, const fs::path& log) {
  const std::vector<std::string> args = {
      job.program.string(), "--open3d-peer",       Open3dMethodName(job.tracking),
      "--peer-case",        job.case_dir.string(), "--peer-out",
      job.out_dir.string()};
  std::vector<char*> argv;
  for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = 0;
  const int error = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (error != 0) {
    throw std::runtime_error(Open3dMethodName(job.tracking) + ": cannot start " + args[0] + ": " +
                             std::strerror(error));
  }
  return pid;
}

// Waits for the peer; throws when it did not exit with 0.
void Wait(const Open3dPeerJob& job, pid_t pid, const fs::path& log) {
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      throw std::runtime_error(Open3dMethodName(job.tracking) +
                               ": lost its process: " + std::strerror(errno));
    }
  }
  const std::string name = Open3dMethodName(job.tracking);
  if (WIFSIGNALED(status)) {
    const int signal = WTERMSIG(status);
    throw std::runtime_error(name + " died of signal " + std::to_string(signal) + " (" +
                             strsignal(signal) + "): " + LastLine(log));
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    throw std::runtime_error(name + " failed (exit status " + std::to_string(WEXITSTATUS(status)) +
                             "): " + LastLine(log));
  }
}

}  // namespace

Open3dTracking Open3dTrackingNamed(const std::string& name) {
  for (Open3dTracking tracking : {Open3dTracking::kFrameToFrame, Open3dTracking::kFrameToModel}) {
    if (Open3dMethodName(tracking) == name) return tracking;
  }
  throw std::invalid_argument("no Open3D baseline is called " + name + " (open3d, open3d-f2m)");
}

Open3dBaselineResult RunOpen3dPeer(const Open3dPeerJob& job) {
  fs::remove_all(job.out_dir);
  fs::create_directories(job.out_dir);
  const fs::path log = job.out_dir / "peer.log";
  Wait(job, Spawn(job, log), log);
  const std::string name = Open3dMethodName(job.tracking);
  const nlohmann::json stats =
      nlohmann::json::parse(ReadFileToString(job.out_dir / "peer.json"), nullptr, false);
  if (stats.is_discarded() || !stats.is_object())
    throw std::runtime_error(name + ": its peer.json is not readable");
  Open3dBaselineResult result;
  try {
    result.frames = stats.at("frames").get<int>();
    result.odometry_failures = stats.at("odometry_failures").get<int>();
    result.empty_frames = stats.at("empty_frames").get<int>();
    result.odometry_ms = stats.at("odometry_ms").get<double>();
    result.integrate_ms = stats.at("integrate_ms").get<double>();
    result.raycast_ms = stats.at("raycast_ms").get<double>();
  } catch (const nlohmann::json::exception& error) {
    throw std::runtime_error(name + ": peer.json: " + error.what());
  }
  result.trajectory = ReadTumTrajectory(job.out_dir / "trajectory.txt");
  result.raw = ReadMesh(job.out_dir / "raw.ply");
  return result;
}

void RunOpen3dPeerJob(const Open3dPeerJob& job) {
  std::unique_ptr<sensor::FrameSource> source =
      sensor::OpenInput((job.case_dir / "sequence.oni").string());
  source->Start();
  Open3dBaselineOptions options;
  options.tracking = job.tracking;
  Open3dBaseline baseline(source->Intrinsics(), options);
  const fs::path gt_dir = job.case_dir / "gt";
  for (;;) {
    const sensor::SourceRead read = source->Next(std::chrono::seconds(5));
    if (read.status == sensor::SourceStatus::kTimeout) continue;
    if (read.status != sensor::SourceStatus::kFrame) break;
    const Frame& frame = *read.frame;
    std::vector<std::uint8_t> keep =
        eval::TruthObjectPixels(gt_dir, frame.index, frame.width, frame.height);
    // Without labels the baseline gets no object pixels.
    if (keep.empty()) keep.assign(frame.PixelCount(), 0);
    baseline.Process(frame, keep);
  }
  const Open3dBaselineResult result = baseline.Finish();
  fs::create_directories(job.out_dir);
  WriteMesh(job.out_dir / "raw.ply", result.raw);
  WriteTumTrajectory(job.out_dir / "trajectory.txt", result.trajectory,
                     {"cam_from_object of " + Open3dMethodName(job.tracking) + ", mm"});
  const nlohmann::json stats = {{"frames", result.frames},
                                {"odometry_failures", result.odometry_failures},
                                {"empty_frames", result.empty_frames},
                                {"odometry_ms", result.odometry_ms},
                                {"integrate_ms", result.integrate_ms},
                                {"raycast_ms", result.raycast_ms}};
  // Last: the parent takes a peer.json as the sign that the rest was written.
  WriteFileAtomically(job.out_dir / "peer.json", stats.dump(2));
}

}  // namespace ihs::bench

#pragma once
// Open3D's baselines in a process of their own. Open3D aborts the whole process on an internal
// error (the frame-to-model peer's VoxelBlockGrid::ExtractTriangleMesh once did at the end of
// the whole recorded sphere session: "GetVoxelAt returns nullptr"), and that took the benchmark
// and every case after it down. Run in a child process, such an abort is one failed cell of
// the report, with its reason. The child is a fresh program started with exec (Open3D's OpenMP
// thread pool does not survive a fork): the benchmark runs itself with `--open3d-peer`.

#include <filesystem>

#include "tools/bench/open3d_baseline.h"

namespace ihs::bench {

/// What the parent asks of its peer process.
struct Open3dPeerJob {
  /// The program to run: it must do RunOpen3dPeerJob when called as
  /// `PROGRAM --open3d-peer NAME --peer-case CASE_DIR --peer-out OUT_DIR` (inhandscan-bench).
  std::filesystem::path program;
  /// The case's folder: sequence.oni and gt/ (the truth's object labels keep the object's
  /// pixels, as for the baselines in process).
  std::filesystem::path case_dir;
  Open3dTracking tracking = Open3dTracking::kFrameToFrame;
  /// Where the peer writes raw.ply, trajectory.txt, peer.json and its log (peer.log); emptied
  /// first.
  std::filesystem::path out_dir;
};

/// Parent side: runs `job.program` as the peer, waits for it and reads what it wrote. Throws
/// std::runtime_error naming the method and why when the peer died of a signal (e.g. "open3d-f2m
/// died of signal 6 (Aborted): <its log's last line>"), exited with an error or wrote nothing
/// readable.
Open3dBaselineResult RunOpen3dPeer(const Open3dPeerJob& job);

/// Child side: every frame of `job.case_dir`/sequence.oni through the Open3D baseline with the
/// truth's object pixels, then the results into `job.out_dir` (`job.program` is not used).
void RunOpen3dPeerJob(const Open3dPeerJob& job);

/// The tracking a method name (Open3dMethodName) stands for; throws std::invalid_argument for
/// another name.
Open3dTracking Open3dTrackingNamed(const std::string& name);

}  // namespace ihs::bench

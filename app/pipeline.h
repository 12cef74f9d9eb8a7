#pragma once
// The threaded scanner. Pipeline owns the frame source, the stage objects, the bounded SPSC
// queues between them and the threads:
//
//   capture thread ─queue─► tracker thread (HandStage) ─queue─► fusion thread (ObjectStage)
//                                                                   │ snapshots
//                                                                   ▼
//                                                  export thread (meshes, files, previews)
//
// Live sources (a device, or a recording paced in real time) never block the capture thread:
// when the tracker falls behind, frames are dropped and counted before it (it always takes the
// newest), and the fusion thread gets every tracked frame, one at a time. Recordings replayed as
// fast as possible block instead, so two replays give identical results. Exports in mid-scan are
// requests to the fusion thread, answered with a snapshot of the model that the export thread
// meshes while the scan goes on. Stop (or the end of the input) lets every thread finish the
// frames in hand; a failing thread stores its error and stops the others, and the model so far
// is still exported.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "app/model_view.h"
#include "app/preview.h"
#include "app/run_record.h"
#include "app/scan_record.h"
#include "app/scanner_options.h"
#include "core/latest_value.h"
#include "sensor/frame_source.h"
#include "tracker/hand_pose.h"

namespace ihs::app {

/// Where and what a pipeline writes besides the stages' options.
struct PipelineOutput {
  /// Output folder (created if missing).
  std::filesystem::path folder;
  /// Extra formats of the watertight mesh: "obj", "stl".
  std::vector<std::string> extra_formats;
  /// How trajectory.txt is written.
  TrajectoryFormat trajectory_format = TrajectoryFormat::kCamFromObjectMm;
  /// Publish a LiveView for a window or a screenshot (costs a raycast of the model every few
  /// frames).
  bool live_view = false;
};

/// Counters for progress displays; a consistent-enough snapshot of atomics.
struct PipelineProgress {
  std::int64_t captured = 0;          ///< Frames read from the source.
  std::int64_t processed = 0;         ///< Frames through both stages.
  std::int64_t registered = 0;        ///< Frames fused into the model.
  std::int64_t dropped = 0;           ///< Frames dropped because a stage was behind (live only).
  std::int64_t exports = 0;           ///< Exports written (in mid-scan and final).
  std::optional<std::int64_t> total;  ///< Frames in the recording, when known.
  double seconds = 0;                 ///< Since Start().
  double processing_seconds = 0;      ///< From Start() to the last frame through both stages.
  std::string hand = "waiting";       ///< The hand's state for a person: FramePacket::HandState().
  std::string object = "waiting";  ///< The object's state for a person: FramePacket::ObjectState().
  double coverage = 0;                ///< Share of the directions around the object seen.

  /// Frames through both stages per second of processing.
  double FramesPerSecond() const {
    return processing_seconds > 0 ? processed / processing_seconds : 0.0;
  }
};

/// What the live window shows: the latest frame with the hand and the model, fitted to the
/// panel and turned as the user asked (SetModelViewpoint).
struct LiveView {
  std::shared_ptr<const Frame> frame;
  /// Hand joints (camera frame, mm) and contact points of the frame.
  std::vector<Eigen::Vector3d> joints_mm;
  /// For each joint, the joint it is drawn connected to (-1: none).
  std::vector<int> joint_parents;
  std::vector<Eigen::Vector3d> contacts_mm;
  /// The model raycast from the viewpoint (ViewModelFitted), frame-sized; black before the
  /// model starts.
  RgbImage model;
  ModelViewpoint viewpoint;
};

/// How a pipeline ended.
struct PipelineResult {
  /// ihs::ExitCode: 0, or what failed (3 input, 4 device, 5 a stage, 6 output).
  int exit_code = 0;
  /// One line saying what went wrong (empty when nothing did).
  std::string error;
  /// Why the input ended ("end of stream", "stopped", a device's disconnect message).
  std::string end_reason;
  /// The files of the final export (empty when nothing could be meshed).
  std::vector<std::filesystem::path> files;
  PipelineProgress progress;
};

/// Runs a scan on its own threads. Start() once, then Wait()/RequestExport()/RequestStop() from
/// the controlling thread, then Finish(). The destructor stops and joins whatever still runs.
class Pipeline {
 public:
  /// Takes the source (not yet started). Throws std::invalid_argument for bad options.
  Pipeline(std::unique_ptr<sensor::FrameSource> source, ScannerOptions options,
           PipelineOutput output);
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  /// Starts the source and the threads. The source's errors (ihs::DeviceError, InputError) and
  /// an unusable output folder (OutputError) are thrown from here, before any thread runs; an
  /// output folder made for this scan is then removed (no empty folder is left behind).
  /// `initial_hand_pose` starts the tracker from a known pose (benchmark mode).
  void Start(const std::optional<tracker::HandPose>& initial_hand_pose = std::nullopt);
  /// Asks for an export of the model so far; the scan goes on. Safe from any thread.
  void RequestExport() { export_requested_.store(true); }
  /// Asks the pipeline to stop reading: the frames in hand are finished, then the final export
  /// runs. Safe from any thread.
  void RequestStop() { stop_requested_.store(true); }
  /// Asks for the model to be discarded and the scan to start anew ('r' in the live window).
  void RequestReset() { reset_requested_.store(true); }
  /// For a stop whose frames in hand do not finish (a source read or a stage that does not
  /// return): the fusion thread stops waiting for them and the final export saves the model
  /// so far without them. The stuck thread still runs; Finish() would wait for it, so a program
  /// that cannot wait exits after WaitForFinalExport(). Safe from any thread.
  void Abandon() { abandon_requested_.store(true); }
  /// Waits up to `timeout` for the final export to be done (written, or failed); true when it is.
  bool WaitForFinalExport(std::chrono::milliseconds timeout);
  /// Waits up to `timeout` for every thread to finish; true when they have.
  bool Wait(std::chrono::milliseconds timeout);
  /// Joins the threads (stopping them if asked to) and says how the scan ended.
  PipelineResult Finish();

  PipelineProgress Progress() const;
  /// The source's intrinsics (valid after Start()).
  CameraIntrinsics intrinsics() const;
  /// The newest LiveView, if one was published since the last call.
  std::optional<LiveView> TakeLiveView() { return live_view_.Take(); }
  /// Turns the LiveView's model from the camera's view (from the next view published on).
  /// Safe from any thread.
  void SetModelViewpoint(const ModelViewpoint& viewpoint);

 private:
  struct Shared;
  void CaptureLoop();
  void TrackerLoop();
  void FusionLoop();
  void ExportLoop();
  // Records `error` of `stage` (the first one wins) and asks every thread to stop.
  void Fail(const std::string& stage, std::exception_ptr error);
  // Every thread's last act: counts it out and wakes Wait().
  void ThreadDone();
  // Start's steps before the threads: the source, the hand stage, the run record. Throws as
  // Start does; Start then removes an output folder it made.
  void StartStages(const std::optional<tracker::HandPose>& initial_hand_pose);

  std::unique_ptr<sensor::FrameSource> source_;
  const ScannerOptions options_;
  const PipelineOutput output_;
  RunRecord run_record_;  // Set in Start(), before any thread; options.conf and stats.json's "run".
  std::unique_ptr<Shared> shared_;
  std::atomic<bool> export_requested_{false};
  std::atomic<bool> stop_requested_{false};
  std::atomic<bool> reset_requested_{false};
  std::atomic<bool> abandon_requested_{false};
  LatestValue<LiveView> live_view_;
  std::atomic<double> view_yaw_deg_{0}, view_pitch_deg_{0};  // SetModelViewpoint's.
  std::vector<std::thread> threads_;
  bool started_ = false;
  bool finished_ = false;
};

}  // namespace ihs::app

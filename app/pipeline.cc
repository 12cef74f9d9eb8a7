#include "app/pipeline.h"

#include <spdlog/spdlog.h>
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "app/scan_export.h"
#include "app/scan_record.h"
#include "app/scan_stages.h"
#include "core/errors.h"
#include "core/exit_codes.h"
#include "core/spsc_queue.h"
#include "core/stopwatch.h"

namespace ihs::app {
namespace {

// An export whose watertight mesh is more than this share made up (never seen) warns the user:
// the volume of a sphere seen in half moves by 20 % and more with Poisson's settings alone.
constexpr double kUnseenShareWarning = 0.2;
// An export warns when the frames saw the object from fewer of the directions around it.
constexpr double kCoverageWarning = 0.8;

using PacketPtr = std::unique_ptr<FramePacket>;

// A snapshot for the export thread: a preview or a mesh export.
struct ExportJob {
  enum class Kind { kPreview, kExport, kFinal } kind = Kind::kExport;
  fusion::ModelSnapshot model;  // Exports: raw marching cubes and free space, object frame.
  // Previews: what the camera saw, the model seen from the camera, and the posed hand.
  std::shared_ptr<const Frame> frame;
  ModelView model_view;
  std::shared_ptr<const TriangleMesh> hand;
  // Exports: the scan's log so far.
  std::shared_ptr<const ScanRecord> record;
};
using JobPtr = std::unique_ptr<ExportJob>;

// The process's peak resident memory so far, MiB.
double PeakResidentMiB() {
  rusage usage = {};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // ru_maxrss is in KiB on Linux.
}

int ExitCodeOf(const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const InputError&) {
    return kExitInput;
  } catch (const DeviceError&) {
    return kExitDevice;
  } catch (const OutputError&) {
    return kExitOutput;
  } catch (...) {
    return kExitStageFailed;
  }
}

std::string MessageOf(const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const std::exception& e) {
    return e.what();
  } catch (...) {
    return "unknown error";
  }
}

}  // namespace

struct Pipeline::Shared {
  // Live, the tracker hands the fusion thread one frame at a time: frames wait (and are
  // dropped) before the tracker, where a dropped frame costs nothing but itself; after it, a
  // dropped frame would leave the next one's contact pairs pointing at a frame the fusion never
  // saw.
  Shared(std::size_t capacity, bool live)
      : frames(capacity), tracked(live ? 1 : capacity), jobs(2), live(live) {}

  SpscQueue<PacketPtr> frames;   // capture → tracker
  SpscQueue<PacketPtr> tracked;  // tracker → fusion
  SpscQueue<JobPtr> jobs;        // fusion → export
  CameraIntrinsics intrinsics;
  std::unique_ptr<HandStage> hand;
  std::vector<std::string> bone_names, angle_names;  // The hand stage's, for ScanRecord.
  std::vector<int> joint_parents;  // Joint j+1 ends bone j, which starts where its parent ends.
  std::chrono::steady_clock::time_point start;
  const bool live;

  std::atomic<std::int64_t> captured{0}, processed{0}, registered{0}, exports{0};
  std::atomic<double> processing_seconds{0};  // From Start() to the last frame fused.
  std::atomic<double> coverage{0};            // fusion::FusionResult::coverage of the last frame.
  // Live drops: frames the capture queue had no room for, and queued frames the tracker passed
  // over for a newer one.
  std::atomic<std::int64_t> dropped_capture{0}, dropped_stale{0}, previews_skipped{0};
  mutable std::mutex mutex;  // Guards what follows.
  std::condition_variable done;
  std::string hand_state = "waiting", object_state = "waiting";  // FramePacket's, the last.
  std::string end_reason;
  std::string nothing_scanned;  // ScanRecord::NothingScanned() when the scan ends.
  std::string failed_stage;
  std::exception_ptr failure;
  std::vector<std::filesystem::path> final_files;
  bool export_done = false;  // The export thread has ended (the final export written or failed).
  int running = 0;           // Threads still running.
};

Pipeline::Pipeline(std::unique_ptr<sensor::FrameSource> source, ScannerOptions options,
                   PipelineOutput output)
    : source_(std::move(source)), options_(std::move(options)), output_(std::move(output)) {
  options_.Check();
  if (!source_) throw std::invalid_argument("Pipeline: no frame source");
}

Pipeline::~Pipeline() {
  if (started_ && !finished_) {
    RequestStop();
    for (std::thread& thread : threads_) {
      if (thread.joinable()) thread.join();
    }
  }
  if (source_) source_->Stop();
}

void Pipeline::Start(const std::optional<tracker::HandPose>& initial_hand_pose) {
  if (started_) throw std::logic_error("Pipeline::Start called twice");
  std::error_code error;
  const bool made_folder = !std::filesystem::exists(output_.folder, error);
  std::filesystem::create_directories(output_.folder, error);
  if (error || !std::filesystem::is_directory(output_.folder)) {
    throw OutputError(output_.folder.string() + ": cannot create the output folder" +
                      (error ? " (" + error.message() + ")" : ""));
  }
  try {
    StartStages(initial_hand_pose);
  } catch (...) {
    // Nothing was scanned: a folder made for this scan goes again (with its empty preview/).
    if (made_folder) std::filesystem::remove_all(output_.folder, error);
    throw;
  }
  shared_->start = SteadyClock::now();
  started_ = true;
  shared_->running = 4;
  threads_.emplace_back([this] { CaptureLoop(); });
  threads_.emplace_back([this] { TrackerLoop(); });
  threads_.emplace_back([this] { FusionLoop(); });
  threads_.emplace_back([this] { ExportLoop(); });
}

void Pipeline::StartStages(const std::optional<tracker::HandPose>& initial_hand_pose) {
  std::error_code error;
  source_->Start();
  if (options_.pipeline.preview_every > 0) {
    std::filesystem::create_directories(output_.folder / "preview", error);
  }
  shared_ = std::make_unique<Shared>(options_.pipeline.queue_capacity, source_->IsLive());
  shared_->intrinsics = source_->Intrinsics();
  const CameraIntrinsics& camera = shared_->intrinsics;
  spdlog::info("camera: {}x{} pixels, fx {:.2f} fy {:.2f} cx {:.2f} cy {:.2f}", camera.width,
               camera.height, camera.fx, camera.fy, camera.cx, camera.cy);
  // Live, a search must not stall the tracker (PipelineOptions::live_search_beside).
  ScannerOptions hand_options = options_;
  hand_options.tracker.search_beside = shared_->live && options_.pipeline.live_search_beside;
  shared_->hand = std::make_unique<HandStage>(hand_options, shared_->intrinsics);
  shared_->bone_names = shared_->hand->BoneNames();
  shared_->angle_names = shared_->hand->AngleNames();
  shared_->joint_parents = {-1};
  for (const auto& bone : shared_->hand->model().bones) {
    shared_->joint_parents.push_back(bone.parent < 0 ? 0 : bone.parent + 1);
  }
  if (initial_hand_pose) shared_->hand->Initialise(*initial_hand_pose);
  // Only once the input opened and the stages were made: a mistyped input or template must not
  // cost the earlier scan.
  if (const int removed = RemovePreviousScan(output_.folder)) {
    spdlog::info("{}: removed {} files of an earlier scan", output_.folder.string(), removed);
  }
  run_record_ = RunRecord::Of(source_->Description(), options_);
  run_record_.Write(output_.folder, shared_->intrinsics);
}

void Pipeline::ThreadDone() {
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    --shared_->running;
  }
  shared_->done.notify_all();
}

void Pipeline::Fail(const std::string& stage, std::exception_ptr error) {
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    if (!shared_->failure) {
      shared_->failure = error;
      shared_->failed_stage = stage;
    }
  }
  spdlog::error("{} failed: {}", stage, MessageOf(error));
  RequestStop();
}

void Pipeline::CaptureLoop() {
  Shared& s = *shared_;
  std::string end_reason = "end of stream";
  try {
    std::int64_t read_frames = 0;
    while (true) {
      if (stop_requested_.load()) {
        end_reason = "stopped";
        break;
      }
      if (options_.pipeline.max_frames > 0 && read_frames >= options_.pipeline.max_frames) {
        end_reason = "frame limit";
        break;
      }
      const sensor::SourceRead read = source_->Next(std::chrono::milliseconds(200));
      if (read.status == sensor::SourceStatus::kTimeout) continue;
      if (read.status == sensor::SourceStatus::kEndOfStream) break;
      if (read.status == sensor::SourceStatus::kDisconnected) {
        end_reason = "disconnected" + (read.message.empty() ? "" : ": " + read.message);
        Fail("capture", std::make_exception_ptr(DeviceError(end_reason)));
        break;
      }
      ++read_frames;
      ++s.captured;
      auto packet = std::make_unique<FramePacket>();
      packet->frame = read.frame;
      packet->captured_at = SteadyClock::now();
      if (s.live) {
        if (!s.frames.TryPush(std::move(packet))) ++s.dropped_capture;
      } else if (!s.frames.Push(std::move(packet))) {
        break;  // The tracker has stopped.
      }
    }
  } catch (...) {
    end_reason = "failed";
    Fail("capture", std::current_exception());
  }
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    s.end_reason = end_reason;
  }
  s.frames.Close();
  ThreadDone();
}

void Pipeline::TrackerLoop() {
  Shared& s = *shared_;
  try {
    PacketPtr packet;
    while (true) {
      // Live, the newest frame: the older ones queued meanwhile would only add latency.
      std::size_t skipped = 0;
      const PopStatus status = s.live
                                   ? s.frames.PopLatest(packet, std::chrono::seconds(1), &skipped)
                                   : s.frames.Pop(packet);
      s.dropped_stale += static_cast<std::int64_t>(skipped);
      if (status == PopStatus::kTimeout) continue;
      if (status == PopStatus::kClosed) break;
      s.hand->Process(*packet);
      {
        std::lock_guard<std::mutex> lock(s.mutex);
        s.hand_state = packet->HandState();
      }
      if (!s.tracked.Push(std::move(packet))) break;  // The fusion thread has stopped.
    }
  } catch (...) {
    Fail("tracker", std::current_exception());
  }
  s.frames.Abandon();  // Releases a capture thread blocked on a full queue.
  s.tracked.Close();
  ThreadDone();
}

void Pipeline::FusionLoop() {
  Shared& s = *shared_;
  std::unique_ptr<ObjectStage> object;
  auto record = std::make_shared<ScanRecord>(s.bone_names, s.angle_names);
  std::int64_t previewed_at = 0;
  std::int64_t live_view_frame = -1000;
  // Hands a snapshot to the export thread; false when it is busy (try again later). Only this
  // thread pushes, so a queue with room now still has room after the snapshot is made.
  auto submit = [&](ExportJob::Kind kind, const FramePacket* packet) {
    const bool final = kind == ExportJob::Kind::kFinal;
    if (!final && s.jobs.SizeApprox() >= s.jobs.capacity()) return false;
    auto job = std::make_unique<ExportJob>();
    job->kind = kind;
    if (kind == ExportJob::Kind::kPreview) {
      job->frame = packet->frame;
      job->model_view =
          ViewModelFromCamera(object->volume(), s.intrinsics, packet->fusion.cam_from_object);
      job->hand = packet->hand_mesh;
    } else {
      if (object) job->model = object->Snapshot();
      job->record = std::make_shared<ScanRecord>(*record);
    }
    if (final) return s.jobs.Push(std::move(job));
    return s.jobs.TryPush(std::move(job));
  };
  try {
    object = std::make_unique<ObjectStage>(options_, s.intrinsics);
    PacketPtr packet;
    while (true) {
      const PopStatus status = s.tracked.Pop(packet, std::chrono::milliseconds(50));
      if (reset_requested_.exchange(false)) {
        spdlog::info("reset: the model starts anew");
        object = std::make_unique<ObjectStage>(options_, s.intrinsics);
        record = std::make_shared<ScanRecord>(s.bone_names, s.angle_names);
        s.registered = 0;
        s.coverage = 0;
        previewed_at = 0;
      }
      if (export_requested_.load() && object->started() &&
          submit(ExportJob::Kind::kExport, nullptr)) {
        export_requested_.store(false);
      }
      if (status == PopStatus::kTimeout) {
        if (!abandon_requested_.load()) continue;
        spdlog::warn(
            "the frames in hand did not finish after the stop: the model so far is "
            "exported without them");
        std::lock_guard<std::mutex> lock(s.mutex);
        if (s.end_reason.empty()) s.end_reason = "stopped, frames in hand left behind";
        break;
      }
      if (status == PopStatus::kClosed) break;
      object->Process(*packet);
      packet->latency_ms = MillisecondsSince(packet->captured_at);
      record->Add(*packet);
      s.coverage = packet->fusion.coverage;
      {
        std::lock_guard<std::mutex> lock(s.mutex);
        s.object_state = packet->ObjectState();
      }
      ++s.processed;
      s.processing_seconds = MillisecondsSince(s.start) / 1000.0;
      if (!packet->Registered()) continue;
      const std::int64_t registered = ++s.registered;
      const int every = options_.pipeline.preview_every;
      if (every > 0 && registered - previewed_at >= every) {
        if (submit(ExportJob::Kind::kPreview, packet.get())) {
          previewed_at = registered;
        } else {
          ++s.previews_skipped;
        }
      }
      if (output_.live_view && packet->frame->index - live_view_frame >= 3) {
        live_view_frame = packet->frame->index;
        LiveView view;
        view.frame = packet->frame;
        view.joints_mm = packet->track.joints_mm;
        view.joint_parents = s.joint_parents;
        for (const auto& pair : packet->track.contact_pairs)
          view.contacts_mm.push_back(pair.current_mm);
        view.viewpoint = {view_yaw_deg_.load(), view_pitch_deg_.load()};
        view.model = ViewModelFitted(object->volume(), s.intrinsics, packet->fusion.cam_from_object,
                                     view.viewpoint);
        live_view_.Put(std::move(view));
      }
    }
  } catch (...) {
    Fail("fusion", std::current_exception());
  }
  s.tracked.Abandon();  // Releases a tracker thread blocked on a full queue.
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    s.nothing_scanned = record->NothingScanned();
  }
  try {
    submit(ExportJob::Kind::kFinal, nullptr);
  } catch (...) {
    Fail("fusion (final snapshot)", std::current_exception());
  }
  s.jobs.Close();
  ThreadDone();
}

void Pipeline::ExportLoop() {
  Shared& s = *shared_;
  std::unique_ptr<PreviewRenderer> previews;
  bool previews_failed = false;
  JobPtr job;
  while (s.jobs.Pop(job) == PopStatus::kItem) {
    try {
      if (job->kind == ExportJob::Kind::kPreview) {
        if (previews_failed) continue;
        try {
          if (!previews) previews = std::make_unique<PreviewRenderer>(s.intrinsics);
        } catch (const std::exception& error) {
          spdlog::warn("no preview images: {}", error.what());
          previews_failed = true;
          continue;
        }
        char name[32];
        std::snprintf(name, sizeof(name), "%06lld.png", static_cast<long long>(job->frame->index));
        WritePng(output_.folder / "preview" / name,
                 previews->Draw(*job->frame, job->model_view, job->hand.get()));
        continue;
      }
      const bool final = job->kind == ExportJob::Kind::kFinal;
      const ExportedMeshes exported =
          ExportMeshes(job->model, options_.meshing, output_.folder, output_.extra_formats);
      job->record->WriteTables(output_.folder, output_.trajectory_format);
      const PipelineProgress progress = Progress();
      nlohmann::json extra = {
          {"source", source_->Description()},
          {"run", run_record_.Json(s.intrinsics)},
          {"live", s.live},
          {"final", final},
          {"captured_frames", progress.captured},
          {"dropped_frames",
           {{"missed_by_source", source_->MissedFrames()},
            {"capture_queue_full", s.dropped_capture.load()},
            {"skipped_stale", s.dropped_stale.load()}}},
          {"previews_skipped", s.previews_skipped.load()},
          {"seconds", progress.seconds},
          {"processing_seconds", progress.processing_seconds},
          {"frames_per_second", progress.FramesPerSecond()},
          {"peak_rss_mib", PeakResidentMiB()},
          {"hand_scale", s.hand->scale()},
          {"hand_scale_at_bound", s.hand->scale_at_bound()},
          {"export_ms",
           {{"total", exported.milliseconds},
            {"cleanup", exported.meshes.cleanup_ms},
            {"smoothing", exported.meshes.smoothing_ms},
            {"poisson", exported.meshes.poisson_ms},
            {"bound", exported.meshes.bound_ms},
            {"repair", exported.meshes.repair_ms}}},
          {"mesh",
           {{"faces", exported.meshes.watertight.faces.size()},
            {"watertight", exported.meshes.IsWatertight()},
            {"self_intersections", exported.meshes.self_intersections},
            {"self_intersections_repaired", exported.meshes.repaired_intersections},
            {"unseen_share", exported.meshes.unseen_share},
            {"cut_share", exported.meshes.cut_share},
            {"hull_cut_share", exported.meshes.hull_cut_share},
            {"hull_revolved", exported.meshes.hull_shape == fusion::HullShape::kRevolved},
            {"hull_box", exported.meshes.hull_shape == fusion::HullShape::kBox},
            {"volume_mm3", exported.meshes.watertight.IsWatertight()
                               ? exported.meshes.watertight.Volume()
                               : 0.0}}}};
      if (final && !s.live) {
        // Frames of a recording its reader could not decode (skipped, each said in the log):
        // read once the capture has ended (the final job comes after it through the queues).
        extra["dropped_frames"]["unreadable_in_input"] = source_->SkippedFrames();
        extra["input_recovered"] = source_->Recovered();
      }
      {
        std::lock_guard<std::mutex> lock(s.mutex);
        if (!s.end_reason.empty()) extra["end_reason"] = s.end_reason;
        if (s.failure) extra["failure"] = s.failed_stage + ": " + MessageOf(s.failure);
      }
      job->record->WriteStats(output_.folder / "stats.json", extra);
      ++s.exports;
      if (exported.meshes.repaired_intersections > 0) {
        spdlog::info(
            "export: the closed mesh crossed itself ({} pairs of faces); re-made from its signed "
            "distance without them",
            exported.meshes.repaired_intersections);
      }
      if (exported.meshes.self_intersections > 0) {
        spdlog::warn(
            "export: the closed mesh crosses itself ({} pairs of faces): closed and manifold, "
            "but not watertight to a slicer",
            exported.meshes.self_intersections);
      }
      if (exported.files.empty()) {
        // The final one: the scan's end says "nothing was scanned" and why.
        if (!final) spdlog::warn("export: nothing to mesh yet");
      } else {
        const double coverage = job->record->coverage();
        spdlog::info(
            "exported {} ({} faces, seen from {:.0f} % of the directions around it, {:.0f} % of "
            "its surface never seen, {:.1f} s)",
            exported.files.back().string(), exported.meshes.watertight.faces.size(), 100 * coverage,
            100 * exported.meshes.unseen_share, exported.milliseconds / 1000.0);
        if (exported.meshes.unseen_share > kUnseenShareWarning || coverage < kCoverageWarning) {
          spdlog::warn(
              "export: the object was seen from {:.0f} % of the directions around it and {:.0f} "
              "% of the watertight mesh was never seen, Poisson's guess (its volume too): turn "
              "the object to show the rest",
              100 * coverage, 100 * exported.meshes.unseen_share);
        }
      }
      if (final) {
        std::lock_guard<std::mutex> lock(s.mutex);
        s.final_files = exported.files;
      }
    } catch (...) {
      Fail("export", std::current_exception());
    }
  }
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    s.export_done = true;
  }
  ThreadDone();
}

bool Pipeline::Wait(std::chrono::milliseconds timeout) {
  if (!started_) return true;
  std::unique_lock<std::mutex> lock(shared_->mutex);
  return shared_->done.wait_for(lock, timeout, [this] { return shared_->running == 0; });
}

bool Pipeline::WaitForFinalExport(std::chrono::milliseconds timeout) {
  if (!started_) return true;
  std::unique_lock<std::mutex> lock(shared_->mutex);
  return shared_->done.wait_for(lock, timeout, [this] { return shared_->export_done; });
}

PipelineProgress Pipeline::Progress() const {
  PipelineProgress progress;
  if (!shared_) return progress;
  const Shared& s = *shared_;
  progress.captured = s.captured.load();
  progress.processed = s.processed.load();
  progress.registered = s.registered.load();
  progress.dropped = s.dropped_capture.load() + s.dropped_stale.load();
  progress.exports = s.exports.load();
  if (source_) progress.total = source_->FrameCount();
  if (started_) progress.seconds = MillisecondsSince(s.start) / 1000.0;
  progress.processing_seconds = s.processing_seconds.load();
  progress.coverage = s.coverage.load();
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    progress.hand = s.hand_state;
    progress.object = s.object_state;
  }
  return progress;
}

void Pipeline::SetModelViewpoint(const ModelViewpoint& viewpoint) {
  view_yaw_deg_.store(viewpoint.yaw_deg);
  view_pitch_deg_.store(viewpoint.pitch_deg);
}

CameraIntrinsics Pipeline::intrinsics() const {
  if (!shared_) throw std::logic_error("Pipeline::intrinsics before Start");
  return shared_->intrinsics;
}

PipelineResult Pipeline::Finish() {
  PipelineResult result;
  if (!started_) throw std::logic_error("Pipeline::Finish before Start");
  if (!finished_) {
    for (std::thread& thread : threads_) thread.join();
    finished_ = true;
    source_->Stop();
  }
  Shared& s = *shared_;
  result.progress = Progress();
  std::lock_guard<std::mutex> lock(s.mutex);
  result.end_reason = s.end_reason;
  result.files = s.final_files;
  if (s.failure) {
    result.exit_code = ExitCodeOf(s.failure);
    result.error = s.failed_stage + ": " + MessageOf(s.failure);
    // What is in the folder now was written by this scan (an earlier one's files were removed
    // when it started), the final export's or an earlier export's.
    const std::string saved = ScanFileNamesIn(output_.folder);
    if (saved.empty()) {
      result.error += " (nothing could be saved)";
    } else if (std::filesystem::exists(output_.folder / "mesh.ply")) {
      result.error += " (the model so far was saved: " + saved + ")";
    } else {
      result.error += " (no mesh could be saved; saved: " + saved + ")";
    }
  } else if (result.progress.captured == 0) {
    result.exit_code = kExitInput;
    result.error = source_->Description() + ": no frames";
  } else if (result.files.empty()) {
    result.exit_code = kExitStageFailed;
    result.error = s.nothing_scanned;
  }
  return result;
}

}  // namespace ihs::app

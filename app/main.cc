// inhandscan: scan an object turned in one hand, live from an OpenNI2 camera or from a
// recording. Subcommands: live, replay, record, devices, config. See --help.

#include <signal.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "app/live_screen.h"
#include "app/pipeline.h"
#include "app/scan_export.h"
#include "app/scanner_options.h"
#include "core/allocator.h"
#include "core/command_line.h"
#include "core/errors.h"
#include "core/exit_codes.h"
#include "core/logging.h"
#include "render/live_window.h"
#include "sensor/intrinsics_override.h"
#include "sensor/open_input.h"
#include "sensor/openni_recorder.h"
#include "sensor/openni_source.h"
#include "sensor/paced_source.h"
#include "sensor/tum_directory.h"
#include "sensor/usb_devices.h"

namespace {

namespace fs = std::filesystem;
using ihs::app::Pipeline;

// Set by the signal handlers, read by the controlling loop (lock-free atomics are
// async-signal-safe).
std::atomic<int> g_stop_signals{0};
std::atomic<bool> g_export_signal{false};
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<bool>::is_always_lock_free);

void OnStopSignal(int) {
  // The first SIGINT/SIGTERM/SIGHUP finishes the scan (frames in hand, export); a second exits at
  // once.
  if (g_stop_signals.fetch_add(1) >= 1) _exit(130);
}

void OnExportSignal(int) { g_export_signal.store(true); }

void InstallSignalHandlers() {
  struct sigaction action = {};
  sigemptyset(&action.sa_mask);
  action.sa_handler = OnStopSignal;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGHUP, &action, nullptr);  // A closed terminal must not lose the scan.
  action.sa_handler = OnExportSignal;
  sigaction(SIGUSR1, &action, nullptr);
}

std::string DefaultOutputFolder() {
  const std::time_t now = std::time(nullptr);
  std::tm local = {};
  localtime_r(&now, &local);
  char name[64];
  std::strftime(name, sizeof(name), "scan-%Y%m%d-%H%M%S", &local);
  return name;
}

// Options shared by live and replay.
struct ScanArgs {
  std::string out;
  std::vector<std::string> formats;
  bool no_window = false;
  bool window = false;
  std::string screenshot;
  bool realtime = false;
  int loops = 1;
  std::string device;
  std::string input;
  std::string trajectory_format = "mm";
  std::string intrinsics;  // --intrinsics FILE
  double depth_scale = 0;  // --depth-scale, units per metre (0: the input's own)
};

// The input's source with the camera options: for an image folder, its intrinsics and depth
// scale; for a recording or a device, the intrinsics in place of its own (its depth is in mm).
std::unique_ptr<ihs::sensor::FrameSource> OpenWithCamera(
    const ScanArgs& args, ihs::sensor::InputOptions options,
    const std::function<
        std::unique_ptr<ihs::sensor::FrameSource>(const ihs::sensor::InputOptions&)>& open) {
  const bool folder = !args.input.empty() && std::filesystem::is_directory(args.input);
  if (args.depth_scale > 0) {
    if (!folder) {
      throw std::invalid_argument(
          "--depth-scale applies to image folders (TUM or Open3D's); a recording's or a "
          "camera's depth is in millimetres");
    }
    options.tum.depth_scale_per_m = options.tum.open3d_depth_scale_per_m = args.depth_scale;
  }
  if (args.intrinsics.empty()) return open(options);
  const ihs::CameraIntrinsics intrinsics = ihs::sensor::ReadIntrinsicsFile(args.intrinsics);
  if (folder) {
    options.tum.intrinsics = intrinsics;
    return open(options);
  }
  return std::make_unique<ihs::sensor::IntrinsicsOverride>(open(options), intrinsics);
}

// The options `live` and `replay` share: the outputs and the camera.
void AddScanFlags(CLI::App* command, ScanArgs& args) {
  command->add_option("--screenshot", args.screenshot,
                      "save a PNG of the window as it looks when the scan ends (drawn off-screen "
                      "when there is no window)");
  command->add_option("--out", args.out, "output folder (default: scan-DATE-TIME)");
  command->add_option("--format", args.formats, "also write the mesh as obj and/or stl")
      ->check(CLI::IsMember({"obj", "stl", "ply"}))
      ->delimiter(',');
  command
      ->add_option("--trajectory-format", args.trajectory_format,
                   "trajectory.txt as mm (cam_from_object, millimetres) or tum-m (the camera's "
                   "pose in the object's frame, metres: TUM's and evo's tools)")
      ->check(CLI::IsMember({"mm", "tum-m"}))
      ->capture_default_str();
  command->add_option("--intrinsics", args.intrinsics,
                      "the camera's intrinsics: a file of 'fx fy cx cy width height', or "
                      "Open3D's PinholeCameraIntrinsic JSON (default: the input's own)");
  command
      ->add_option("--depth-scale", args.depth_scale,
                   "depth image units per metre of an image folder (default: TUM 5000, "
                   "Open3D's layout 1000)")
      ->check(CLI::Range(1.0, 1e6));
}

// Edits (insertions, deletions, substitutions) between `a` and `b`.
size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// A first word that is not a subcommand but close to one ("replya"): the one it was meant to be.
std::optional<std::string> MistypedSubcommand(const CLI::App& app, int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return std::nullopt;
  const std::string word = argv[1];
  std::optional<std::string> closest;
  size_t best = 3;  // At most two edits away.
  for (const CLI::App* command : app.get_subcommands({})) {
    const std::string& name = command->get_name();
    if (name == word) return std::nullopt;
    const size_t distance = EditDistance(word, name);
    if (distance < best) best = distance, closest = name;
  }
  return closest;
}

// Progress for a person: a line rewritten in place on a terminal, a log line every 10 s
// otherwise.
class ProgressReporter {
 public:
  ProgressReporter() : terminal_(isatty(STDERR_FILENO) != 0) {}

  void Update(const ihs::app::PipelineProgress& progress) {
    const double fps = progress.FramesPerSecond();
    std::string done = std::to_string(progress.processed);
    std::string eta;
    if (progress.total && *progress.total > 0) {
      done += "/" + std::to_string(*progress.total);
      if (fps > 0) {
        const double left = (*progress.total - progress.processed) / fps;
        eta = ", ETA " + std::to_string(static_cast<long long>(std::ceil(std::max(0.0, left)))) +
              " s";
      }
    }
    char line[256];
    std::snprintf(line, sizeof(line), "frames %s, %.1f fps, fused %lld, dropped %lld, seen %.0f %%%s",
                  done.c_str(), fps, static_cast<long long>(progress.registered),
                  static_cast<long long>(progress.dropped), 100 * progress.coverage, eta.c_str());
    if (terminal_) {
      ihs::ProgressLine::OnStderr().Show(line);  // Log lines meanwhile go above it.
    } else if (progress.seconds - last_log_s_ >= 10.0) {
      last_log_s_ = progress.seconds;
      spdlog::info("{}", line);
    }
  }

  void Done() { ihs::ProgressLine::OnStderr().End(); }

 private:
  const bool terminal_;
  double last_log_s_ = 0;
};

// A stop whose frames in hand did not finish within the grace: once the model so far is exported
// without them (or the export itself is stuck), says what was saved and exits at once, leaving
// the stuck thread behind (joining it would wait for ever).
class StopGuard {
 public:
  StopGuard(Pipeline& pipeline, const fs::path& folder, double grace_s)
      : pipeline_(pipeline), folder_(folder), grace_(std::chrono::duration<double>(grace_s)) {}

  void Check(bool stop_sent) {
    const auto now = std::chrono::steady_clock::now();
    if (!stop_sent) return;
    if (!stopped_at_) stopped_at_ = now;
    if (!abandoned_at_ && now - *stopped_at_ > grace_) {
      spdlog::warn("a stage has not finished its frame {:.0f} s after the stop", grace_.count());
      pipeline_.Abandon();
      abandoned_at_ = now;
    }
    if (!abandoned_at_) return;
    // The final export itself takes seconds (Poisson); only a fusion thread stuck in its own
    // frame never gets to it.
    const bool exported = pipeline_.WaitForFinalExport(std::chrono::milliseconds(0));
    if (!exported && now - *abandoned_at_ <= grace_ + kExportWait) return;
    const std::string saved = ihs::app::ScanFileNamesIn(folder_);
    ihs::ProgressLine::OnStderr().End();  // The error on a line of its own.
    std::fprintf(stderr, "inhandscan: error: %s\n",
                 ihs::OneLine("a stage did not finish its frame after the stop; " +
                              (saved.empty() ? std::string("nothing could be saved")
                                             : "the model so far was saved without the frames "
                                               "in hand: " +
                                                   saved))
                     .c_str());
    if (fs::exists(folder_ / "mesh.ply")) std::printf("mesh: %s\n", (folder_ / "mesh.ply").c_str());
    std::fflush(stdout);
    std::fflush(stderr);
    std::_Exit(ihs::kExitStageFailed);
  }

 private:
  Pipeline& pipeline_;
  const fs::path folder_;
  const std::chrono::duration<double> grace_;
  std::optional<std::chrono::steady_clock::time_point> stopped_at_, abandoned_at_;
  static constexpr std::chrono::seconds kExportWait{300};
};

// Runs a pipeline to its end: signals (and the window's keys) become requests; returns the
// exit code after printing where the mesh is.
int RunPipeline(Pipeline& pipeline, ihs::render::LiveWindow* window, const std::string& screenshot,
                bool quiet, StopGuard& guard) {
  ProgressReporter reporter;
  ihs::app::LiveScreen screen(pipeline, window);
  bool stop_sent = false;
  while (!pipeline.Wait(std::chrono::milliseconds(window ? 15 : 100))) {
    guard.Check(stop_sent);
    if (g_export_signal.exchange(false)) {
      spdlog::info("export requested");
      pipeline.RequestExport();
    }
    if (g_stop_signals.load() > 0 && !stop_sent) {
      spdlog::info("stopping: finishing the frames in hand, then exporting");
      pipeline.RequestStop();
      stop_sent = true;
    }
    if (screen.Poll() && !stop_sent) pipeline.RequestStop(), stop_sent = true;
    if (!window && !quiet) reporter.Update(pipeline.Progress());
  }
  reporter.Done();
  if (!screenshot.empty()) {
    try {
      screen.SaveScreenshot(screenshot);
    } catch (const ihs::OutputError& error) {  // The scan itself is saved: only say so.
      spdlog::error("no screenshot: {}", error.what());
    }
  }
  const ihs::app::PipelineResult result = pipeline.Finish();
  const auto& p = result.progress;
  spdlog::info("{} frames ({}): {} fused, {} dropped, {:.1f} frames/s, {:.1f} s in all",
               p.processed, result.end_reason, p.registered, p.dropped, p.FramesPerSecond(),
               p.seconds);
  for (const fs::path& file : result.files) {
    if (file.filename() == "mesh.ply") std::printf("mesh: %s\n", file.c_str());
  }
  if (!result.error.empty()) {
    std::fprintf(stderr, "inhandscan: error: %s\n", ihs::OneLine(result.error).c_str());
  }
  return result.exit_code;
}

int Scan(std::unique_ptr<ihs::sensor::FrameSource> source, ihs::app::ScannerOptions options,
         const ScanArgs& args, bool want_window, bool quiet) {
  ihs::app::PipelineOutput output;
  output.folder = args.out.empty() ? DefaultOutputFolder() : args.out;
  output.extra_formats = args.formats;
  output.trajectory_format = ihs::app::ParseTrajectoryFormat(args.trajectory_format);
  output.live_view = want_window || !args.screenshot.empty();
  const double stop_grace_s = options.pipeline.stop_grace_s;
  Pipeline pipeline(std::move(source), std::move(options), output);
  pipeline.Start();
  std::unique_ptr<ihs::render::LiveWindow> window;
  if (want_window) {
    try {
      int width = 0, height = 0;
      ihs::app::LiveScreenSize(pipeline.intrinsics(), &width, &height);
      window = std::make_unique<ihs::render::LiveWindow>("inhandscan", width, height);
    } catch (const ihs::DeviceError& error) {
      spdlog::warn("{}; scanning without a window (export: kill -USR1 {}; stop: Ctrl-C)",
                   error.what(), getpid());
    }
  }
  spdlog::info("scanning into {} (export now: kill -USR1 {}; stop: Ctrl-C)", output.folder.string(),
               getpid());
  StopGuard guard(pipeline, output.folder, stop_grace_s);
  return RunPipeline(pipeline, window.get(), args.screenshot, quiet, guard);
}

}  // namespace

int main(int argc, char** argv) {
  ihs::KeepFreedMemoryForReuse();
  CLI::App app{
      "inhandscan: scan a small object into a watertight 3D mesh while you turn it in "
      "one hand in front of a depth camera (Tzionas & Gall, ICCV 2015).",
      "inhandscan"};
  app.footer(ihs::ExitCodesHelp());
  app.set_version_flag("--version", std::string("inhandscan ") + IHS_VERSION);
  app.require_subcommand(1);
  std::string log_level = "info";
  bool quiet = false;
  std::string config_file;
  std::vector<std::string> assignments;
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
  app.add_flag("-q,--quiet", quiet, "only warnings and errors, no progress");
  app.add_option("--config", config_file,
                 "options file (NAME = VALUE lines; `inhandscan config` prints every option)");
  app.add_option("--set", assignments, "set one option: NAME=VALUE (repeatable; after --config)");

  ScanArgs args;
  CLI::App* live = app.add_subcommand("live", "scan with a Carmine 1.09 (or any OpenNI2 camera)");
  live->add_option("--device", args.device, "device URI (default: the first one)");
  live->add_flag("--no-window", args.no_window, "headless: export on SIGUSR1, stop on Ctrl-C");
  AddScanFlags(live, args);
  CLI::App* replay =
      app.add_subcommand("replay", "scan a recording (.oni, TUM or Open3D folder), headless");
  replay->add_option("input", args.input, ".oni file, TUM RGB-D folder or Open3D folder")
      ->required();
  replay->add_flag("--realtime", args.realtime,
                   "pace frames at their timestamps and drop frames as live would");
  replay->add_flag("--window", args.window, "show the live window while replaying");
  replay
      ->add_option("--loop", args.loops,
                   "play the recording this many times over, as one long input (a soak run)")
      ->check(CLI::Range(1, 1000));
  AddScanFlags(replay, args);
  std::string record_path;
  double record_seconds = 0;
  CLI::App* record = app.add_subcommand("record", "record the camera to an .oni file");
  record->add_option("output", record_path, ".oni file to write")->required();
  record->add_option("--seconds", record_seconds, "stop after this long (default: Ctrl-C)")
      ->check(CLI::PositiveNumber);
  record->add_option("--device", args.device, "device URI (default: the first one)");
  CLI::App* devices = app.add_subcommand("devices", "list cameras on USB and what OpenNI2 sees");
  CLI::App* config =
      app.add_subcommand("config", "print every option with its default and meaning");
  ihs::ShareOptionsWithSubcommands(app);  // Global options may also follow the subcommand.

  if (const auto meant = MistypedSubcommand(app, argc, argv)) {
    std::fprintf(stderr, "inhandscan: error: unknown command '%s' (did you mean '%s'?)\n", argv[1],
                 meant->c_str());
    return ihs::kExitUsage;
  }
  if (const auto done = ihs::ParseCommandLine(app, argc, argv)) return *done;
  return ihs::RunReportingErrors("inhandscan", [&]() -> int {
    ihs::SetUpLogging(ihs::ParseLogLevel(log_level), quiet);
    ihs::app::ScannerOptions options;
    ihs::app::OptionRegistry registry = ihs::app::RegisterScannerOptions(&options);
    if (!config_file.empty()) registry.Load(config_file);
    for (const std::string& assignment : assignments) registry.SetAssignment(assignment);
    options.Check();
    if (config->parsed()) {
      std::printf("# inhandscan %s options (a valid --config file; defaults are the paper's)\n%s",
                  IHS_VERSION, registry.Describe().c_str());
      return ihs::kExitOk;
    }
    if (devices->parsed()) {
      bool ready = false;
      std::printf(
          "%s", ihs::sensor::DescribeUsbScan(ihs::sensor::ScanPrimeSenseDevices(), &ready).c_str());
      std::printf("%s", ihs::sensor::DescribeOpenNiDevices().c_str());
      return ready ? ihs::kExitOk : ihs::kExitDevice;
    }
    InstallSignalHandlers();
    if (record->parsed()) {
      ihs::sensor::OpenNiOptions device;
      device.uri = args.device;
      std::atomic<bool> stop{false};
      // No --seconds: until Ctrl-C (a year stands for "no limit": the recorder compares it with
      // a clock difference in nanoseconds, which milliseconds::max() would overflow).
      const std::chrono::milliseconds max_duration =
          record_seconds > 0
              ? std::chrono::milliseconds(static_cast<long long>(record_seconds * 1000))
              : std::chrono::hours(24 * 365);
      // The recorder polls `stop`; the signal handler only counts signals.
      std::thread watcher([&] {
        while (!stop.load()) {
          if (g_stop_signals.load() > 0) stop.store(true);
          std::this_thread::sleep_for(std::chrono::milliseconds(50));
        }
      });
      ihs::sensor::RecordingSummary summary;
      try {
        summary = ihs::sensor::RecordWithOpenNi(device, record_path, max_duration, 0, stop);
      } catch (...) {
        stop.store(true);
        watcher.join();
        throw;
      }
      stop.store(true);
      watcher.join();
      std::printf("recorded %lld frames (%.1f s) to %s\n",
                  static_cast<long long>(summary.depth_frames), summary.seconds,
                  record_path.c_str());
      return ihs::kExitOk;
    }
    if (live->parsed()) {
      ihs::sensor::OpenNiOptions device;
      device.uri = args.device;
      auto camera = OpenWithCamera(args, {}, [&](const ihs::sensor::InputOptions&) {
        return std::make_unique<ihs::sensor::OpenNiSource>(device);
      });
      return Scan(std::move(camera), options, args, !args.no_window, quiet);
    }
    ihs::sensor::InputOptions input_options;
    input_options.pacing =
        args.realtime ? ihs::sensor::Pacing::kRealTime : ihs::sensor::Pacing::kAsFastAsPossible;
    input_options.loops = args.loops;
    auto input = OpenWithCamera(args, input_options, [&](const ihs::sensor::InputOptions& with) {
      return ihs::sensor::OpenInput(args.input, with);
    });
    return Scan(std::move(input), options, args, args.window, quiet);
  });
}

// inhandscan-frames: what is in a recording (.oni or TUM folder), and conversion between the two.

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "core/command_line.h"
#include "core/errors.h"
#include "core/exit_codes.h"
#include "core/logging.h"
#include "sensor/oni_writer.h"
#include "sensor/open_input.h"
#include "sensor/openni_source.h"
#include "sensor/tum_directory.h"

namespace {

namespace fs = std::filesystem;
using ihs::sensor::FrameSource;
using ihs::sensor::SourceRead;
using ihs::sensor::SourceStatus;

// Reads every frame of `source`, calling `on_frame` for each; returns how the stream ended.
template <typename OnFrame>
SourceRead Drain(FrameSource& source, OnFrame on_frame) {
  while (true) {
    SourceRead read = source.Next(std::chrono::seconds(5));
    if (read.status == SourceStatus::kTimeout) continue;
    if (read.status != SourceStatus::kFrame) return read;
    on_frame(*read.frame);
  }
}

int Info(const std::string& input, const ihs::sensor::InputOptions& options, bool json) {
  auto source = ihs::sensor::OpenInput(input, options);
  source->Start();
  std::int64_t depth_frames = 0, color_frames = 0;
  std::int64_t first = std::numeric_limits<std::int64_t>::max(), last = 0;
  int width = 0, height = 0;
  Drain(*source, [&](const ihs::Frame& frame) {
    ++depth_frames;
    if (frame.HasColor()) ++color_frames;
    width = frame.width;
    height = frame.height;
    first = std::min(first, frame.depth_timestamp_us);
    last = std::max(last, frame.depth_timestamp_us);
  });
  const ihs::CameraIntrinsics k = source->Intrinsics();
  if (depth_frames == 0) first = 0;
  nlohmann::ordered_json info = {
      {"input", input},
      {"source", source->Description()},
      {"depth_frames", depth_frames},
      {"color_frames", color_frames},
      {"width", width},
      {"height", height},
      {"fx", k.fx},
      {"fy", k.fy},
      {"cx", k.cx},
      {"cy", k.cy},
      {"first_timestamp_us", first},
      {"last_timestamp_us", last},
      {"skipped_frames", source->SkippedFrames()},
      {"recovered", source->Recovered()},
  };
  if (json) {
    std::printf("%s\n", info.dump(2).c_str());
  } else {
    for (const auto& [key, value] : info.items()) {
      std::printf("%s: %s\n", key.c_str(),
                  value.is_string() ? value.get<std::string>().c_str() : value.dump().c_str());
    }
  }
  return ihs::kExitOk;
}

// Where a conversion is written before it is complete: beside OUTPUT, hidden, removed unless
// it is renamed into place (a full disk or a bad input leaves nothing under OUTPUT's name).
class PartialOutput {
 public:
  explicit PartialOutput(const fs::path& output)
      : final_(output.lexically_normal()),
        partial_(final_.parent_path() /
                 ("." + final_.filename().string() + ".partial-" + std::to_string(getpid()))) {
    if (final_.filename().empty()) throw std::invalid_argument(output.string() + ": not a path");
    std::error_code error;
    if (fs::is_directory(final_, error) && !fs::is_empty(final_, error)) {
      throw ihs::OutputError(final_.string() + ": a folder that is not empty; give a new one");
    }
  }
  ~PartialOutput() {
    std::error_code error;
    if (!committed_) fs::remove_all(partial_, error);
  }
  const fs::path& path() const { return partial_; }
  // Moves the complete output into place: replaces a file, or fills an absent or empty folder.
  void Commit() {
    std::error_code error;
    if (fs::is_directory(final_, error)) fs::remove(final_, error);  // Empty (checked above).
    fs::rename(partial_, final_, error);
    if (error) {
      throw ihs::OutputError(final_.string() + ": cannot move the conversion into place (" +
                             error.message() + ")");
    }
    committed_ = true;
  }

 private:
  const fs::path final_, partial_;
  bool committed_ = false;
};

int Convert(const std::string& input, const std::string& output,
            const ihs::sensor::InputOptions& options) {
  auto source = ihs::sensor::OpenInput(input, options);
  source->Start();
  std::int64_t frames = 0;
  SourceRead end;
  PartialOutput partial(output);
  if (ihs::sensor::OpenNiSource::IsOniPath(output)) {
    ihs::sensor::OniWriterOptions writer_options;
    writer_options.intrinsics = source->Intrinsics();
    ihs::sensor::OniWriter writer(partial.path(), writer_options);
    end = Drain(*source, [&](const ihs::Frame& frame) {
      writer.Write(frame);
      ++frames;
    });
    writer.Close();
  } else {
    ihs::sensor::TumWriter writer(partial.path(), source->Intrinsics(), options.tum);
    end = Drain(*source, [&](const ihs::Frame& frame) {
      writer.Write(frame);
      ++frames;
    });
    writer.Finish();
  }
  if (source->Recovered()) {
    spdlog::warn("{}: damaged recording: converted the {} frames that could be recovered", input,
                 frames);
  }
  if (frames == 0) return ihs::kExitInput;
  partial.Commit();
  spdlog::info("wrote {} frames to {}", frames, output);
  return ihs::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Inspect and convert RGB-D recordings (.oni files, TUM RGB-D folders).",
               "inhandscan-frames"};
  app.footer(ihs::ExitCodesHelp());
  app.set_version_flag("--version", std::string("inhandscan-frames ") + IHS_VERSION);
  app.require_subcommand(1);
  std::string log_level = "info";
  bool quiet = false;
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off");
  app.add_flag("-q,--quiet", quiet, "only warnings and errors");

  std::string input, output, intrinsics, backend = "auto";
  double depth_scale = 5000;
  bool json = false;
  auto add_input_options = [&](CLI::App* command) {
    command->add_option("--depth-scale", depth_scale,
                        "TUM depth PNG units per metre (default 5000)");
    command->add_option("--intrinsics", intrinsics, "fx,fy,cx,cy[,width,height] for TUM input");
    command->add_option("--oni-reader", backend, "auto, openni or own")
        ->check(CLI::IsMember({"auto", "openni", "own"}));
  };
  CLI::App* info = app.add_subcommand("info", "print what a recording holds");
  info->add_option("input", input, ".oni file or TUM folder")->required();
  info->add_flag("--json", json, "print a JSON object");
  add_input_options(info);
  CLI::App* convert = app.add_subcommand("convert", "convert between .oni and TUM folders");
  convert->add_option("input", input, ".oni file or TUM folder")->required();
  convert->add_option("output", output, ".oni file or TUM folder to write")->required();
  add_input_options(convert);
  ihs::ShareOptionsWithSubcommands(app);

  if (const auto done = ihs::ParseCommandLine(app, argc, argv)) return *done;
  return ihs::RunReportingErrors("inhandscan-frames", [&] {
    ihs::SetUpLogging(ihs::ParseLogLevel(log_level), quiet);
    ihs::sensor::InputOptions options;
    options.tum.depth_scale_per_m = depth_scale;
    if (!intrinsics.empty()) options.tum.intrinsics = ihs::sensor::ParseIntrinsics(intrinsics);
    options.tum.Check();
    options.oni_backend = backend == "openni" ? ihs::sensor::OniBackend::kOpenNi
                          : backend == "own"  ? ihs::sensor::OniBackend::kOwnReader
                                              : ihs::sensor::OniBackend::kAuto;
    return info->parsed() ? Info(input, options, json) : Convert(input, output, options);
  });
}

// inhandscan-synth: renders a ground-truthed synthetic in-hand scanning sequence (a hand turning
// an object) as an .oni file, a TUM folder and gt/ (see tools/synth/sequence.h for the layout).

#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <string>

#include "core/command_line.h"
#include "core/exit_codes.h"
#include "core/logging.h"
#include "render/offscreen_renderer.h"
#include "tools/synth/sequence.h"

namespace {

// "A:B", "A:" or "A" → first and last frame (−1: to the end).
void ParseFrameRange(const std::string& text, int* first, int* last) {
  const size_t colon = text.find(':');
  try {
    size_t used = 0;
    *first = std::stoi(text.substr(0, colon), &used);
    if (used != (colon == std::string::npos ? text.size() : colon)) throw std::invalid_argument("");
    *last = *first;
    if (colon != std::string::npos) {
      const std::string tail = text.substr(colon + 1);
      *last = tail.empty() ? -1 : std::stoi(tail, &used);
      if (!tail.empty() && used != tail.size()) throw std::invalid_argument("");
    }
  } catch (const std::exception&) {
    throw std::invalid_argument("--frames must be A:B, A: or A (frame numbers), got '" + text +
                                "'");
  }
}

}  // namespace

int main(int argc, char** argv) {
  ihs::render::UseMachineIndependentRasteriser();
  CLI::App app{"Render a synthetic in-hand scanning sequence with ground truth.",
               "inhandscan-synth"};
  app.footer(ihs::ExitCodesHelp());
  app.set_version_flag("--version", std::string("inhandscan-synth ") + IHS_VERSION);
  ihs::synth::SequenceOptions options;
  std::string out, frames, preset, log_level = "info";
  bool no_noise = false, quiet = false, no_oni = false, no_tum = false;
  double slip_mm = 0;
  app.add_option(
         "--object", options.object,
         "sphere, water-bottle, bowling-pin, small-bottle, box, plain-box, cube or lathe:FILE")
      ->capture_default_str();
  app.add_flag("--textured", options.textured,
               "give a lathe object or the cube a colour pattern (default: one uniform colour)");
  app.add_flag("--label", options.label,
               "with --textured, a lathe object's pattern is a label of spots drawn from --seed "
               "(every side different) instead of the checkerboard (which repeats every 60 deg)");
  app.add_flag("--empty-hand", options.empty_hand,
               "the hand makes the motion with nothing in it (the object is not rendered)");
  app.add_option("--motion", options.motion,
                 "scripted, or recorded:DIR (a session folder of the real hand data)")
      ->capture_default_str();
  app.add_option("--hand-scale", options.hand_scale,
                 "the hand's size relative to the template (scripted motion)")
      ->check(CLI::Range(0.5, 2.0));
  app.add_option("--hand", options.hand, "procedural, or the real hand data folder")
      ->capture_default_str();
  app.add_flag("--left-hand", options.left_hand,
               "a left hand (scripted motion; the procedural hand mirrored)");
  app.add_option("--frames", frames, "frame range A:B of the motion (default: all)");
  app.add_option("--frame-step", options.frame_step,
                 "render every Nth frame of the range: the motion N times as fast")
      ->check(CLI::Range(1, 10));
  app.add_option("--seed", options.seed, "seed of every random choice")->capture_default_str();
  app.add_flag("--no-noise", no_noise, "an ideal sensor (depth rounded to mm, nothing else)");
  app.add_option("--slip-mm", slip_mm, "contacts slide this much per held frame (random walk)")
      ->check(CLI::Range(0.0, 20.0));
  app.add_option("--scripted-frames", options.scripted.frames, "length of the scripted motion")
      ->capture_default_str();
  app.add_option("--turns", options.scripted.turns, "turns of the scripted motion")
      ->capture_default_str();
  app.add_option("--distance-mm", options.scripted.distance_mm,
                 "object distance from the camera in the scripted motion")
      ->capture_default_str();
  app.add_option("--tilt-deg", options.scripted.tilt_deg,
                 "the object's axis leans this much toward the camera (scripted motion)")
      ->capture_default_str();
  app.add_option(
         "--start-azimuth-deg", options.scripted.start_azimuth_deg,
         "where the hand starts about the object's axis, from the default side "
         "position (scripted motion; the sphere at 90: the hand in front, its back to the camera)")
      ->capture_default_str();
  app.add_flag("--no-oni", no_oni, "do not write sequence.oni");
  app.add_flag("--no-tum", no_tum, "do not write the tum/ folder");
  app.add_option("--preset", preset,
                 "demo: the textured box turned a full turn in 180 frames, procedural hand")
      ->check(CLI::IsMember({"demo"}));
  app.add_option("--out", out, "output folder")->required();
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off");
  app.add_flag("-q,--quiet", quiet, "only warnings and errors");
  if (const auto done = ihs::ParseCommandLine(app, argc, argv)) return *done;
  return ihs::RunReportingErrors("inhandscan-synth", [&] {
    ihs::SetUpLogging(ihs::ParseLogLevel(log_level), quiet);
    if (preset == "demo") {
      // A box, whose turn shows in its mesh (a sphere's lost spin would not), a full turn in as
      // many frames as tools/demo.sh scans in well under a minute.
      if (app.count("--object") == 0) options.object = "box";
      if (app.count("--motion") == 0) options.motion = "scripted";
      if (app.count("--hand") == 0) options.hand = "procedural";
      if (app.count("--scripted-frames") == 0) options.scripted.frames = 180;
      if (app.count("--turns") == 0) options.scripted.turns = 1.0;
    }
    if (!frames.empty()) ParseFrameRange(frames, &options.first_frame, &options.last_frame);
    if (no_noise) options.sensor = ihs::synth::SensorModelOptions::Ideal();
    options.scripted.seed = options.recorded.seed = options.seed;
    options.scripted.slip_mm = options.recorded.slip_mm = slip_mm;
    options.write_oni = !no_oni;
    options.write_tum = !no_tum;
    const ihs::synth::SequenceSummary summary = ihs::synth::GenerateSequence(options, out);
    spdlog::info("{} frames ({} held, deepest penetration {:.2f} mm) in {:.1f} s -> {}",
                 summary.frames, summary.held_frames, summary.max_penetration_mm, summary.seconds,
                 out);
    if (options.motion != "scripted") {
      const auto& r = summary.recorded;
      spdlog::info(
          "recorded motion: grasp at frame {}, held {} of {} frames; holding fingertips within "
          "3 mm: {:.1f} % carried by the contacts alone, {:.1f} % placed; penetration p95 {:.2f} "
          "mm, max {:.2f} mm",
          r.grasp_frame, r.held_frames, r.frames, 100 * r.carried_within_3mm_share,
          100 * r.placed_within_3mm_share, r.penetration_p95_mm, r.penetration_max_mm);
    }
    return ihs::kExitOk;
  });
}

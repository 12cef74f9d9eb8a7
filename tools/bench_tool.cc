// inhandscan-bench: the benchmark report. Renders generator sequences (scripted full turns of
// seven objects, the paper's four objects turned by its recorded hand motions), scans each with
// ours and the baselines (visual only, contacts only, no ICP, the γt sweep and, when built with
// Open3D, Open3D's frame-to-frame odometry + TSDF and its frame-to-model dense SLAM), measures
// everything against the ground truth and writes
// OUT/benchmarks.md with CSV files and pictures beside it.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "core/allocator.h"
#include "core/command_line.h"
#include "core/errors.h"
#include "core/exit_codes.h"
#include "core/logging.h"
#include "render/offscreen_renderer.h"
#include "tools/bench/bench_run.h"
#include "tools/bench/open3d_baseline.h"
#include "tools/bench/open3d_peer.h"
#include "tools/bench/report.h"

namespace {

namespace fs = std::filesystem;

struct Args {
  std::string data, out = "bench-report", work, app;
  std::vector<std::string> cases;
  int frames = 0;
  bool quick = false, no_open3d = false, no_app = false, no_pictures = false, quiet = false;
  std::string command;
  // The benchmark's own child process for one Open3D baseline (tools/bench/open3d_peer.h).
  std::string peer, peer_case, peer_out;
};

// What the program does as an Open3D peer: one baseline over one case, its results in files.
int RunPeer(const Args& args) {
  ihs::bench::RunOpen3dPeerJob(
      {{}, args.peer_case, ihs::bench::Open3dTrackingNamed(args.peer), args.peer_out});
  return ihs::kExitOk;
}

int Run(const Args& args) {
  namespace bench = ihs::bench;
  fs::path data = args.data;
  if (!data.empty() && !fs::is_directory(fs::path(data) / "sequences"))
    throw ihs::InputError(args.data + ": no sequences/ folder (the real hand data)");
  int frames = args.frames;
  std::vector<double> sweep = bench::GammaSweep();
  if (args.quick && frames == 0) frames = 40;
  std::vector<bench::BenchCase> cases = bench::DefaultCases(data, frames);
  if (args.quick) {
    // A few short sequences: one recorded session (when the data is here), a scripted sphere
    // and the textured box.
    std::vector<bench::BenchCase> quick;
    for (const auto& c : cases) {
      if (c.name == "004-sphere" || c.name == "sphere-turn" || c.name == "textured-box-turn")
        quick.push_back(c);
    }
    cases = quick;
  }
  if (!args.cases.empty()) {
    std::vector<bench::BenchCase> chosen;
    for (const std::string& name : args.cases) {
      bool found = false;
      for (const auto& c : cases) {
        if (c.name == name) {
          chosen.push_back(c);
          found = true;
        }
      }
      if (!found) throw std::invalid_argument("--case " + name + ": no such case");
    }
    cases = chosen;
  }
  const std::vector<bench::Method> methods = bench::DefaultMethods(sweep);

  bench::RunOptions run;
  run.work =
      args.work.empty() ? fs::temp_directory_path() / "inhandscan-bench" : fs::path(args.work);
  run.open3d = !args.no_open3d;
  // Each Open3D baseline runs in a child process: this program, started anew.
  run.open3d_program = fs::read_symlink("/proc/self/exe");
  run.quiet = args.quiet;
  if (!args.no_app) run.app = args.app.empty() ? fs::path(IHS_INHANDSCAN_PATH) : fs::path(args.app);
  if (!run.app.empty() && !fs::exists(run.app))
    throw ihs::InputError(run.app.string() + ": no such program (build it, or --no-app)");
  if (!args.quiet && run.open3d && !bench::Open3dAvailable())
    std::fprintf(stderr, "inhandscan-bench: built without Open3D; its baseline is left out\n");

  std::vector<bench::CaseResult> results;
  for (const auto& c : cases) {
    if (!args.quiet) std::fprintf(stderr, "inhandscan-bench: %s...\n", c.name.c_str());
    results.push_back(bench::RunCase(c, methods, run));
  }
  bench::ReportOptions report;
  report.out = args.out;
  report.command = args.command;
  report.sweep = sweep;
  report.mesh_pictures = !args.no_pictures;
  const std::string text = bench::WriteReport(results, methods, report);
  if (!args.quiet) std::fputs(text.c_str(), stdout);
  std::printf("report: %s\n", (fs::path(args.out) / "benchmarks.md").c_str());
  return ihs::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  ihs::KeepFreedMemoryForReuse();
  ihs::render::UseMachineIndependentRasteriser();
  CLI::App app{
      "The benchmark report: generator sequences scanned by ours and the baselines, measured "
      "against the ground truth (the paper's Table 1 and 2, joint error, Chamfer, speed, the γt "
      "sweep, trajectories, mesh pictures).",
      "inhandscan-bench"};
  app.footer(ihs::ExitCodesHelp());
  app.set_version_flag("--version", std::string("inhandscan-bench ") + IHS_VERSION);
  Args args;
  app.add_option("--data", args.data,
                 "the real hand data folder (hand-iccv15, with sequences/): the paper's four "
                 "sessions; without it only the scripted cases run");
  app.add_option("--out", args.out, "writes OUT/benchmarks.md and OUT/benchmarks/")
      ->capture_default_str();
  app.add_option("--work", args.work,
                 "where sequences are rendered (kept and reused) and scans written (default: "
                 "TMPDIR/inhandscan-bench)");
  app.add_option("--frames", args.frames, "at most this many frames per case (0: all)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--case", args.cases,
                 "only these cases (001-water-bottle, 002-bowling-pin, 003-small-bottle, "
                 "004-sphere, 004-sphere-whole, sphere-turn, bowling-pin-turn, "
                 "water-bottle-turn, small-bottle-turn, cube-turn, box-turn, textured-box-turn)");
  app.add_flag("--quick", args.quick,
               "a few short sequences (40 frames: a recorded sphere when --data is given, a "
               "scripted sphere, the textured box), for CI");
  app.add_flag("--no-open3d", args.no_open3d, "leave out the Open3D baselines");
  app.add_option("--app", args.app, "the inhandscan program to time (default: the one built)");
  app.add_flag("--no-app", args.no_app, "do not time the application");
  app.add_flag("--no-pictures", args.no_pictures, "no mesh pictures (needs no OSMesa)");
  app.add_flag("-q,--quiet", args.quiet, "print only the report's path");
  // Hidden (no group): how the benchmark runs an Open3D baseline in a process of its own.
  app.add_option("--open3d-peer", args.peer)->group("");
  app.add_option("--peer-case", args.peer_case)->group("");
  app.add_option("--peer-out", args.peer_out)->group("");
  if (const auto done = ihs::ParseCommandLine(app, argc, argv)) return *done;
  // The command quoted in the report: the wrapper's when it says so (tools/bench.sh), else ours.
  std::ostringstream command;
  command << "inhandscan-bench";
  for (int i = 1; i < argc; ++i) command << " " << argv[i];
  const char* wrapper = std::getenv("IHS_BENCH_COMMAND");
  args.command = wrapper && *wrapper ? wrapper : command.str();
  return ihs::RunReportingErrors("inhandscan-bench", [&] {
    ihs::SetUpLogging(ihs::ParseLogLevel("warn"), args.quiet);
    return args.peer.empty() ? Run(args) : RunPeer(args);
  });
}

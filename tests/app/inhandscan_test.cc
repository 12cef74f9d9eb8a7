// The inhandscan executable as a user drives it: help and exit codes, options and config files,
// a missing input or device, and signals during a replay (SIGUSR1 exports and the scan goes on;
// SIGINT and SIGHUP finish, export and exit 0).

#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "core/mesh_io.h"
#include "core/trajectory_io.h"
#include "sensor/oni_writer.h"
#include "sensor/tum_directory.h"
#include "tests/frame_fixtures.h"
#include "tests/test_util.h"
#include "tools/synth/sequence.h"

namespace ihs {
namespace {

namespace fs = std::filesystem;

test::CommandResult RunApp(const std::string& arguments) {
  return test::RunCommand(std::string(IHS_APP) + " " + arguments);
}

int Lines(const std::string& text) {
  return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

TEST(InhandscanTest, HelpListsTheSubcommandsAndExitCodes) {
  const auto help = RunApp("--help");
  EXPECT_EQ(help.exit_code, 0);
  for (const char* word : {"live", "replay", "record", "devices", "config", "--config", "--set"}) {
    EXPECT_NE(help.out.find(word), std::string::npos) << word;
  }
  EXPECT_NE(help.out.find("5"), std::string::npos);
  EXPECT_NE(help.out.find("partial"), std::string::npos) << help.out;
  const auto version = RunApp("--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.out.find(IHS_VERSION), std::string::npos);
}

// Each subcommand's help lists the global options, which may stand before or after it: --set
// on both sides adds up, and a bad --log-level on either side is refused.
TEST(InhandscanTest, SubcommandHelpListsTheGlobalOptionsThatMayFollowIt) {
  for (const char* command : {"live", "replay", "record", "devices", "config"}) {
    const auto help = RunApp(std::string(command) + " --help");
    EXPECT_EQ(help.exit_code, 0) << command << ": " << help.err;
    const size_t global = help.out.find("Global options");
    ASSERT_NE(global, std::string::npos) << command << ": " << help.out;
    for (const char* option : {"--log-level", "--quiet", "--config", "--set", "--version"}) {
      EXPECT_NE(help.out.find(option, global), std::string::npos) << command << ": " << option;
    }
    EXPECT_NE(help.out.find("Exit codes:", global), std::string::npos) << help.out;
  }
  EXPECT_EQ(RunApp("--help").out.find("Global options"), std::string::npos);
  const auto both = RunApp("--set mesh.poisson_depth=7 config --set fusion.tsdf.resolution=128");
  ASSERT_EQ(both.exit_code, 0) << both.err;
  EXPECT_NE(both.out.find("mesh.poisson_depth = 7\n"), std::string::npos);
  EXPECT_NE(both.out.find("fusion.tsdf.resolution = 128\n"), std::string::npos);
  for (const char* arguments : {"--log-level loud config", "config --log-level loud"}) {
    const auto run = RunApp(arguments);
    EXPECT_EQ(run.exit_code, 2) << arguments;
    EXPECT_NE(run.err.find("--log-level"), std::string::npos) << arguments << ": " << run.err;
  }
}

TEST(InhandscanTest, ConfigPrintsEveryOptionAsAFileItReadsBack) {
  test::TempDir dir;
  const auto config = RunApp("config --set fusion.pairwise.contact_weight=5");
  ASSERT_EQ(config.exit_code, 0) << config.err;
  EXPECT_NE(config.out.find("fusion.pairwise.contact_weight = 5\n"), std::string::npos);
  EXPECT_NE(config.out.find("tracker.fit.collision_weight = 10\n"), std::string::npos);
  EXPECT_NE(config.out.find("# gamma_t"), std::string::npos);
  test::WriteBytes(dir / "scan.conf", config.out);
  const auto reread = RunApp("config --config " + (dir / "scan.conf").string());
  ASSERT_EQ(reread.exit_code, 0) << reread.err;
  EXPECT_EQ(reread.out, config.out);
}

TEST(InhandscanTest, BadUsageGetsOneLineAndCodeTwo) {
  for (const char* arguments :
       {"", "replay", "frobnicate", "config --set fusion.nonsense=1",
        "config --set fusion.tsdf.resolution=many", "config --set pipeline.queue_capacity=0",
        "replay x.oni --format gif", "config --config /nonexistent/inhandscan.conf",
        // A recording's depth is in mm: a depth scale is for image folders only.
        "replay x.oni --depth-scale 1000", "replay folder --depth-scale 0"}) {
    const auto run = RunApp(arguments);
    const int expected = std::string(arguments).find("nonexistent") != std::string::npos ? 3 : 2;
    EXPECT_EQ(run.exit_code, expected) << arguments << ": " << run.err;
    EXPECT_EQ(Lines(run.err), 1) << arguments << ": " << run.err;
  }
}

// The camera's intrinsics given in place of a recording's own: a file of the wrong image size or
// not an intrinsics file is refused in one line (code 3) before anything is scanned.
TEST(InhandscanTest, GivenIntrinsicsMustFitTheFramesAndParse) {
  test::TempDir dir;
  sensor::OniWriterOptions options;
  options.intrinsics = CameraIntrinsics::Carmine109().Scaled(160, 120);
  sensor::OniWriter writer(dir / "a.oni", options);
  for (const Frame& frame : test::MakePatternFrames(2, 160, 120)) writer.Write(frame);
  writer.Close();
  test::WriteBytes(dir / "vga.txt", "525 525 319.5 239.5 640 480\n");
  test::WriteBytes(dir / "bad.json", R"({"width": 160})");
  for (const char* file : {"vga.txt", "bad.json"}) {
    const auto run = RunApp("replay " + (dir / "a.oni").string() + " --intrinsics " +
                            (dir / file).string() + " --out " + (dir / "out").string());
    EXPECT_EQ(run.exit_code, 3) << file << ": " << run.err;
    EXPECT_EQ(Lines(run.err), 1) << file << ": " << run.err;
    EXPECT_NE(run.err.find(file == std::string("vga.txt") ? "640x480" : "bad.json"),
              std::string::npos)
        << run.err;
  }
}

// A mistyped subcommand is named with the one it was meant to be.
TEST(InhandscanTest, AMistypedSubcommandGetsASuggestion) {
  const auto run = RunApp("replya x.oni");
  EXPECT_EQ(run.exit_code, 2) << run.err;
  EXPECT_EQ(Lines(run.err), 1) << run.err;
  EXPECT_NE(run.err.find("did you mean 'replay'?"), std::string::npos) << run.err;
}

// `cmake --install` puts the scanner and its tools in a prefix's bin/, and they run from there.
TEST(InhandscanTest, InstalledToAPrefixItRunsFromThere) {
  test::TempDir prefix;
  const auto install = test::RunCommand(std::string("cmake --install '") + IHS_BUILD_DIR +
                                        "' --prefix '" + prefix.path().string() + "'");
  ASSERT_EQ(install.exit_code, 0) << install.err;
  for (const char* tool :
       {"inhandscan", "inhandscan-frames", "inhandscan-mesh", "inhandscan-measure",
        "inhandscan-scan", "inhandscan-track", "inhandscan-synth"}) {
    EXPECT_TRUE(fs::is_regular_file(prefix / "bin" / tool)) << tool;
  }
  const auto version = test::RunCommand((prefix / "bin" / "inhandscan").string() + " --version");
  EXPECT_EQ(version.exit_code, 0) << version.err;
  EXPECT_NE(version.out.find(IHS_VERSION), std::string::npos) << version.out;
  const auto config = test::RunCommand((prefix / "bin" / "inhandscan").string() + " config");
  EXPECT_EQ(config.exit_code, 0) << config.err;
  EXPECT_NE(config.out.find("fusion.tsdf.resolution = 256"), std::string::npos);
}

TEST(InhandscanTest, AMissingRecordingIsCodeThree) {
  test::TempDir dir;
  const auto run =
      RunApp("replay " + (dir / "missing.oni").string() + " --out " + (dir / "out").string());
  EXPECT_EQ(run.exit_code, 3) << run.err;
  EXPECT_EQ(Lines(run.err), 1) << run.err;
  EXPECT_NE(run.err.find("missing.oni"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "out")) << "an empty output folder was left behind";
}

TEST(InhandscanTest, LiveWithoutACameraSaysSoWithCodeFour) {
  test::TempDir dir;
  const auto run = RunApp("live --no-window --out " + (dir / "out").string());
  if (run.exit_code == 0) GTEST_SKIP() << "a camera is attached";
  EXPECT_EQ(run.exit_code, 4) << run.err;
  EXPECT_NE(run.err.find("camera"), std::string::npos) << run.err;
  EXPECT_EQ(Lines(run.err), 1) << run.err;
  const auto devices = RunApp("devices");
  EXPECT_EQ(devices.exit_code, 4) << devices.err;
  EXPECT_NE(devices.out.find("OpenNI2"), std::string::npos) << devices.out;
}

// A scene without a hand, or with a hand holding nothing, ends the same way whichever recording
// shows it: no frame is fused, code 5, one line that says so and names what was missing.
void ExpectNothingScannedForWantOf(const fs::path& recording, const fs::path& out,
                                   const std::string& missing) {
  const auto run = RunApp("replay " + recording.string() + " --out " + out.string() +
                          " --set pipeline.preview_every=0 -q");
  EXPECT_EQ(run.exit_code, 5) << run.err;
  EXPECT_NE(run.err.find("nothing was scanned"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find(missing + " ×"), std::string::npos) << run.err;
  EXPECT_EQ(Lines(run.err), 1) << run.err;
  EXPECT_FALSE(fs::exists(out / "mesh.ply"));
}

TEST(InhandscanTest, RecordingsWithoutAHandOrWithAnEmptyOneScanNothingAndSaySo) {
  test::TempDir dir;
  // A generated ball turning in front of the camera, no hand anywhere.
  sensor::OniWriterOptions options;
  {
    sensor::OniWriter writer(dir / "ball.oni", options);
    for (int i = 0; i < 8; ++i) {
      Frame frame = test::RenderEllipsoid(
          options.intrinsics,
          Rigid3::Translation({0, 0, 550}) * Rigid3::FromAxisAngle({0, 1, 0}, i * 0.05),
          {35, 35, 35});
      frame.index = i;
      frame.depth_timestamp_us = i * 33333;
      frame.color_timestamp_us = frame.depth_timestamp_us;
      writer.Write(frame);
    }
    writer.Close();
  }
  // Into a folder an earlier scan wrote: its mesh must not stay beside the new stats.json.
  fs::create_directories(dir / "ball" / "preview");
  for (const char* name : {"mesh.ply", "stats.json", "preview/000030.png", "notes.txt"})
    test::WriteBytes(dir / "ball" / name, "from an earlier scan");
  // A mistyped input does not cost the earlier scan.
  const auto missing =
      RunApp("replay " + (dir / "bal.oni").string() + " --out " + (dir / "ball").string() + " -q");
  EXPECT_EQ(missing.exit_code, 3) << missing.err;
  EXPECT_EQ(test::ReadFileString(dir / "ball" / "mesh.ply"), "from an earlier scan");
  ExpectNothingScannedForWantOf(dir / "ball.oni", dir / "ball", "no hand");
  EXPECT_FALSE(fs::exists(dir / "ball" / "preview" / "000030.png"));
  EXPECT_NE(test::ReadFileString(dir / "ball" / "stats.json"), "from an earlier scan");
  EXPECT_TRUE(fs::exists(dir / "ball" / "notes.txt"));  // Not a scan's file: left alone.
  // A hand grasping and turning nothing: the same answer.
  synth::SequenceOptions empty;
  empty.object = "cube";
  empty.empty_hand = true;
  empty.scripted.frames = 60;
  empty.last_frame = 19;
  empty.write_tum = false;
  synth::GenerateSequence(empty, dir / "empty");
  ExpectNothingScannedForWantOf(dir / "empty" / "sequence.oni", dir / "empty-out",
                                "too few object points");
  // The real Kinect recording of a room.
  const fs::path real = test::KinectRecording();
  if (real.empty()) GTEST_SKIP() << "no shared data: the real recording's case is left out";
  ExpectNothingScannedForWantOf(real, dir / "room", "no hand");
}

class InhandscanSignalTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir();
    synth::SequenceOptions options;  // 90 frames: 3 s at the recorded pace.
    options.scripted.frames = 90;
    options.write_tum = false;
    synth::GenerateSequence(options, dir_->path());
  }
  static void TearDownTestSuite() { delete dir_; }

  // Replays at the recorded pace, sends `signal` `seconds` after the scan started (its output
  // folder appears once the signal handlers are in place: a signal sent earlier, while a loaded
  // machine is still starting the program, would find none), and waits for the exit.
  static test::CommandResult ReplayWithSignal(const fs::path& out, const std::string& signal,
                                              double seconds) {
    const std::string command =
        std::string(IHS_APP) + " replay --realtime " + (*dir_ / "sequence.oni").string() +
        " --out " + out.string() + " --set pipeline.preview_every=0 & pid=$!; i=0; while [ ! -d " +
        out.string() + " ] && [ $i -lt 600 ]; do sleep 0.1; i=$((i+1)); done; sleep " +
        std::to_string(seconds) + "; kill -" + signal + " $pid; wait $pid";
    return test::RunCommand("sh -c '" + command + "'");
  }

  static test::TempDir* dir_;
};

test::TempDir* InhandscanSignalTest::dir_ = nullptr;

TEST_F(InhandscanSignalTest, SigusrOneExportsAndTheReplayGoesOn) {
  const test::TempDir dir;
  const fs::path out = dir / "scan";  // Made by the program.
  const auto run = ReplayWithSignal(out, "USR1", 1.5);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("export requested"), std::string::npos) << run.err;
  // The requested export and the final one.
  size_t exports = 0;
  for (size_t at = run.err.find("exported "); at != std::string::npos;
       at = run.err.find("exported ", at + 1)) {
    ++exports;
  }
  EXPECT_EQ(exports, 2u) << run.err;
  const auto stats = nlohmann::json::parse(test::ReadFileString(out / "stats.json"));
  EXPECT_EQ(stats["summary"]["end_reason"], "end of stream");
  // At the recorded pace every frame is read (a late reader makes the pipeline drop frames, not
  // the recording's player skip them).
  EXPECT_EQ(stats["summary"]["captured_frames"].get<int>(), 90);
  EXPECT_EQ(stats["summary"]["dropped_frames"]["missed_by_source"].get<int>(), 0);
  EXPECT_TRUE(ReadMesh(out / "mesh.ply").IsWatertight());
}

TEST_F(InhandscanSignalTest, ReplayWritesEveryOutputAndTheFormatsAskedFor) {
  test::TempDir out;
  const auto run =
      RunApp("replay " + (*dir_ / "sequence.oni").string() + " --out " + out.path().string() +
             " --format obj,stl --set pipeline.max_frames=31 --quiet");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.out, "mesh: " + (out / "mesh.ply").string() + "\n");
  const TriangleMesh ply = ReadMesh(out / "mesh.ply");
  EXPECT_TRUE(ply.IsWatertight());
  EXPECT_EQ(ReadMesh(out / "mesh.obj").faces.size(), ply.faces.size());
  EXPECT_EQ(ReadMesh(out / "mesh.stl").faces.size(), ply.faces.size());
  for (const char* name :
       {"mesh_tsdf.ply", "trajectory.txt", "hand_joints.csv", "hand_poses.csv", "stats.json"}) {
    EXPECT_TRUE(fs::is_regular_file(out / name)) << name;
  }
  // A preview every 30 fused frames.
  EXPECT_FALSE(fs::is_empty(out / "preview"));
}

// The pixels of `image`'s bottom `rows` rows coloured as a state that is well (green).
int GreenPixelsAtTheBottom(const cv::Mat& bgr, int rows) {
  int green = 0;
  for (int v = std::max(0, bgr.rows - rows); v < bgr.rows; ++v) {
    for (int u = 0; u < bgr.cols; ++u) {
      const cv::Vec3b p = bgr.at<cv::Vec3b>(v, u);
      green += p[1] > 180 && p[0] < 150 && p[2] < 150;
    }
  }
  return green;
}

// --screenshot saves the screen as the window shows it: composed off-screen without a window,
// read back from the window with one (on a virtual display). Both show the states in colour
// (here "tracked" and "registered", green) in the status bar.
TEST_F(InhandscanSignalTest, ScreenshotsWithAndWithoutAWindow) {
  test::TempDir dir;
  const std::string replay = "replay " + (*dir_ / "sequence.oni").string() +
                             " --set pipeline.max_frames=31 --quiet --screenshot ";
  const auto headless =
      RunApp(replay + (dir / "screen.png").string() + " --out " + (dir / "a").string());
  ASSERT_EQ(headless.exit_code, 0) << headless.err;
  const cv::Mat screen = cv::imread((dir / "screen.png").string());
  ASSERT_FALSE(screen.empty()) << headless.err;
  EXPECT_EQ(screen.cols, 2 * 640);  // Two panels of the camera's size and a status bar.
  EXPECT_GT(screen.rows, 480);
  EXPECT_GT(GreenPixelsAtTheBottom(screen, screen.rows - 480), 20);

  test::VirtualDisplay display(1280, 1024);
  if (!display.ok()) GTEST_SKIP() << "no Xvfb (Debian package xvfb) to open a window on";
  const auto windowed = test::RunCommand("DISPLAY=" + display.name() + " " + IHS_APP + " " +
                                         replay + (dir / "window.png").string() + " --window" +
                                         " --out " + (dir / "b").string());
  ASSERT_EQ(windowed.exit_code, 0) << windowed.err;
  EXPECT_EQ(windowed.err.find("scanning without a window"), std::string::npos) << windowed.err;
  const cv::Mat window = cv::imread((dir / "window.png").string());
  ASSERT_FALSE(window.empty()) << windowed.err;
  EXPECT_EQ(window.size(), screen.size()) << "the window opens at the screen's size";
  EXPECT_GT(GreenPixelsAtTheBottom(window, window.rows / 10), 20);
}

// The output folder records the run: the options in effect (flags and --set) as options.conf,
// which --config reads back to make the same mesh; stats.json names the version, commit, input
// and camera, camera_intrinsic.json holds it for Open3D; hand_poses.csv names every column; the
// trajectory in TUM's metres is the millimetre one's inverse.
TEST_F(InhandscanSignalTest, TheRunRecordReadBackByConfigMakesTheSameMesh) {
  test::TempDir dir;
  const std::string input = (*dir_ / "sequence.oni").string();
  const auto first = RunApp("replay " + input + " --out " + (dir / "first").string() +
                            " --set pipeline.max_frames=31 --set fusion.pairwise.contact_weight=12"
                            " --set pipeline.preview_every=0 --quiet");
  ASSERT_EQ(first.exit_code, 0) << first.err;
  const std::string options = test::ReadFileString(dir / "first" / "options.conf");
  EXPECT_NE(options.find("\nfusion.pairwise.contact_weight = 12\n"), std::string::npos);
  EXPECT_NE(options.find("\npipeline.max_frames = 31\n"), std::string::npos);
  const auto run = nlohmann::json::parse(test::ReadFileString(dir / "first" / "stats.json"));
  const auto& record = run["summary"]["run"];
  EXPECT_EQ(record["version"], IHS_VERSION);
  EXPECT_FALSE(record["commit"].get<std::string>().empty());
  EXPECT_NE(record["input"].get<std::string>().find(input), std::string::npos) << record;
  EXPECT_EQ(record["intrinsics"]["fx"].get<double>(), 525.0);
  EXPECT_EQ(record["intrinsics"]["width"].get<int>(), 640);

  const auto again =
      RunApp("replay " + input + " --out " + (dir / "again").string() + " --config " +
             (dir / "first" / "options.conf").string() + " --trajectory-format tum-m --quiet");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(test::ReadFileString(dir / "again" / "mesh.ply"),
            test::ReadFileString(dir / "first" / "mesh.ply"));
  const CameraIntrinsics camera =
      sensor::ReadIntrinsicsFile(dir / "first" / "camera_intrinsic.json");
  EXPECT_EQ(camera.fx, record["intrinsics"]["fx"].get<double>());
  EXPECT_EQ(camera.width, record["intrinsics"]["width"].get<int>());

  const auto millimetres = ReadTumTrajectory(dir / "first" / "trajectory.txt");
  const auto metres = ReadTumTrajectory(dir / "again" / "trajectory.txt");
  ASSERT_EQ(millimetres.size(), metres.size());
  ASSERT_GT(millimetres.size(), 20u);
  for (size_t i = 0; i < metres.size(); ++i) {
    EXPECT_NEAR(metres[i].time_s, millimetres[i].time_s, 1e-6);
    const Rigid3 object_from_cam = millimetres[i].transform.Inverse();
    // The files hold 6 decimals of a metre (1 µm) and 9 of the quaternion.
    EXPECT_LT((metres[i].transform.translation() * 1000 - object_from_cam.translation()).norm(),
              0.01)
        << i;
    EXPECT_LT((metres[i].transform.rotation() - object_from_cam.rotation()).norm(), 1e-6) << i;
  }

  std::istringstream poses(test::ReadFileString(dir / "first" / "hand_poses.csv"));
  std::string comment, header, row;
  ASSERT_TRUE(std::getline(poses, comment) && std::getline(poses, header) &&
              std::getline(poses, row));
  EXPECT_EQ(header.find("angles..."), std::string::npos) << header;
  EXPECT_NE(header.find(",RFing.3_1.y,"), std::string::npos) << header;
  EXPECT_EQ(std::count(header.begin(), header.end(), ','), std::count(row.begin(), row.end(), ','));
}

// SIGINT (Ctrl-C) and SIGHUP (the terminal closed) both end the scan with its model saved.
TEST_F(InhandscanSignalTest, SigintAndSighupFinishExportAndExitZero) {
  for (const char* signal : {"INT", "HUP"}) {
    const test::TempDir dir;
    const fs::path out = dir / "scan";  // Made by the program.
    const auto run = ReplayWithSignal(out, signal, 1.5);
    ASSERT_EQ(run.exit_code, 0) << signal << ": " << run.err;
    EXPECT_NE(run.out.find("mesh: "), std::string::npos) << signal << ": " << run.out;
    const auto stats = nlohmann::json::parse(test::ReadFileString(out / "stats.json"));
    EXPECT_EQ(stats["summary"]["end_reason"], "stopped") << signal;
    EXPECT_LT(stats["summary"]["captured_frames"].get<int>(), 90) << signal;
    EXPECT_FALSE(ReadMesh(out / "mesh.ply").Empty()) << signal;
  }
}

}  // namespace
}  // namespace ihs

// inhandscan-scan on a short generated sequence: a sphere turned a full round in the hand is
// scanned into a watertight mesh of its size; files written; bad input gets one-line errors.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "core/mesh_io.h"
#include "core/trajectory_io.h"
#include "fusion/measure.h"
#include "tests/test_util.h"
#include "tools/synth/sequence.h"

namespace ihs {
namespace {

test::CommandResult RunTool(const std::string& arguments) {
  return test::RunCommand(std::string(IHS_SCAN_TOOL) + " " + arguments);
}

TEST(ScanToolTest, AShortSequenceOfASphereScansToItsSize) {
  test::TempDir dir;
  synth::SequenceOptions options;  // The sphere (Ø70), a scripted full turn, sensor noise.
  options.scripted.frames = 90;
  options.write_tum = false;
  synth::GenerateSequence(options, dir / "seq");
  const auto run = RunTool((dir / "seq" / "sequence.oni").string() + " --out " +
                           (dir / "out").string() + " --gt " + (dir / "seq" / "gt").string());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("pairwise registration error"), std::string::npos) << run.out;

  // The diameter on the surface that was seen (as the paper's measures are taken, see
  // tools/evaluation.h), the volume on the watertight mesh.
  const TriangleMesh mesh = ReadMesh(dir / "out" / "mesh.ply");
  EXPECT_TRUE(mesh.IsWatertight());
  EXPECT_TRUE(mesh.HasColors());
  const fusion::RevolutionMeasures measures =
      fusion::MeasureRevolution(ReadMesh(dir / "out" / "mesh_tsdf.ply"));
  std::printf("sphere: diameter %.2f mm, volume %.0f mm³\n", measures.widest_diameter_mm,
              mesh.Volume());
  EXPECT_NEAR(measures.widest_diameter_mm, 70.0, 2.0);
  // The volume of a sphere a quarter of which was never seen (the 90-frame turn): measured
  // −6.0 % for this sequence on an AMD EPYC machine (within 5 % where it was written), −6.3,
  // +0.6, +0.9, −2.1, −1.9 % for seeds 2-6 (inhandscan-synth --seed S --scripted-frames 90).
  EXPECT_NEAR(mesh.Volume() / (4.0 / 3.0 * M_PI * 35 * 35 * 35), 1.0, 0.08);

  const auto trajectory = ReadTumTrajectory(dir / "out" / "trajectory.txt");
  // TUM: what it is, the column names once, then a pose per registered frame.
  const std::string trajectory_text = test::ReadFileString(dir / "out" / "trajectory.txt");
  const std::string header =
      "# cam_from_object of the scanned object (mm), registered frames only\n"
      "# timestamp tx ty tz qx qy qz qw\n";
  EXPECT_EQ(trajectory_text.compare(0, header.size(), header), 0) << trajectory_text.substr(0, 200);
  EXPECT_EQ(std::count(trajectory_text.begin(), trajectory_text.end(), '#'), 2);
  const auto stats = nlohmann::json::parse(test::ReadFileString(dir / "out" / "stats.json"));
  EXPECT_EQ(stats["summary"]["frames"], 90);
  EXPECT_EQ(stats["frames"].size(), 90u);
  EXPECT_EQ(trajectory.size(), stats["summary"]["registered_frames"].get<size_t>());
  EXPECT_GT(trajectory.size(), 80u);
  EXPECT_TRUE(stats["summary"]["evaluation"].contains("chamfer_mm"));
}

// inhandscan-scan's summary evaluation of `sequence` with `extra` options.
nlohmann::json ScanEvaluation(const std::filesystem::path& sequence,
                              const std::filesystem::path& out, const std::string& extra) {
  const auto run = RunTool((sequence / "sequence.oni").string() + " --out " + out.string() +
                           " --gt " + (sequence / "gt").string() + " " + extra);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  const auto stats = nlohmann::json::parse(test::ReadFileString(out / "stats.json"));
  nlohmann::json evaluation = stats["summary"]["evaluation"];
  evaluation["hidden_frames"] = stats["summary"]["hidden_frames"];
  return evaluation;
}

TEST(ScanToolTest, ABoxHiddenBehindTheHandIsTrackedNotWrittenIntoItsModel) {
  // A box turned a full turn by a hand in front of it (inhandscan-synth --object box --seed
  // 7495 --turns 1 --scripted-frames 240 --tilt-deg 12 --distance-mm 650): in frames 18-56 the
  // hand covers most of it, and with its red checkered face taken for skin specks (the
  // segmentation's print rule off) only 250-1000 of its 3000 points were left. Integrated, those
  // frames wrote a box turned 20-67° into the model and every later frame aligned to it; tracked
  // only, the model stays whole and the box is found against it where it shows itself again.
  test::TempDir dir;
  synth::SequenceOptions options;
  options.object = "box";
  options.seed = options.scripted.seed = 7495;
  options.scripted.turns = 1.0;
  options.scripted.frames = 240;
  options.scripted.tilt_deg = 12;
  options.scripted.distance_mm = 650;
  options.write_tum = false;
  synth::GenerateSequence(options, dir / "seq");
  // By default; and without the print rule, with the hold (fusion/hidden_span.h) and without.
  const std::string no_print = "--set tracker.segmentation.speck_enclosed_share=0";
  const nlohmann::json scan = ScanEvaluation(dir / "seq", dir / "default", "");
  const nlohmann::json held = ScanEvaluation(dir / "seq", dir / "held", no_print);
  // Every frame written: the see-through check off too (it holds out ten of the frames that
  // align to the corrupted model: 63.9° at the end).
  const nlohmann::json written = ScanEvaluation(
      dir / "seq", dir / "written",
      no_print + " --set fusion.hidden.share=0 --set fusion.see_through.max_share=0");
  auto sides = [](const nlohmann::json& evaluation) {
    double worst = 0;
    for (const auto& side : evaluation["dimensions_watertight"]) {
      worst =
          std::max(worst, std::abs(side["scan_mm"].get<double>() - side["truth_mm"].get<double>()));
    }
    return worst;
  };
  auto print = [&](const char* name, const nlohmann::json& evaluation) {
    std::printf(
        "%s: %d frames held out; at the end %.1f° off, mesh.ply's sides within %.1f mm, "
        "Chamfer %.2f mm\n",
        name, evaluation["hidden_frames"].get<int>(),
        evaluation["rotation_error_deg"]["final"].get<double>(), sides(evaluation),
        evaluation["chamfer_mm"].get<double>());
  };
  print("box behind the hand", scan);
  print("print rule off, held", held);
  print("print rule off, integrated", written);
  // Measured: by default 56 frames held out, 0.4° off, sides within 2.1 mm, Chamfer 0.80 mm;
  // print rule off: 71 held out, 0.4°, 11.1 mm, 2.18 mm (66.9°, 42.3 mm, 7.11 mm integrated).
  for (const nlohmann::json* evaluation : {&scan, &held}) {
    EXPECT_GT((*evaluation)["hidden_frames"].get<int>(), 30);
    EXPECT_LT((*evaluation)["rotation_error_deg"]["final"].get<double>(), 5.0);
    EXPECT_LT((*evaluation)["chamfer_mm"].get<double>(), 3.0);
  }
  EXPECT_LT(sides(scan), 5.0);
  EXPECT_LT(sides(held), 15.0);
  EXPECT_EQ(written["hidden_frames"].get<int>(), 0);
  const double held_deg = held["rotation_error_deg"]["final"];
  EXPECT_GT(written["rotation_error_deg"]["final"].get<double>(), 4 * held_deg);
}

TEST(ScanToolTest, BadInputAndOptionsGetOneLineErrors) {
  test::TempDir dir;
  const auto missing = RunTool((dir / "nothing.oni").string() + " --out " + (dir / "o").string());
  EXPECT_EQ(missing.exit_code, 3) << missing.err;
  EXPECT_EQ(std::count(missing.err.begin(), missing.err.end(), '\n'), 1) << missing.err;
  const auto bad_gamma = RunTool("x.oni --gamma-t -1 --out " + (dir / "o").string());
  EXPECT_EQ(bad_gamma.exit_code, 2);
  const auto contradiction =
      RunTool("x.oni --contacts-only --gamma-t 0 --out " + (dir / "o").string());
  EXPECT_EQ(contradiction.exit_code, 2);
  EXPECT_NE(contradiction.err.find("--contacts-only"), std::string::npos);
  // --set takes inhandscan's options by name, checked before the input is opened.
  const auto unknown = RunTool("x.oni --set fusion.nothing=1 --out " + (dir / "o").string());
  EXPECT_EQ(unknown.exit_code, 2) << unknown.err;
  EXPECT_NE(unknown.err.find("fusion.nothing"), std::string::npos) << unknown.err;
  const auto negative =
      RunTool("x.oni --set fusion.icp.anchor_share=-1 --out " + (dir / "o").string());
  EXPECT_EQ(negative.exit_code, 2) << negative.err;
  EXPECT_EQ(std::count(negative.err.begin(), negative.err.end(), '\n'), 1) << negative.err;
}

}  // namespace
}  // namespace ihs

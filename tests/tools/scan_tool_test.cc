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

// inhandscan-measure on a true object's mesh: the paper's measures, JSON out, bad input.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "core/mesh_io.h"
#include "tests/test_util.h"
#include "tools/synth/objects.h"

namespace ihs {
namespace {

test::CommandResult RunTool(const std::string& arguments) {
  return test::RunCommand(std::string(IHS_MEASURE_TOOL) + " " + arguments);
}

TEST(MeasureToolTest, ABowlingPinMeasuresToThePapersDimensions) {
  test::TempDir dir;
  const TriangleMesh pin = synth::MakeLatheMesh(
      synth::ResampleProfile(synth::PaperObjectProfile("bowling-pin"), 0.5), 256);
  WriteMesh(dir / "pin.ply", pin);
  const auto run = RunTool((dir / "pin.ply").string() + " --object bowling-pin --json " +
                           (dir / "m.json").string());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("head diameter"), std::string::npos) << run.out;
  const auto json = nlohmann::json::parse(test::ReadFileString(dir / "m.json"));
  ASSERT_EQ(json["dimensions"].size(), 3u);
  for (const auto& row : json["dimensions"]) {
    EXPECT_NEAR(row["scan_mm"].get<double>(), row["truth_mm"].get<double>(), 0.5) << row;
  }
  EXPECT_NEAR(json["height_mm"].get<double>(), 268, 0.5);
  EXPECT_NEAR(json["volume_error"].get<double>(), 0.0, 0.002);
}

TEST(MeasureToolTest, BadInputGetsOneLineErrors) {
  test::TempDir dir;
  const auto missing = RunTool((dir / "none.ply").string());
  EXPECT_EQ(missing.exit_code, 3) << missing.err;
  EXPECT_EQ(std::count(missing.err.begin(), missing.err.end(), '\n'), 1) << missing.err;
  WriteMesh(dir / "ball.ply", synth::MakeLatheMesh(synth::PaperObjectProfile("sphere"), 64));
  const auto unknown = RunTool((dir / "ball.ply").string() + " --object teapot");
  EXPECT_EQ(unknown.exit_code, 2) << unknown.err;
  EXPECT_NE(unknown.err.find("teapot"), std::string::npos);
}

}  // namespace
}  // namespace ihs

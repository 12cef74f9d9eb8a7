// End-to-end tests of the inhandscan-mesh executable: output, exit codes, one-line errors.

#include <gtest/gtest.h>

#include <string>

#include "core/mesh_io.h"
#include "tests/mesh_fixtures.h"
#include "tests/test_util.h"

namespace ihs {
namespace {

struct ToolRun {
  int exit_code = -1;
  std::string output;  // stdout and stderr together.
};

ToolRun RunTool(const std::string& arguments) {
  const test::CommandResult result = test::RunCommand(std::string(IHS_MESH_TOOL) + " " + arguments);
  return {result.exit_code, result.out + result.err};
}

int LineCount(const std::string& text) {
  int lines = 0;
  for (char c : text) lines += c == '\n';
  return lines;
}

TEST(MeshToolTest, InfoReportsCountsSizeAndVolume) {
  test::TempDir dir;
  WriteMesh(dir / "cube.ply", test::MakeCube(20));
  const ToolRun run = RunTool("info " + (dir / "cube.ply").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("vertices: 8\n"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("faces: 12\n"), std::string::npos);
  EXPECT_NE(run.output.find("size_mm: 20.000 20.000 20.000\n"), std::string::npos);
  EXPECT_NE(run.output.find("watertight: yes\n"), std::string::npos);
  EXPECT_NE(run.output.find("self_intersections: 0\n"), std::string::npos);
  EXPECT_NE(run.output.find("volume_mm3: 8000.000\n"), std::string::npos);
}

TEST(MeshToolTest, AClosedMeshThatCrossesItselfIsNotWatertight) {
  // Two cubes overlapping in one mesh: every edge has its two faces, but the surfaces cross.
  test::TempDir dir;
  const TriangleMesh cubes = test::MergeMeshes(test::MakeCube(20), test::MakeCube(20), {7, 5, 3});
  WriteMesh(dir / "cubes.ply", cubes);
  const ToolRun run = RunTool("info " + (dir / "cubes.ply").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("watertight: no\n"), std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("self_intersections: 0\n"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("self_intersections: "), std::string::npos) << run.output;
}

TEST(MeshToolTest, ConvertsBetweenFormats) {
  test::TempDir dir;
  const TriangleMesh sphere = test::MakeUvSphere(10, 8, 16);
  WriteMesh(dir / "sphere.ply", sphere);
  for (const std::string out : {"sphere.stl", "sphere.obj", "sphere_ascii.ply"}) {
    const std::string flag = out == "sphere_ascii.ply" ? " --ascii" : "";
    const ToolRun run = RunTool("--quiet convert " + (dir / "sphere.ply").string() + " " +
                                (dir / out).string() + flag);
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const TriangleMesh read = ReadMesh(dir / out);
    EXPECT_EQ(read.faces.size(), sphere.faces.size()) << out;
    EXPECT_NEAR(read.Volume(), sphere.Volume(), 1e-3) << out;
  }
  EXPECT_EQ(test::ReadFileString(dir / "sphere_ascii.ply").find("format ascii"), 4u);
}

TEST(MeshToolTest, BadInputsGiveOneLineErrorsAndDocumentedExitCodes) {
  test::TempDir dir;
  WriteMesh(dir / "cube.ply", test::MakeCube(1));
  struct Case {
    std::string arguments;
    int exit_code;
    std::string needle;
  };
  const Case cases[] = {
      {"", 2, "error"},
      {"info", 2, "mesh is required"},
      {"frobnicate x", 2, "error"},
      {"--log-level loud info " + (dir / "cube.ply").string(), 2, "unknown log level"},
      {"info " + (dir / "missing.ply").string(), 3, "no such file"},
      {"info " + (dir / "cube.xyz").string(), 2, "unknown mesh format"},
      {"convert " + (dir / "cube.ply").string() + " " + (dir / "nodir" / "x.stl").string(), 6,
       "does not exist"},
      {"convert " + (dir / "cube.ply").string() + " " + (dir / "x.stl").string() + " --ascii", 2,
       "--ascii applies to .ply"},
  };
  for (const Case& c : cases) {
    const ToolRun run = RunTool(c.arguments);
    EXPECT_EQ(run.exit_code, c.exit_code) << c.arguments << "\n" << run.output;
    EXPECT_EQ(LineCount(run.output), 1) << c.arguments << "\n" << run.output;
    EXPECT_NE(run.output.find(c.needle), std::string::npos) << c.arguments << "\n" << run.output;
  }
  test::WriteBytes(dir / "truncated.ply", test::ReadFileString(dir / "cube.ply").substr(0, 250));
  const ToolRun truncated = RunTool("info " + (dir / "truncated.ply").string());
  EXPECT_EQ(truncated.exit_code, 3);
  EXPECT_NE(truncated.output.find("truncated.ply: truncated PLY"), std::string::npos)
      << truncated.output;
}

TEST(MeshToolTest, VersionAndHelpExitZero) {
  const ToolRun version = RunTool("--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_EQ(version.output.rfind("inhandscan-mesh ", 0), 0u) << version.output;
  const ToolRun help = RunTool("--help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.output.find("Exit codes:"), std::string::npos) << help.output;
}

// The global options may follow a subcommand, and its help lists them.
TEST(MeshToolTest, SubcommandsTakeAndListTheGlobalOptions) {
  const ToolRun help = RunTool("convert --help");
  EXPECT_EQ(help.exit_code, 0);
  const size_t global = help.output.find("Global options");
  ASSERT_NE(global, std::string::npos) << help.output;
  EXPECT_NE(help.output.find("--log-level", global), std::string::npos) << help.output;
  EXPECT_NE(help.output.find("-q,--quiet", global), std::string::npos) << help.output;
  test::TempDir dir;
  WriteMesh(dir / "cube.ply", test::MakeCube(20));
  const std::string convert =
      "convert " + (dir / "cube.ply").string() + " " + (dir / "cube.stl").string();
  const ToolRun loud = RunTool(convert);
  ASSERT_EQ(loud.exit_code, 0) << loud.output;
  EXPECT_NE(loud.output.find("[info] wrote"), std::string::npos) << loud.output;
  const ToolRun quiet = RunTool(convert + " --quiet");
  ASSERT_EQ(quiet.exit_code, 0) << quiet.output;
  EXPECT_EQ(quiet.output, "");
}

}  // namespace
}  // namespace ihs

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "core/errors.h"
#include "tests/test_util.h"
#include "tools/synth/objects.h"

namespace ihs::synth {
namespace {

// Largest diameter in the xy plane and height of a mesh standing on z = 0.
std::pair<double, double> DiameterAndHeight(const TriangleMesh& mesh) {
  double radius = 0;
  for (const auto& v : mesh.vertices) radius = std::max(radius, double(v.head<2>().norm()));
  const auto [lo, hi] = mesh.Bounds();
  return {2 * radius, hi.z() - lo.z()};
}

TEST(SynthObjectsTest, PaperObjectsHaveThePapersDimensionsAndAreClosed) {
  const std::map<std::string, std::pair<double, double>> truth = {{"sphere", {70, 70}},
                                                                  {"water-bottle", {73, 218}},
                                                                  {"bowling-pin", {82, 268}},
                                                                  {"small-bottle", {52, 80}}};
  for (const std::string& name : PaperObjectNames()) {
    const TriangleMesh mesh = MakeLatheMesh(PaperObjectProfile(name), 180);
    EXPECT_TRUE(mesh.IsWatertight()) << name;
    EXPECT_GT(mesh.Volume(), 0) << name;
    const auto [diameter, height] = DiameterAndHeight(mesh);
    EXPECT_NEAR(diameter, truth.at(name).first, 0.01) << name;
    EXPECT_NEAR(height, truth.at(name).second, 0.01) << name;
  }
  // The bowling pin's head is Ø50.
  double head = 0;
  for (const auto& [z, r] : PaperObjectProfile("bowling-pin")) {
    if (z > 200) head = std::max(head, 2 * r);
  }
  EXPECT_NEAR(head, 50, 1e-9);
  // The paper's sphere volume is 179 503 mm³ (4/3·π·35³ = 179 594).
  const double volume = MakeLatheMesh(PaperObjectProfile("sphere"), 360).Volume();
  EXPECT_NEAR(volume / 179594.0, 1.0, 2e-3);
  EXPECT_THROW(PaperObjectProfile("teapot"), std::invalid_argument);
}

TEST(SynthObjectsTest, LatheProfilesFromFiles) {
  test::TempDir dir;
  test::WriteBytes(dir / "cup.txt", "# height radius\n0 30\n90 40\n");
  const TriangleMesh cup = MakeLatheMesh(ReadLatheProfile(dir / "cup.txt"), 64);
  EXPECT_TRUE(cup.IsWatertight());
  // A truncated cone: V = π·h/3·(r1² + r1·r2 + r2²) = 350 316 mm³ (the 64-gon a little less).
  EXPECT_NEAR(cup.Volume() / 350316.0, 1.0, 0.01);
  test::WriteBytes(dir / "bad.txt", "0 30\n90 -4\n");
  EXPECT_THROW(ReadLatheProfile(dir / "bad.txt"), InputError);
  test::WriteBytes(dir / "down.txt", "10 30\n5 20\n");
  EXPECT_THROW(ReadLatheProfile(dir / "down.txt"), InputError);
  test::WriteBytes(dir / "words.txt", "0 thirty\n");
  EXPECT_THROW(ReadLatheProfile(dir / "words.txt"), InputError);
}

TEST(SynthObjectsTest, TexturedBoxHasItsSizeOutwardFacesAndAPattern) {
  const TriangleMesh box = MakeTexturedBox({60, 40, 100}, 10);
  const auto [lo, hi] = box.Bounds();
  EXPECT_EQ(hi - lo, Eigen::Vector3f(60, 40, 100));
  EXPECT_NEAR(box.Volume(), 60 * 40 * 100, 1e-3);  // Outward everywhere (closed as a surface).
  EXPECT_NEAR(box.SurfaceArea(), 2 * (60 * 40 + 60 * 100 + 40 * 100), 1e-3);
  std::set<std::array<std::uint8_t, 3>> colours(box.colors.begin(), box.colors.end());
  EXPECT_EQ(colours.size(), 12u);  // Light and dark cells in a hue per side.
}

}  // namespace
}  // namespace ihs::synth

// The option registry: every type parses and prints back, config files with sections and
// comments, errors that name the option (and the file's line), and the scanner's full registry
// round-trips through its own description.

#include "app/option_registry.h"

#include <gtest/gtest.h>

#include "app/scanner_options.h"
#include "core/errors.h"
#include "tests/test_util.h"

namespace ihs::app {
namespace {

struct Fields {
  double weight = 15.0;
  int iterations = 4;
  std::uint32_t seed = 1;
  bool color = true;
  std::string name = "procedural";
  Eigen::Vector3d corner{-100, -140, 400};
};

OptionRegistry Register(Fields* f) {
  OptionRegistry r;
  r.Add("fusion.weight", &f->weight, "a weight");
  r.Add("fit.iterations", &f->iterations, "iterations");
  r.Add("seed", &f->seed, "a seed");
  r.Add("tsdf.color", &f->color, "colour");
  r.Add("scan.template", &f->name, "a name");
  r.Add("crop.min_mm", &f->corner, "a corner");
  return r;
}

TEST(OptionRegistryTest, SetsEveryTypeFromText) {
  Fields f;
  OptionRegistry r = Register(&f);
  r.Set("fusion.weight", "2.5");
  r.SetAssignment("fit.iterations=7");
  r.Set("seed", " 42 ");
  r.Set("tsdf.color", "off");
  r.Set("scan.template", "\"/data/hand\"");
  r.Set("crop.min_mm", "-1,2.5,300");
  EXPECT_EQ(f.weight, 2.5);
  EXPECT_EQ(f.iterations, 7);
  EXPECT_EQ(f.seed, 42u);
  EXPECT_FALSE(f.color);
  EXPECT_EQ(f.name, "/data/hand");
  EXPECT_EQ(f.corner, Eigen::Vector3d(-1, 2.5, 300));
  EXPECT_EQ(r.Get("crop.min_mm"), "-1,2.5,300");
  EXPECT_EQ(r.Get("tsdf.color"), "false");
}

TEST(OptionRegistryTest, BadNamesAndValuesAreNamedAndLeaveTheFieldAlone) {
  Fields f;
  OptionRegistry r = Register(&f);
  try {
    r.Set("fusion.wieght", "1");
    FAIL() << "an unknown name was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("fusion.wieght"), std::string::npos);
  }
  EXPECT_THROW(r.Set("fit.iterations", "4.5"), std::invalid_argument);
  EXPECT_THROW(r.Set("fusion.weight", "fast"), std::invalid_argument);
  EXPECT_THROW(r.Set("tsdf.color", "maybe"), std::invalid_argument);
  EXPECT_THROW(r.Set("crop.min_mm", "1,2"), std::invalid_argument);
  EXPECT_THROW(r.Set("seed", "-3"), std::invalid_argument);
  EXPECT_THROW(r.SetAssignment("fit.iterations"), std::invalid_argument);
  EXPECT_EQ(f.iterations, 4);
  EXPECT_EQ(f.weight, 15.0);
  EXPECT_EQ(f.corner, Eigen::Vector3d(-100, -140, 400));
}

TEST(OptionRegistryTest, LoadsConfigFilesWithSectionsAndComments) {
  test::TempDir dir;
  test::WriteBytes(dir / "a.conf",
                   "# a comment\n\nseed = 9   # trailing comment\n[fusion]\nweight = 0\n"
                   "[fit]\niterations=12\n");
  Fields f;
  OptionRegistry r = Register(&f);
  r.Load(dir / "a.conf");
  EXPECT_EQ(f.seed, 9u);
  EXPECT_EQ(f.weight, 0.0);
  EXPECT_EQ(f.iterations, 12);

  test::WriteBytes(dir / "bad.conf", "seed = 1\n[fit]\niterations = many\n");
  try {
    r.Load(dir / "bad.conf");
    FAIL() << "a bad value was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("bad.conf:3"), std::string::npos) << error.what();
  }
  EXPECT_THROW(r.Load(dir / "missing.conf"), InputError);
}

TEST(OptionRegistryTest, TheScannersOptionsRoundTripThroughTheirDescription) {
  ScannerOptions changed;
  OptionRegistry registry = RegisterScannerOptions(&changed);
  EXPECT_GT(registry.Names().size(), 60u);
  registry.Set("fusion.pairwise.contact_weight", "0");
  registry.Set("tracker.segmentation.crop_min_mm", "-90,-140,410");
  registry.Set("mesh.poisson_depth", "8");
  test::TempDir dir;
  test::WriteBytes(dir / "all.conf", registry.Describe());

  ScannerOptions loaded;
  OptionRegistry reader = RegisterScannerOptions(&loaded);
  reader.Load(dir / "all.conf");
  EXPECT_EQ(loaded.fusion.pairwise.contact_weight, 0.0);
  EXPECT_EQ(loaded.tracker.segmentation.crop_min_mm, Eigen::Vector3d(-90, -140, 410));
  EXPECT_EQ(loaded.meshing.poisson_depth, 8);
  for (const std::string& name : registry.Names()) {
    EXPECT_EQ(reader.Get(name), registry.Get(name)) << name;
  }
  // The defaults are the paper's.
  const ScannerOptions defaults;
  EXPECT_EQ(defaults.fusion.pairwise.contact_weight, 15.0);
  EXPECT_EQ(defaults.tracker.fit.collision_weight, 10.0);
  EXPECT_EQ(defaults.fusion.tsdf.resolution, 256);
  EXPECT_EQ(defaults.meshing.poisson_depth, 10);
  EXPECT_NO_THROW(defaults.Check());
}

TEST(OptionRegistryTest, ScannerOptionsCheckNamesTheBadField) {
  ScannerOptions options;
  options.pipeline.queue_capacity = 0;
  try {
    options.Check();
    FAIL() << "queue capacity 0 was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("pipeline.queue_capacity"), std::string::npos);
  }
  ScannerOptions nothing_to_register;
  nothing_to_register.scan.features_2d = false;
  nothing_to_register.fusion.pairwise.contact_weight = 0;
  EXPECT_THROW(nothing_to_register.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace ihs::app

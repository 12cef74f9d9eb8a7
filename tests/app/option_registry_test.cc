// The option registry: every type parses and prints back, config files with sections and
// comments, errors that name the option (and the file's line), and the scanner's full registry
// round-trips through its own description.

#include "app/option_registry.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cctype>
#include <functional>

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
  // The defaults are the paper's, but Poisson's depth: 9 rather than 10, still finer than the
  // TSDF's voxels (MeshingOptions::poisson_depth).
  const ScannerOptions defaults;
  EXPECT_EQ(defaults.fusion.pairwise.contact_weight, 15.0);
  EXPECT_EQ(defaults.tracker.fit.collision_weight, 10.0);
  EXPECT_EQ(defaults.fusion.tsdf.resolution, 256);
  EXPECT_EQ(defaults.meshing.poisson_depth, 9);
  EXPECT_NO_THROW(defaults.Check());
}

// Each group registers its own prefix; all groups together are the scanner's options, in order.
TEST(OptionRegistryTest, EachGroupHoldsItsPrefixAndTheGroupsMakeTheWhole) {
  ScannerOptions options;
  const std::vector<std::pair<std::string, std::function<void(OptionRegistry&)>>> groups = {
      {"scan.", [&](OptionRegistry& r) { AddScanOptions(r, &options.scan); }},
      {"tracker.", [&](OptionRegistry& r) { AddTrackerOptions(r, &options.tracker); }},
      {"features.", [&](OptionRegistry& r) { AddFeatureOptions(r, &options.sift, &options.shot); }},
      {"fusion.", [&](OptionRegistry& r) { AddFusionOptions(r, &options.fusion); }},
      {"mesh.", [&](OptionRegistry& r) { AddMeshingOptions(r, &options.meshing); }},
      {"pipeline.", [&](OptionRegistry& r) { AddPipelineOptions(r, &options.pipeline); }}};
  std::vector<std::string> all;
  for (const auto& [prefix, add] : groups) {
    OptionRegistry group;
    add(group);
    EXPECT_FALSE(group.Names().empty()) << prefix;
    for (const std::string& name : group.Names()) {
      EXPECT_EQ(name.rfind(prefix, 0), 0u) << name << " in the group " << prefix;
      all.push_back(name);
    }
  }
  EXPECT_EQ(all, RegisterScannerOptions(&options).Names());
  // A tool that adds only the tracker's group does not know the others' names.
  OptionRegistry tracker_only;
  AddTrackerOptions(tracker_only, &options.tracker);
  EXPECT_NO_THROW(tracker_only.Set("tracker.contacts.max_mm", "8"));
  EXPECT_EQ(options.tracker.contacts.max_mm, 8.0);
  EXPECT_THROW(tracker_only.Set("fusion.icp.iterations", "3"), std::invalid_argument);
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

TEST(OptionRegistryTest, NonFiniteNumbersAreRefusedByEveryNumericOption) {
  ScannerOptions options;
  OptionRegistry registry = RegisterScannerOptions(&options);
  int numeric = 0;
  for (const std::string& name : registry.Names()) {
    const std::string value = registry.Get(name);
    if (value.empty() || !(std::isdigit(static_cast<unsigned char>(value[0])) || value[0] == '-'))
      continue;  // bool or text
    const bool vector = value.find(',') != std::string::npos;
    ++numeric;
    for (const std::string bad : {"nan", "inf", "-inf", "1e400", "-1e400"}) {
      const std::string text = vector ? bad + ",0,0" : bad;
      EXPECT_THROW(registry.Set(name, text), std::invalid_argument) << name << " = " << text;
      EXPECT_EQ(registry.Get(name), value) << name << " changed by " << text;
    }
  }
  EXPECT_GT(numeric, 80);
}

// Values the options' types accept but whose memory or time would have no bound (each was
// accepted once: > 6 GB, or a loop that never ends) are refused by Check(), naming the option.
TEST(OptionRegistryTest, ValuesThatWouldExhaustMemoryOrTimeAreRefused) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"tracker.contacts.step_mm", "1e-300"},
      {"tracker.contacts.max_mm", "1e300"},
      {"tracker.fit.outer_iterations", "2147483647"},
      {"tracker.fit.inner_iterations", "100000"},
      {"tracker.fit.max_data_points", "2147483647"},
      {"tracker.scale_step", "1e-6"},
      {"tracker.scale_frames", "100000"},
      {"fusion.tsdf.resolution", "1024"},
      {"fusion.tsdf.size_mm", "1e308"},
      {"fusion.tsdf.size_mm", "1e-300"},
      {"fusion.icp.iterations", "1000000"},
      {"fusion.pairwise.ransac_iterations", "2000000000"},
      {"features.sift.max_features", "2147483647"},
      {"features.shot.resolution_mm", "1e-300"},
      {"features.shot.support_radius", "1e300"},
      {"mesh.poisson_scale", "-1"},
      {"mesh.poisson_scale", "0.5"},
      {"mesh.poisson_depth", "20"},
      {"mesh.poisson_threads", "100000"},
  };
  for (const auto& [name, value] : cases) {
    ScannerOptions options;
    OptionRegistry registry = RegisterScannerOptions(&options);
    registry.Set(name, value);  // Of the field's type: only Check() can refuse it.
    const std::string field = name.substr(name.rfind('.') + 1);
    try {
      options.Check();
      ADD_FAILURE() << name << " = " << value << " was accepted";
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find(field), std::string::npos)
          << name << ": " << error.what();
    }
  }
}

TEST(OptionRegistryTest, ConfigsThatAreNotRegularFilesOrAreHugeAreRefusedWithoutReading) {
  test::TempDir dir;
  Fields f;
  OptionRegistry r = Register(&f);
  // A FIFO nobody writes to would block a reader for ever; a folder reads as nothing; /dev/zero
  // never ends.
  ASSERT_EQ(mkfifo((dir / "fifo").c_str(), 0600), 0);
  EXPECT_THROW(r.Load(dir / "fifo"), InputError);
  EXPECT_THROW(r.Load(dir.path()), InputError);
  EXPECT_THROW(r.Load("/dev/zero"), InputError);
  test::WriteBytes(dir / "huge.conf",
                   std::string(OptionRegistry::kMaxConfigBytes, '#') + "\nseed = 3\n");
  try {
    r.Load(dir / "huge.conf");
    FAIL() << "a config over the size cap was read";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("huge.conf"), std::string::npos) << error.what();
  }
  EXPECT_EQ(f.seed, 1u);
}

}  // namespace
}  // namespace ihs::app

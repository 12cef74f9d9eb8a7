#include "core/trajectory_io.h"

#include <gtest/gtest.h>

#include <random>

#include "core/errors.h"
#include "tests/test_util.h"

namespace ihs {
namespace {

TEST(TrajectoryIoTest, RoundTripsPosesToMicrometresAndMicroradians) {
  test::TempDir dir;
  std::mt19937 rng = test::Rng(8);
  std::normal_distribution<double> normal(0, 1);
  std::vector<StampedPose> poses;
  for (int i = 0; i < 50; ++i) {
    poses.push_back(
        {1.0 + i / 30.0,
         Rigid3::FromAxisAngle({normal(rng), normal(rng), normal(rng)}, 3 * normal(rng),
                               {100 * normal(rng), 100 * normal(rng), 600 + normal(rng)})});
  }
  WriteTumTrajectory(dir / "trajectory.txt", poses, {"cam_from_object, mm"});
  EXPECT_EQ(test::ReadFileString(dir / "trajectory.txt").rfind("# cam_from_object, mm\n", 0), 0u);
  const auto read = ReadTumTrajectory(dir / "trajectory.txt");
  ASSERT_EQ(read.size(), poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_NEAR(read[i].time_s, poses[i].time_s, 1e-6);
    EXPECT_LT(read[i].transform.TranslationDistanceTo(poses[i].transform), 1e-5);
    EXPECT_LT(read[i].transform.RotationAngleToRad(poses[i].transform), 1e-8);
  }
}

TEST(TrajectoryIoTest, MalformedLinesAndQuaternionsAreInputErrors) {
  test::TempDir dir;
  test::WriteBytes(dir / "short.txt", "# header\n1.0 0 0 0 0 0 0\n");
  EXPECT_THROW(ReadTumTrajectory(dir / "short.txt"), InputError);
  test::WriteBytes(dir / "scaled.txt", "1.0 0 0 0 0 0 0 2\n");
  EXPECT_THROW(ReadTumTrajectory(dir / "scaled.txt"), InputError);
  test::WriteBytes(dir / "ok.txt", "\n# c\n1.5 1 2 3 0 0 0 1\n");
  const auto poses = ReadTumTrajectory(dir / "ok.txt");
  ASSERT_EQ(poses.size(), 1u);
  EXPECT_EQ(poses[0].transform.translation(), Eigen::Vector3d(1, 2, 3));
  EXPECT_THROW(ReadTumTrajectory(dir / "missing.txt"), InputError);
}

}  // namespace
}  // namespace ihs

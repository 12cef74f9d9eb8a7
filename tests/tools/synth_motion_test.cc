// Object shapes, the scripted and the recorded motions of the synthetic generator.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>

#include "core/errors.h"
#include "tests/test_util.h"
#include "tools/synth/hand_object.h"
#include "tools/synth/object_shape.h"
#include "tools/synth/objects.h"
#include "tools/synth/recorded_motion.h"
#include "tools/synth/scripted_motion.h"
#include "tracker/hand_data.h"
#include "tracker/procedural_hand.h"

namespace ihs::synth {
namespace {

TEST(ObjectShapeTest, SignedDistanceOfTheSphereAndTheBox) {
  const ObjectShape sphere = ObjectShape::FromSpec("sphere");
  EXPECT_NEAR(sphere.SignedDistance({0, 0, 35}), -35, 0.01);  // A 90-segment profile.
  EXPECT_NEAR(sphere.SignedDistance({50, 0, 35}), 15, 0.05);
  EXPECT_NEAR(sphere.SignedDistance({0, 0, 80}), 10, 1e-6);
  EXPECT_NEAR(sphere.SignedDistance({0, 0, -5}), 5, 1e-6);
  EXPECT_NEAR(sphere.RadiusAt(35), 35, 0.01);
  // Every mesh vertex lies on the surface.
  for (const auto& v : sphere.mesh().vertices)
    ASSERT_NEAR(sphere.SignedDistance(v.cast<double>()), 0, 1e-3);

  const ObjectShape box = ObjectShape::FromSpec("box");
  EXPECT_NEAR(box.SignedDistance({0, 0, 45}), -22.5, 1e-9);
  EXPECT_NEAR(box.SignedDistance({40, 0, 45}), 10, 1e-9);
  EXPECT_NEAR(box.SignedDistance({33, 0, 95}), std::sqrt(3.0 * 3 + 5 * 5), 1e-9);  // Edge.
  EXPECT_TRUE(box.textured());
  EXPECT_FALSE(box.rotationally_symmetric());

  const ObjectShape bottle = ObjectShape::FromSpec("water-bottle");
  EXPECT_NEAR(bottle.SignedDistance({0, 0, 100}), -36.5, 1e-9);  // Nearest: the side wall.
  EXPECT_NEAR(bottle.SignedDistance({0, 0, 230}), 12, 1e-9);     // Above the cap.
  EXPECT_NEAR(bottle.RadiusAt(100), 36.5, 1e-9);
  EXPECT_THROW(ObjectShape::FromSpec("teapot"), std::invalid_argument);
}

// The cube: three equal sides, one colour unless textured; the plain box: the box's shape in one
// colour.
TEST(ObjectShapeTest, TheCubeAndThePlainBox) {
  const std::array<std::uint8_t, 3> blue = {70, 110, 200};
  const ObjectShape cube = ObjectShape::FromSpec("cube", false, blue);
  const auto [lo, hi] = cube.mesh().Bounds();
  EXPECT_EQ(hi - lo, Eigen::Vector3f(60, 60, 60));
  EXPECT_EQ(lo.z(), 0.0f);
  EXPECT_NEAR(cube.mesh().Volume(), 60.0 * 60 * 60, 1e-2);
  EXPECT_NEAR(cube.SignedDistance({0, 0, 30}), -30, 1e-9);
  EXPECT_NEAR(cube.SignedDistance({0, 40, 30}), 10, 1e-9);
  EXPECT_NEAR(cube.height_mm(), 60, 1e-9);
  EXPECT_FALSE(cube.textured());
  EXPECT_FALSE(cube.rotationally_symmetric());
  for (const auto& c : cube.mesh().colors) ASSERT_EQ(c, blue);
  const ObjectShape textured_cube = ObjectShape::FromSpec("cube", true, blue);
  EXPECT_TRUE(textured_cube.textured());
  const std::set<std::array<std::uint8_t, 3>> colours(textured_cube.mesh().colors.begin(),
                                                      textured_cube.mesh().colors.end());
  EXPECT_EQ(colours.size(), 12u);  // The box's checkerboard, a hue per side.

  const ObjectShape box = ObjectShape::FromSpec("box", false, blue);
  const ObjectShape plain = ObjectShape::FromSpec("plain-box", true, blue);
  EXPECT_TRUE(box.textured());  // The box always has its pattern, the plain box never.
  EXPECT_FALSE(plain.textured());
  EXPECT_EQ(plain.mesh().Bounds(), box.mesh().Bounds());
  EXPECT_EQ(plain.SignedDistance({33, 0, 95}), box.SignedDistance({33, 0, 95}));
  for (const auto& c : plain.mesh().colors) ASSERT_EQ(c, blue);
}

// The colours a lathe mesh shows about its axis at height `z_mm`, turned by `turn_deg`: one per
// 2° sector, from the vertex nearest that direction.
std::vector<std::array<std::uint8_t, 3>> RingColours(const ObjectShape& shape, double z_mm,
                                                     double turn_deg) {
  std::vector<std::array<std::uint8_t, 3>> ring;
  for (int sector = 0; sector < 180; ++sector) {
    const double phi = (2.0 * sector + turn_deg) * M_PI / 180.0;
    size_t best = 0;
    double best_distance = 1e9;
    for (size_t v = 0; v < shape.mesh().vertices.size(); ++v) {
      const Eigen::Vector3f& p = shape.mesh().vertices[v];
      const double r = std::hypot(p.x(), p.y());
      const double d = std::abs(p.z() - z_mm) +
                       r * std::abs(std::remainder(std::atan2(p.y(), p.x()) - phi, 2 * M_PI));
      if (d < best_distance) best_distance = d, best = v;
    }
    ring.push_back(shape.mesh().colors[best]);
  }
  return ring;
}

// A label (textured with a seed) repeats nowhere about the axis; the checkerboard every 60°.
TEST(ObjectShapeTest, ALabelRepeatsNowhereTheCheckerboardEverySixtyDegrees) {
  const ObjectShape checker = ObjectShape::FromSpec("small-bottle", true);
  const ObjectShape label = ObjectShape::FromSpec("small-bottle", true, {235, 235, 235}, 11u);
  const ObjectShape other = ObjectShape::FromSpec("small-bottle", true, {235, 235, 235}, 12u);
  int checker_60 = 0, differ_60 = 0, differ_other = 0;
  for (double z : {20.0, 40.0, 60.0}) {
    const auto ring = RingColours(label, z, 0), turned = RingColours(label, z, 60);
    const auto other_ring = RingColours(other, z, 0);
    const auto checker_ring = RingColours(checker, z, 0),
               checker_turned = RingColours(checker, z, 60);
    for (size_t i = 0; i < ring.size(); ++i) {
      checker_60 += checker_ring[i] != checker_turned[i];
      differ_60 += ring[i] != turned[i];
      differ_other += ring[i] != other_ring[i];
    }
  }
  // The checkerboard differs only where a sample falls on a sector's edge; spots cover part of
  // the side: a fifth of the samples differ at least.
  EXPECT_LT(checker_60, 3 * 180 / 20);
  EXPECT_GT(differ_60, 3 * 180 / 5);
  EXPECT_GT(differ_other, 3 * 180 / 5);
  EXPECT_EQ(RingColours(label, 40, 0),
            RingColours(ObjectShape::FromSpec("small-bottle", true, {235, 235, 235}, 11u), 40, 0))
      << "the same seed, the same label";
  EXPECT_THROW(ObjectShape::FromSpec("cube", true, {235, 235, 235}, 11u), std::invalid_argument);
}

// The signed distance the slow way: to every segment of the closed (r, z) outline but the axis,
// inside by the crossings of a ray toward +r.
double SignedDistanceOverEverySegment(const LatheProfile& profile, const Eigen::Vector3d& p) {
  std::vector<Eigen::Vector2d> outline = {{0.0, profile.front().first}};
  for (const auto& [z, r] : profile) outline.emplace_back(r, z);
  outline.emplace_back(0.0, profile.back().first);
  const Eigen::Vector2d q(p.head<2>().norm(), p.z());
  double distance = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i + 1 < outline.size(); ++i) {
    const Eigen::Vector2d a = outline[i], ab = outline[i + 1] - a;
    const double s =
        ab.squaredNorm() > 0 ? std::clamp((q - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
    distance = std::min(distance, (q - (a + s * ab)).norm());
  }
  bool inside = false;
  for (size_t i = 0; i < outline.size(); ++i) {
    const Eigen::Vector2d& a = outline[i];
    const Eigen::Vector2d& b = outline[(i + 1) % outline.size()];
    if ((a.y() > q.y()) != (b.y() > q.y()) &&
        q.x() < a.x() + (q.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y())) {
      inside = !inside;
    }
  }
  return inside ? -distance : distance;
}

TEST(ObjectShapeTest, TheSignedDistanceIsTheNearestOfEveryProfileSegment) {
  // The shape searches only the segments near the point's height: the same value, to the bit,
  // as over every segment; at random points and at the profile's own heights (flat steps, ties).
  std::vector<std::pair<std::string, LatheProfile>> profiles;
  for (const std::string& name : PaperObjectNames())
    profiles.emplace_back(name, PaperObjectProfile(name));
  profiles.emplace_back(
      "steps", LatheProfile{{0, 0}, {0, 20}, {10, 20}, {10, 5}, {10, 30}, {25, 30}, {25, 0}});
  std::mt19937 rng = test::Rng();
  for (const auto& [name, profile] : profiles) {
    const ObjectShape shape = ObjectShape::Lathe(name, profile, {200, 200, 200}, false);
    const double top = profile.back().first;
    std::uniform_real_distribution<double> xy(-60, 60), z(-20, top + 20);
    std::uniform_int_distribution<size_t> point(0, profile.size() - 1);
    for (int k = 0; k < 3000; ++k) {
      Eigen::Vector3d p(xy(rng), xy(rng), z(rng));
      if (k % 3 == 0) p.z() = profile[point(rng)].first;
      ASSERT_EQ(shape.SignedDistance(p), SignedDistanceOverEverySegment(profile, p))
          << name << " at " << p.transpose();
    }
  }
}

TEST(ObjectShapeTest, ATexturedLatheObjectHasTheSameShapeInTwoColours) {
  const std::array<std::uint8_t, 3> blue = {70, 110, 200};
  const ObjectShape plain = ObjectShape::FromSpec("small-bottle", false, blue);
  const ObjectShape textured = ObjectShape::FromSpec("small-bottle", true, blue);
  EXPECT_FALSE(plain.textured());
  EXPECT_TRUE(textured.textured());
  EXPECT_TRUE(textured.mesh().IsWatertight());
  EXPECT_NEAR(textured.mesh().Volume(), plain.mesh().Volume(), 1e-3 * plain.mesh().Volume());
  std::set<std::array<std::uint8_t, 3>> colours(textured.mesh().colors.begin(),
                                                textured.mesh().colors.end());
  EXPECT_EQ(colours.size(), 2u);
  EXPECT_TRUE(colours.count(blue));
  for (const auto& v : textured.mesh().vertices)
    ASSERT_NEAR(textured.SignedDistance(v.cast<double>()), 0, 1e-3);
}

// Angle (rad) of the rotation b·a⁻¹ about the object's own axis, signed.
double TurnAboutAxis(const Rigid3& cam_from_object_a, const Rigid3& cam_from_object_b) {
  const Eigen::Quaterniond q = (cam_from_object_a.Inverse() * cam_from_object_b).quaternion();
  return 2 * std::atan2(q.z(), q.w());
}

TEST(ScriptedMotionTest, TurnsTheObjectAFullTurnHeldByThumbIndexAndMiddle) {
  const tracker::HandModel hand = tracker::MakeProceduralHand();
  const HandObjectGeometry geometry(hand);
  for (const std::string name : {"sphere", "small-bottle", "box"}) {
    SCOPED_TRACE(name);
    const ObjectShape object = ObjectShape::FromSpec(name);
    ScriptedMotionOptions options;
    options.frames = 120;
    const Motion motion = MakeScriptedMotion(hand, object, options);
    ASSERT_EQ(motion.frames.size(), 120u);
    double turn = 0, deepest = 0;
    int held = 0;
    for (size_t i = 0; i < motion.frames.size(); ++i) {
      const MotionFrame& frame = motion.frames[i];
      const TriangleMesh posed = hand.Pose(frame.cam_from_bone);
      const HandObjectContact contact = geometry.Measure(posed, object, frame.cam_from_object, 1.0);
      deepest = std::max(deepest, contact.max_penetration_mm);
      if (frame.held) {
        ++held;
        // Thumb, index and middle touch (end-effector order: pinky, ring, middle, index, thumb).
        EXPECT_TRUE(contact.fingertips[2].touching && contact.fingertips[3].touching &&
                    contact.fingertips[4].touching)
            << "frame " << i;
      }
      if (i > 0) {
        const MotionFrame& before = motion.frames[i - 1];
        if (!before.held || !frame.held) {
          // Not held: the object does not move.
          if (!frame.held) {
            EXPECT_LT(before.cam_from_object.TranslationDistanceTo(frame.cam_from_object), 1e-6);
          }
        } else {
          // Held: the object moves exactly with the hand (no slip).
          const Rigid3 a = before.cam_from_object.Inverse() * before.cam_from_bone[0];
          const Rigid3 b = frame.cam_from_object.Inverse() * frame.cam_from_bone[0];
          EXPECT_LT(a.TranslationDistanceTo(b), 1e-6) << "frame " << i;
          EXPECT_LT(a.RotationAngleToRad(b), 1e-9) << "frame " << i;
        }
        turn += TurnAboutAxis(before.cam_from_object, frame.cam_from_object);
      }
    }
    EXPECT_GT(held, 60);
    EXPECT_GE(std::abs(turn), 2 * M_PI - 0.05);
    EXPECT_LT(deepest, 3.0);  // Fingertips press 0.5 mm; the box's corners may cut deeper.
  }
}

TEST(ScriptedMotionTest, SlipTurnsTheObjectAgainstTheFingers) {
  const tracker::HandModel hand = tracker::MakeProceduralHand();
  const ObjectShape object = ObjectShape::FromSpec("sphere");
  ScriptedMotionOptions options;
  options.frames = 60;
  options.slip_mm = 2.0;
  const Motion motion = MakeScriptedMotion(hand, object, options);
  double largest = 0;
  for (size_t i = 1; i < motion.frames.size(); ++i) {
    const auto& a = motion.frames[i - 1];
    const auto& b = motion.frames[i];
    if (!a.held || !b.held) continue;
    const Rigid3 before = a.cam_from_object.Inverse() * a.cam_from_bone[0];
    const Rigid3 after = b.cam_from_object.Inverse() * b.cam_from_bone[0];
    largest = std::max(largest, before.RotationAngleToRad(after) * 35);  // mm at the surface.
  }
  EXPECT_GT(largest, 1.0);
  EXPECT_LT(largest, 10.0);
}

TEST(RecordedMotionTest, FingertipsThatHoldTheObjectStayOnItsSurface) {
  const auto data = test::HandDataDir();
  if (data.empty()) GTEST_SKIP() << "../shared/data is absent";
  const tracker::RecordedHand recorded =
      tracker::LoadRecordedHand(data, data / "sequences" / "004-sphere");
  const ObjectShape object = ObjectShape::FromSpec("sphere");
  RecordedMotionOptions options;
  options.last_frame = 150;
  RecordedMotionReport report;
  const Motion motion = MakeRecordedMotion(recorded, object, options, &report);
  ASSERT_EQ(motion.frames.size(), 151u);
  EXPECT_GE(report.grasp_frame, 0);
  EXPECT_GT(report.held_frames, 100);
  EXPECT_GE(report.carried_within_3mm_share, 0.9);
  EXPECT_GE(report.placed_within_3mm_share, 0.9);
  EXPECT_LT(report.penetration_max_mm, 3.0);
  // Independently: in held frames, at least two fingertips within 3 mm of the surface.
  const HandObjectGeometry geometry(recorded.model);
  int ok = 0, held = 0;
  for (size_t t = 0; t < motion.frames.size(); t += 5) {
    if (!motion.frames[t].held) continue;
    ++held;
    const TriangleMesh posed = recorded.model.Pose(motion.frames[t].cam_from_bone);
    ok +=
        geometry.Measure(posed, object, motion.frames[t].cam_from_object, 3.0).TouchingCount() >= 2;
  }
  EXPECT_GE(ok, 0.9 * held);
}

TEST(RecordedMotionTest, AnObjectThatNeverFitsTheGraspIsAnInputError) {
  const auto data = test::HandDataDir();
  if (data.empty()) GTEST_SKIP() << "../shared/data is absent";
  const tracker::RecordedHand recorded =
      tracker::LoadRecordedHand(data, data / "sequences" / "004-sphere");
  // A disc 300 mm across: no thumb–index gap matches its diameter.
  const ObjectShape huge = ObjectShape::Lathe("disc", {{0, 150}, {5, 150}});
  RecordedMotionOptions options;
  options.last_frame = 20;
  EXPECT_THROW(MakeRecordedMotion(recorded, huge, options, nullptr), InputError);
}

}  // namespace
}  // namespace ihs::synth

// The pairwise registration: a known object motion from noisy feature matches with outliers and
// from contacts, each set alone, and a frame pair with nothing to go on.

#include "fusion/pairwise_registration.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <random>

#include "tests/test_util.h"

namespace ihs::fusion {
namespace {

// The largest distance between where two motions put the points of a 40 mm ball at 600 mm.
double MotionError(const Rigid3& a, const Rigid3& b) {
  double worst = 0;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z) {
        const Eigen::Vector3d p =
            Eigen::Vector3d(0, 0, 600) + 40.0 / std::sqrt(3) * Eigen::Vector3d(x, y, z);
        worst = std::max(worst, (a * p - b * p).norm());
      }
  return worst;
}

struct Scene {
  Rigid3 truth;
  PairwiseInput input;
};

// Points on a 40 mm ball at 600 mm moved by a small motion about its centre; `outliers` of the
// visual matches are wrong.
Scene MakeScene(std::mt19937& rng, int matches_2d, int matches_3d, int contacts, double outliers) {
  std::uniform_real_distribution<double> unit(-1, 1);
  std::normal_distribution<double> noise(0, 1);
  const Eigen::Vector3d centre(10, -20, 600);
  Scene scene;
  scene.truth = Rigid3::Translation(centre + Eigen::Vector3d(6, -3, 4)) *
                Rigid3::FromAxisAngle({0.2, 1, 0.1}, 0.09) * Rigid3::Translation(-centre);
  auto point = [&]() -> Eigen::Vector3d {
    return centre + 40 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
  };
  auto add = [&](std::vector<PointMatch>& set, int count, double sigma, double wrong) {
    for (int i = 0; i < count; ++i) {
      const Eigen::Vector3d p = point();
      Eigen::Vector3d q =
          scene.truth * p + sigma * Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
      if (unit(rng) * 0.5 + 0.5 < wrong) q = point();  // A wrong match: another point of the ball.
      set.push_back({p, q});
    }
  };
  add(scene.input.Pairs("sift", MatchKind::kVisual), matches_2d, 1.0, outliers);
  add(scene.input.Pairs("shot", MatchKind::kVisual), matches_3d, 1.5, outliers);
  add(scene.input.Pairs("contacts", MatchKind::kContact), contacts, 0.5, 0.0);
  return scene;
}

TEST(PairwiseRegistrationTest, RecoversAKnownMotionFromNoisyMatchesWithOutliersAndContacts) {
  std::mt19937 rng = test::Rng();
  const Scene scene = MakeScene(rng, 80, 40, 30, 0.35);
  const PairwiseResult result = RegisterPair(scene.input);
  ASSERT_TRUE(result.ok) << result.reason;
  std::printf("%d visual inliers of 120, %d contacts: motion error %.3f mm, rms %.2f mm\n",
              result.visual_inliers, result.contacts,
              MotionError(result.current_from_previous, scene.truth), result.rms_mm);
  EXPECT_GT(result.visual_inliers, 60);
  EXPECT_LT(result.visual_inliers, 95);  // The outliers are out.
  EXPECT_EQ(result.contacts, 30);
  EXPECT_LT(MotionError(result.current_from_previous, scene.truth), 0.6);
  EXPECT_LT(result.rms_mm, 3.0);
}

TEST(PairwiseRegistrationTest, EachSetAloneStillGivesTheMotion) {
  std::mt19937 rng = test::Rng(1);
  const Scene scene = MakeScene(rng, 60, 0, 12, 0.3);
  PairwiseOptions visual_only;
  visual_only.contact_weight = 0;  // The paper's γt = 0 baseline.
  const PairwiseResult visual = RegisterPair(scene.input, visual_only);
  ASSERT_TRUE(visual.ok) << visual.reason;
  EXPECT_EQ(visual.contacts, 0);
  EXPECT_LT(MotionError(visual.current_from_previous, scene.truth), 1.0);

  PairwiseInput contacts_only = scene.input;
  contacts_only.Pairs("sift", MatchKind::kVisual).clear();
  const PairwiseResult contacts = RegisterPair(contacts_only);
  ASSERT_TRUE(contacts.ok) << contacts.reason;
  EXPECT_EQ(contacts.visual_inliers, 0);
  EXPECT_LT(MotionError(contacts.current_from_previous, scene.truth), 1.0);
}

TEST(PairwiseRegistrationTest, ContactsTheFeaturesContradictAreDropped) {
  // A mistracked hand: its 30 contacts all 8 mm off, against 80 good feature matches. At γt = 15
  // each they would outweigh the features; checked against the features' motion they go.
  // Measured: all 30 dropped, motion error 0.55 mm (7.11 mm unchecked).
  std::mt19937 rng = test::Rng(2);
  Scene scene = MakeScene(rng, 80, 0, 30, 0.2);
  for (PointMatch& contact : scene.input.Pairs("contacts", MatchKind::kContact))
    contact.current += Eigen::Vector3d(8, 0, 0);
  const PairwiseResult checked = RegisterPair(scene.input);
  PairwiseOptions unchecked_options;
  unchecked_options.check_contacts = false;
  unchecked_options.max_rms_mm = 0;  // Used however far its pairs end from it.
  const PairwiseResult unchecked = RegisterPair(scene.input, unchecked_options);
  ASSERT_TRUE(checked.ok && unchecked.ok);
  const double checked_error = MotionError(checked.current_from_previous, scene.truth);
  const double unchecked_error = MotionError(unchecked.current_from_previous, scene.truth);
  std::printf("contacts 8 mm off: %d dropped, motion error %.2f mm (unchecked %.2f mm)\n",
              checked.contacts_rejected, checked_error, unchecked_error);
  EXPECT_EQ(checked.contacts_rejected, 30);
  EXPECT_EQ(checked.contacts, 0);
  EXPECT_LT(checked_error, 1.0);
  EXPECT_GT(unchecked_error, 5.0);

  // Contacts that agree with the features are kept.
  const Scene agreeing = MakeScene(rng, 80, 0, 30, 0.2);
  const PairwiseResult kept = RegisterPair(agreeing.input);
  EXPECT_EQ(kept.contacts_rejected, 0);
  EXPECT_EQ(kept.contacts, 30);
}

// The angle of a rotation, degrees.
double TurnDeg(const Rigid3& motion) {
  return Eigen::AngleAxisd(motion.rotation()).angle() * 180.0 / M_PI;
}

TEST(PairwiseRegistrationTest, VisualMatchesAloneKeepOnlyTheTurnTheyFix) {
  // Seven matches on a 12 mm patch of a 40 mm ball (a bottle label's few SIFT matches), 1 mm
  // noise, the ball turned by 1° about its centre: fitted as they are, their turn is noise
  // of several degrees; under the per-frame prior it shrinks toward none. Their patch still moves
  // where they put it. Many matches over the whole ball keep their turn.
  std::mt19937 rng = test::Rng(3);
  std::normal_distribution<double> noise(0, 1);
  std::uniform_real_distribution<double> unit(-1, 1);
  const Eigen::Vector3d centre(0, 0, 600);
  PairwiseOptions unshrunk;
  unshrunk.visual_turn_prior_deg = 0;
  double turn_error = 0, unshrunk_turn_error = 0, patch_error = 0;
  const int trials = 100;
  for (int trial = 0; trial < trials; ++trial) {
    const Rigid3 truth = Rigid3::Translation(centre + Eigen::Vector3d(1, 0, 0)) *
                         Rigid3::FromAxisAngle({unit(rng), unit(rng), unit(rng)}, M_PI / 180) *
                         Rigid3::Translation(-centre);
    PairwiseInput input;
    Eigen::Vector3d patch_centre = Eigen::Vector3d::Zero();
    for (int i = 0; i < 7; ++i) {
      const Eigen::Vector3d p =
          centre + 40 * Eigen::Vector3d(6 * unit(rng) / 40, 6 * unit(rng) / 40, -1).normalized();
      input.Pairs("sift", MatchKind::kVisual)
          .push_back({p, truth * p + Eigen::Vector3d(noise(rng), noise(rng), noise(rng))});
      patch_centre += p / 7;
    }
    const PairwiseResult shrunk = RegisterPair(input);
    const PairwiseResult fitted = RegisterPair(input, unshrunk);
    ASSERT_TRUE(shrunk.ok && fitted.ok) << shrunk.reason << fitted.reason;
    EXPECT_GT(shrunk.visual_turn_deg, 2.0);
    EXPECT_LT(shrunk.visual_turn_kept, 0.5);
    turn_error += TurnDeg(shrunk.current_from_previous * truth.Inverse()) / trials;
    unshrunk_turn_error += TurnDeg(fitted.current_from_previous * truth.Inverse()) / trials;
    patch_error +=
        (shrunk.current_from_previous * patch_centre - fitted.current_from_previous * patch_centre)
            .norm() /
        trials;
  }
  std::printf(
      "7 matches on a 12 mm patch: turn error %.2f° (fitted as they are %.2f°), their "
      "centroid moved %.3f mm by the shrinking\n",
      turn_error, unshrunk_turn_error, patch_error);
  EXPECT_LT(turn_error, 1.5);
  EXPECT_GT(unshrunk_turn_error, 3 * turn_error);
  EXPECT_LT(patch_error, 1e-6);

  const Scene spread = MakeScene(rng, 80, 0, 0, 0.0);  // A 5.2° turn seen all over the ball.
  const PairwiseResult kept = RegisterPair(spread.input);
  ASSERT_TRUE(kept.ok) << kept.reason;
  std::printf("80 matches over the ball: turn fixed to %.2f°, %.1f %% of it kept\n",
              kept.visual_turn_deg, 100 * kept.visual_turn_kept);
  EXPECT_LT(kept.visual_turn_deg, 0.3);
  EXPECT_GT(kept.visual_turn_kept, 0.95);
  EXPECT_LT(MotionError(kept.current_from_previous, spread.truth), 0.6);
}

// Matches that agree with one motion among themselves but whose solve, under the turn prior,
// leaves them far apart are not a motion: nine matches over a 60 mm patch (a box face's repeated
// squares matched a square over) turned 60° about the patch; the prior keeps part of the turn
// and the pairs end farther from where it puts them than they were picked as one motion by.
// The frame gets no motion (ICP starts where the object was) and says why; with the check off
// it is used as fitted.
TEST(PairwiseRegistrationTest, MatchesItsSolveLeavesFarApartAreNotAMotion) {
  std::mt19937 rng = test::Rng(4);
  std::normal_distribution<double> noise(0, 0.5);
  std::uniform_real_distribution<double> unit(-1, 1);
  const Eigen::Vector3d patch(0, 0, 600);
  const Rigid3 wrong = Rigid3::Translation(patch) *
                       Rigid3::FromAxisAngle({0.3, 1, 0.2}, 60 * M_PI / 180) *
                       Rigid3::Translation(-patch);
  PairwiseInput input;
  for (int i = 0; i < 9; ++i) {
    const Eigen::Vector3d p = patch + Eigen::Vector3d(30 * unit(rng), 30 * unit(rng), 0);
    input.Pairs("sift", MatchKind::kVisual)
        .push_back({p, wrong * p + Eigen::Vector3d(noise(rng), noise(rng), noise(rng))});
  }
  PairwiseOptions unchecked;
  unchecked.max_rms_mm = 0;
  const PairwiseResult used = RegisterPair(input, unchecked);
  ASSERT_TRUE(used.ok) << used.reason;
  const PairwiseResult refused = RegisterPair(input);
  std::printf("9 matches turned 60°: %.0f %% of the turn kept, pairs %.1f mm from the motion\n",
              100 * used.visual_turn_kept, used.rms_mm);
  EXPECT_GT(used.rms_mm, 5.0);
  EXPECT_FALSE(refused.ok);
  EXPECT_EQ(refused.contacts, 0);
  EXPECT_NEAR(refused.rms_mm, used.rms_mm, 1e-9);
  EXPECT_NE(refused.reason.find("disagree with their motion"), std::string::npos) << refused.reason;

  // The same patch turned by 2°: the pairs stay close to what the prior keeps, and it is used.
  PairwiseInput small;
  const Rigid3 turn = Rigid3::Translation(patch) *
                      Rigid3::FromAxisAngle({0.3, 1, 0.2}, 2 * M_PI / 180) *
                      Rigid3::Translation(-patch);
  for (const PointMatch& m : input.All(MatchKind::kVisual))
    small.Pairs("sift", MatchKind::kVisual).push_back({m.previous, turn * m.previous});
  const PairwiseResult kept = RegisterPair(small);
  ASSERT_TRUE(kept.ok) << kept.reason;
  EXPECT_LT(kept.rms_mm, 2.0);
}

// A correspondence source is one more set: its kind decides how it weighs, its name only what
// the messages call it.
TEST(PairwiseRegistrationTest, AnySourcesSetCountsByItsKind) {
  std::mt19937 rng = test::Rng(3);
  Scene scene = MakeScene(rng, 0, 0, 12, 0.0);
  const PairwiseResult contacts = RegisterPair(scene.input);
  ASSERT_TRUE(contacts.ok) << contacts.reason;
  EXPECT_EQ(contacts.contacts, 12);
  // Finger pads as a second contact source: their pairs join the fingertips'.
  const Scene more = MakeScene(rng, 0, 0, 5, 0.0);
  PairwiseInput with_pads = scene.input;
  with_pads.Pairs("pads", MatchKind::kContact) = more.input.All(MatchKind::kContact);
  const PairwiseResult pads = RegisterPair(with_pads);
  ASSERT_TRUE(pads.ok) << pads.reason;
  EXPECT_EQ(pads.contacts, 17);
  // Visual pairs under another name are visual pairs: RANSAC keeps the consistent ones.
  PairwiseInput visual;
  visual.Pairs("depth edges", MatchKind::kVisual) =
      MakeScene(rng, 40, 0, 0, 0.0).input.All(MatchKind::kVisual);
  const PairwiseResult edges = RegisterPair(visual);
  ASSERT_TRUE(edges.ok) << edges.reason;
  EXPECT_GE(edges.visual_inliers, 36);  // Of 40, with 1 mm noise per axis.
  EXPECT_EQ(edges.contacts, 0);
}

TEST(PairwiseRegistrationTest, NothingToGoOnIsASkippedFrameWithItsReason) {
  const PairwiseResult none = RegisterPair({});
  EXPECT_FALSE(none.ok);
  EXPECT_NE(none.reason.find("too few correspondences"), std::string::npos) << none.reason;
  // Two contacts and a handful of inconsistent matches are not enough either.
  std::mt19937 rng = test::Rng(2);
  Scene scene = MakeScene(rng, 8, 0, 2, 1.0);
  const PairwiseResult few = RegisterPair(scene.input);
  EXPECT_FALSE(few.ok);
  // The reason names each source's matches.
  EXPECT_NE(few.reason.find("8 sift and 0 shot feature matches"), std::string::npos) << few.reason;
  PairwiseOptions bad;
  bad.contact_weight = -1;
  EXPECT_THROW(RegisterPair(scene.input, bad), std::invalid_argument);
}

}  // namespace
}  // namespace ihs::fusion

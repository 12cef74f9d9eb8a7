// The grasp-side prior: the object seen in a hand lies on its palm's side, for right and left
// hands, balls, boxes and bottles, seen from the palm's side and from the back of the hand; the
// pose turned over (palm for back) is penalised, the true one is not.

#include "tracker/grasp_side.h"

#include <gtest/gtest.h>

#include <string>

#include "tools/synth/sequence.h"
#include "tracker/hand_search.h"
#include "tracker/procedural_hand.h"
#include "tracker/segmentation.h"

namespace ihs::tracker {
namespace {

struct GraspCase {
  const char* object;
  double azimuth_deg;
  bool left_hand;
  double hand_scale;
  int seed;
};

TEST(GraspSideTest, AHeldObjectLiesOnThePalmsSideOfTheTruePoseNotOfItsTurnedOverOne) {
  // Azimuths round the object: the hand beside it, in front of it (its back to the camera) and
  // behind it (its palm and fingertips toward the camera, the object hiding the fingers).
  const GraspCase cases[] = {
      {"sphere", 0, false, 1.0, 41},         {"sphere", -75, true, 0.85, 42},
      {"box", 60, false, 1.15, 43},          {"water-bottle", -40, true, 1.0, 44},
      {"small-bottle", 100, false, 0.9, 45}, {"bowling-pin", 20, true, 1.1, 46}};
  for (const GraspCase& c : cases) {
    SCOPED_TRACE(std::string(c.object) + " azimuth " + std::to_string(c.azimuth_deg) +
                 (c.left_hand ? " left" : " right"));
    synth::SequenceOptions options;
    options.object = c.object;
    options.scripted.frames = 60;
    options.scripted.turns = 0.25;
    options.scripted.start_azimuth_deg = c.azimuth_deg;
    options.left_hand = c.left_hand;
    options.hand_scale = c.hand_scale;
    options.seed = c.seed;
    options.last_frame = 4;
    synth::SequenceRenderer renderer(options);
    const synth::RenderedFrame rendered = renderer.Render(4);
    const Segmentation segmentation =
        Segmenter(renderer.options().intrinsics, SegmentationOptions()).Segment(rendered.frame);
    // The thumb's opposition counted too (off by default): a true grasp is not penalised.
    GraspSideOptions with_thumb;
    with_thumb.opposition_weight = 10;
    const std::optional<GraspSide> side = GraspSide::Of(segmentation, with_thumb);
    ASSERT_TRUE(side.has_value());

    // The estimated middle (of the part by the hand) lies within a quarter of the object's
    // bounding box's diagonal of its middle (measured: 2–59 mm; the pin's is 59 mm off).
    Eigen::Vector3d middle = Eigen::Vector3d::Zero();
    Eigen::Vector3f low = Eigen::Vector3f::Constant(1e9f), high = -low;
    for (const Eigen::Vector3f& v : renderer.object_mesh().vertices) {
      middle += v.cast<double>();
      low = low.cwiseMin(v), high = high.cwiseMax(v);
    }
    middle =
        rendered.cam_from_object * Eigen::Vector3d(middle / renderer.object_mesh().vertices.size());
    EXPECT_LT((side->centre() - middle).norm(), 0.25 * (high - low).norm());

    const HandModel& hand = renderer.hand();
    const bool right = IsRightHand(hand);
    EXPECT_EQ(right, !c.left_hand);
    const HandPose truth = PoseFromBoneTransforms(hand, rendered.cam_from_bone);
    const PalmAxes palm = PalmAxesOf(hand, hand.JointPositions(ForwardKinematics(hand, truth)));
    EXPECT_GT(side->Cosine(palm, right), 0.3);
    // The thumb holds the object against the fingers: across its middle from them (seen from
    // the middle estimated from the part by the hand: −0.99 … +0.05; the tall bottle's lies
    // below the hand).
    EXPECT_LT(side->Opposition(hand, hand.JointPositions(ForwardKinematics(hand, truth))),
              GraspSideOptions().max_opposition_cosine);
    EXPECT_EQ(side->Penalty(hand, truth, right), 0.0);
    // Turned over, the palm faces away: penalised by at least the weight times the margin.
    EXPECT_GT(side->Penalty(hand, TurnedOver(hand, truth), right),
              GraspSideOptions().weight * (GraspSideOptions().min_cosine + 0.3));
    // The wrong side's normal for the hand's side reverses the verdict.
    EXPECT_LT(side->Cosine(palm, !right), -0.3);
  }
}

TEST(GraspSideTest, NoObjectByTheHandOrTheWeightAtZeroMeansNoPrior) {
  Segmentation segmentation;
  for (int k = 0; k < 400; ++k) segmentation.hand_points.emplace_back(0.1f * k, 0.0f, 500.0f);
  EXPECT_FALSE(GraspSide::Of(segmentation, GraspSideOptions()).has_value());
  // Object points beyond the hand's reach (a table 300 mm away) are not a held object.
  for (int k = 0; k < 400; ++k) segmentation.object_points.emplace_back(0.1f * k, 0.0f, 800.0f);
  EXPECT_FALSE(GraspSide::Of(segmentation, GraspSideOptions()).has_value());
  // Near the hand they are; with the weight at 0 the prior is off.
  for (auto& p : segmentation.object_points) p.z() = 540.0f;
  EXPECT_TRUE(GraspSide::Of(segmentation, GraspSideOptions()).has_value());
  GraspSideOptions off;
  off.weight = 0;
  EXPECT_FALSE(GraspSide::Of(segmentation, off).has_value());
  GraspSideOptions bad;
  bad.min_cosine = 2;
  EXPECT_THROW(bad.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace ihs::tracker

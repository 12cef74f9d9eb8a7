// The object stage's correspondence sources: which the options turn on, in the registration's
// order, and what each found per frame; the object's state for the status line.

#include "app/scan_stages.h"

#include <gtest/gtest.h>

#include "fusion/correspondence_source.h"
#include "tests/frame_fixtures.h"

namespace ihs::app {
namespace {

std::vector<std::string> Names(const ScannerOptions& options) {
  std::vector<std::string> names;
  for (const auto& source : MakeCorrespondenceSources(options, CameraIntrinsics::Carmine109())) {
    names.push_back(source->name());
  }
  return names;
}

TEST(ScanStagesTest, TheOptionsChooseTheCorrespondenceSources) {
  ScannerOptions options;
  EXPECT_EQ(Names(options), (std::vector<std::string>{"sift", "contacts"}));
  options.scan.features_3d = true;
  EXPECT_EQ(Names(options), (std::vector<std::string>{"sift", "shot", "contacts"}));
  options.scan.features_2d = false;
  options.scan.features_3d = false;
  EXPECT_EQ(Names(options), (std::vector<std::string>{"contacts"}));
}

TEST(ScanStagesTest, EachSourcesMatchesAreCountedPerFrame) {
  ScannerOptions options;
  options.scan.fuse_without_hand = true;  // No tracker here: the frames go straight to fusion.
  options.scan.features_3d = true;
  const CameraIntrinsics intrinsics = CameraIntrinsics::Carmine109();
  ObjectStage stage(options, intrinsics);
  const Eigen::Vector3d semi_axes(40, 30, 25);
  for (int i = 0; i < 2; ++i) {
    FramePacket packet;
    const Rigid3 pose =
        Rigid3::Translation({0, 0, 600}) * Rigid3::FromAxisAngle({0, 1, 0}, 0.05 * i);
    auto frame = std::make_shared<Frame>(test::RenderEllipsoid(intrinsics, pose, semi_axes));
    packet.object_mask.resize(frame->depth_mm.size());
    for (size_t p = 0; p < frame->depth_mm.size(); ++p)
      packet.object_mask[p] = frame->depth_mm[p] != 0;
    packet.frame = frame;
    stage.Process(packet);
    EXPECT_TRUE(packet.Registered()) << packet.fusion.reason;
    ASSERT_EQ(packet.matches.size(), 3u);
    EXPECT_EQ(packet.matches[0].first, "sift");
    EXPECT_EQ(packet.matches[1].first, "shot");
    EXPECT_EQ(packet.matches[2].first, "contacts");
    // No hand: no contact pairs; the first frame has nothing to match with.
    EXPECT_EQ(packet.matches[2].second, 0);
    if (i == 0) {
      EXPECT_EQ(packet.matches[1].second, 0);
    }
  }
}

TEST(ScanStagesTest, TheObjectsStateSaysWhenTheHandTurnedIt) {
  FramePacket packet;
  EXPECT_STREQ(packet.ObjectState(), "paused") << "no hand pose, not fused";
  packet.fusion.status = fusion::FusionStatus::kFused;
  EXPECT_STREQ(packet.ObjectState(), "registered");
  packet.fusion.hand_carried_deg = 2.5;
  EXPECT_STREQ(packet.ObjectState(), "turned by the hand");
}

}  // namespace
}  // namespace ihs::app

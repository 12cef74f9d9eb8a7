// The object stage's correspondence sources: which the options turn on, in the registration's
// order, and what each found per frame; the object's state for the status line.

#include "app/scan_stages.h"

#include <gtest/gtest.h>

#include <cmath>

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

// A contact pair joins two frames' contacts: after a frame whose grasp the tracker only held
// (tracker::GraspHold), the next frame's pairs are loose even where its contacts were found,
// and on an object whose surface fixes its motion (a flat ellipsoid turning, which ICP has
// seen fix every direction) they are not used (FusionOptions::loose_contact_mm); a frame later
// they are.
TEST(ScanStagesTest, AContactPairIsAsLooseAsTheLooserOfItsTwoFrames) {
  ScannerOptions options;
  options.scan.fuse_without_hand = true;  // No tracker here: the packets carry its contacts.
  options.scan.features_2d = false;
  const CameraIntrinsics intrinsics = CameraIntrinsics::Carmine109();
  ObjectStage stage(options, intrinsics);
  const Eigen::Vector3d semi_axes(50, 28, 12);
  auto pose = [](int i) {
    return Rigid3::Translation({5, -10, 600}) *
           Rigid3::FromAxisAngle(Eigen::Vector3d(0.3, 1, 0.2), i * 4 * M_PI / 180) *
           Rigid3::FromAxisAngle({1, 0, 0}, 0.3);
  };
  // Six points of the surface round its largest section.
  std::vector<Eigen::Vector3d> touched;
  for (int k = 0; k < 6; ++k) {
    const double angle = 2 * M_PI * k / 6;
    touched.push_back(semi_axes.cwiseProduct(Eigen::Vector3d(std::cos(angle), std::sin(angle), 0)));
  }
  // Frames 0-9 without contacts (ICP sees the surface fix every direction), 10 with a held
  // grasp, 11 and 12 with found contacts and their pairs.
  constexpr int kHeld = 10;
  std::vector<bool> used;
  for (int i = 0; i <= kHeld + 2; ++i) {
    FramePacket packet;
    auto frame = std::make_shared<Frame>(test::RenderEllipsoid(intrinsics, pose(i), semi_axes));
    packet.object_mask.resize(frame->depth_mm.size());
    for (size_t p = 0; p < frame->depth_mm.size(); ++p)
      packet.object_mask[p] = frame->depth_mm[p] != 0;
    packet.frame = frame;
    if (i >= kHeld) {
      tracker::Contacts& contacts = packet.track.contacts;
      contacts.bones = {1, 2};
      contacts.threshold_mm = 5;
      contacts.held_frames = i == kHeld ? 1 : 0;
      for (int k = 0; i > kHeld && k < 6; ++k) {
        packet.track.contact_pairs.push_back({k, pose(i - 1) * touched[k], pose(i) * touched[k]});
      }
    }
    stage.Process(packet);
    EXPECT_TRUE(packet.Registered()) << packet.fusion.reason;
    used.push_back(packet.fusion.ContactsUsed());
  }
  EXPECT_FALSE(used[kHeld + 1]) << "its pairs join the held grasp of the frame before";
  EXPECT_TRUE(used[kHeld + 2]) << "its pairs join two frames' found contacts";
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

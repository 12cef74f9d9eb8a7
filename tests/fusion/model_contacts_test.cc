// Fingertip contacts against the model: a TSDF sphere seen from all round, fingertips (patches
// of points) on its surface, hovering above it or inside it, where the camera never saw it.

#include "fusion/model_contacts.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <stdexcept>
#include <vector>

#include "tests/frame_fixtures.h"

namespace ihs::fusion {
namespace {

constexpr double kRadius = 35.0;

// A fingertip: 50 points in a 6 mm patch around `direction`, `height_mm` above the sphere's
// surface (negative: inside), volume frame.
std::vector<Eigen::Vector3f> Fingertip(const Eigen::Vector3d& direction, double height_mm) {
  const Eigen::Vector3d n = direction.normalized();
  const Eigen::Vector3d a = n.unitOrthogonal(), b = n.cross(a);
  std::vector<Eigen::Vector3f> points;
  for (int k = 0; k < 50; ++k) {
    const double angle = k * 2.399963, r = 3.0 * std::sqrt((k + 0.5) / 50);  // Golden spiral.
    const Eigen::Vector3d p = n * kRadius + r * (std::cos(angle) * a + std::sin(angle) * b);
    points.push_back((p.normalized() * (kRadius + height_mm)).cast<float>());
  }
  return points;
}

class ModelContactsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    volume_ = new TsdfVolume();
    const CameraIntrinsics intrinsics = CameraIntrinsics::Carmine109();
    for (const Rigid3& view : test::ViewsAround(600)) {
      volume_->Integrate(
          test::RenderEllipsoid(intrinsics, view, Eigen::Vector3d::Constant(kRadius)), {},
          intrinsics, view);
    }
  }
  static void TearDownTestSuite() { delete volume_; }

  // The hand: the fingertips' points one after the other, each fingertip's indices, the camera
  // 600 mm in front of the volume's centre; `moved` shifts the current frame's hand.
  struct Hand {
    std::vector<Eigen::Vector3f> previous, current;
    std::vector<std::vector<int>> fingertips;
  };
  static Hand MakeHand(const std::vector<std::vector<Eigen::Vector3f>>& tips,
                       const Eigen::Vector3f& moved = Eigen::Vector3f::Zero()) {
    Hand hand;
    for (const auto& tip : tips) {
      hand.fingertips.emplace_back();
      for (const Eigen::Vector3f& p : tip) {
        hand.fingertips.back().push_back(static_cast<int>(hand.previous.size()));
        hand.previous.push_back(p + kCamera);
        hand.current.push_back(p + kCamera + moved);
      }
    }
    return hand;
  }
  static std::vector<ModelContact> Find(const Hand& hand, const ModelContactOptions& options) {
    const Rigid3 object_from_cam = Rigid3::Translation(-kCamera.cast<double>());
    return FindModelContacts(*volume_, object_from_cam, hand.previous, hand.current,
                             hand.fingertips, options);
  }
  static inline const Eigen::Vector3f kCamera{0, 0, 600};
  static inline TsdfVolume* volume_ = nullptr;
};

TEST_F(ModelContactsTest, FingertipsOnTheSurfaceAreContactsAndHoveringOnesAreNot) {
  ModelContactOptions options;
  options.enabled = true;
  // Thumb and index pinch the ball from its sides, a third finger hovers 8 mm above its top.
  const Hand hand = MakeHand(
      {Fingertip({1, 0, 0}, 0.5), Fingertip({-1, 0.2, 0.3}, -1.0), Fingertip({0, 1, 0}, 8.0)},
      {2, -1, 0});
  const std::vector<ModelContact> contacts = Find(hand, options);
  ASSERT_EQ(contacts.size(), 100u);  // Both touching fingertips, every vertex of each.
  for (const ModelContact& contact : contacts) {
    EXPECT_LT(contact.vertex, 100);
    EXPECT_TRUE(contact.previous.isApprox(hand.previous[contact.vertex].cast<double>()));
    EXPECT_TRUE(contact.current.isApprox(hand.current[contact.vertex].cast<double>()));
  }
  // The hovering finger counts only when the distance allowed reaches it.
  options.distance_mm = 5.0;
  EXPECT_EQ(Find(MakeHand({Fingertip({0, 1, 0}, 8.0), Fingertip({1, 0, 0}, 0.0)}), options).size(),
            0u);
}

TEST_F(ModelContactsTest, OneFingertipAloneCountsOnlyWhenAllowedAndNothingWithoutAModel) {
  ModelContactOptions options;
  options.enabled = true;
  const Hand one = MakeHand({Fingertip({0, 0, -1}, 0.0), Fingertip({0, 1, 0}, 10.0)});
  EXPECT_TRUE(Find(one, options).empty());  // min_fingertips = 2: a lone finger may be sliding.
  options.min_fingertips = 1;
  EXPECT_EQ(Find(one, options).size(), 50u);
  // Off: nothing. Far from anything the model saw (outside the cube): nothing.
  options.enabled = false;
  EXPECT_TRUE(Find(one, options).empty());
  options.enabled = true;
  const Hand far = MakeHand({Fingertip({1, 0, 0}, 400.0), Fingertip({-1, 0, 0}, 400.0)});
  EXPECT_TRUE(Find(far, options).empty());
  // Hands of different sizes from frame to frame are not paired.
  Hand broken = MakeHand({Fingertip({1, 0, 0}, 0.0), Fingertip({-1, 0, 0}, 0.0)});
  broken.current.pop_back();
  EXPECT_TRUE(Find(broken, options).empty());
}

TEST_F(ModelContactsTest, BadOptionsAreRefusedNamingTheField) {
  ModelContactOptions options;
  options.distance_mm = 0;
  EXPECT_THROW(options.Check(), std::invalid_argument);
  options = {};
  options.min_vertex_share = 1.0;
  EXPECT_THROW(options.Check(), std::invalid_argument);
  options = {};
  options.min_fingertips = 0;
  EXPECT_THROW(options.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace ihs::fusion

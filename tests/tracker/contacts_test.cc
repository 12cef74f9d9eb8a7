// The paper's contact rule on the procedural hand in its rest pose: object points laid out at a
// chosen distance outside chosen fingertips, and which fingertips the rule calls contacts.
#include "tracker/contacts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "core/point_kd_tree.h"
#include "tracker/hand_data.h"

namespace ihs::tracker {
namespace {

class ContactsTest : public ::testing::Test {
 protected:
  ContactsTest() : hand_(LoadHandTemplate("procedural")), detector_(hand_) {
    mesh_ = hand_.rest_mesh;
    if (!mesh_.HasNormals()) mesh_.ComputeVertexNormals();
    ends_ = hand_.EndEffectors();
  }

  /// Object points at `distance_mm` outside each listed fingertip (end-effector index →
  /// distance), along its vertices' normals: every vertex of that fingertip is at most that far
  /// from them, and a convex fingertip none nearer.
  Contacts Detect(const std::map<int, float>& distance_mm) const {
    std::vector<Eigen::Vector3f> points;
    for (const auto& [end, distance] : distance_mm) {
      for (int v : detector_.fingertip_vertices()[end])
        points.push_back(mesh_.vertices[v] + distance * mesh_.normals[v]);
    }
    PointKdTree tree(points);
    return detector_.Detect(mesh_.vertices, tree);
  }

  bool Has(const Contacts& contacts, int end) const {
    return std::count(contacts.bones.begin(), contacts.bones.end(), ends_[end]) > 0;
  }

  HandModel hand_;
  ContactDetector detector_;
  TriangleMesh mesh_;
  std::vector<int> ends_;
};

TEST_F(ContactsTest, TwoTouchingFingertipsAreContactsAtTheFirstThreshold) {
  const int thumb = 4, index = 3;
  const Contacts contacts = Detect({{thumb, 0.3f}, {index, 0.3f}});
  ASSERT_EQ(contacts.bones.size(), 2u);
  EXPECT_TRUE(Has(contacts, thumb) && Has(contacts, index));
  EXPECT_DOUBLE_EQ(contacts.threshold_mm, 1.0);
  EXPECT_EQ(contacts.vertices.size(), detector_.fingertip_vertices()[thumb].size() +
                                          detector_.fingertip_vertices()[index].size());
}

TEST_F(ContactsTest, TheThresholdGrowsUntilItFindsTheGraspsSecondFingertip) {
  const int thumb = 4, index = 3;
  const Contacts contacts = Detect({{thumb, 0.3f}, {index, 7.2f}});
  ASSERT_EQ(contacts.bones.size(), 2u);
  EXPECT_TRUE(Has(contacts, thumb) && Has(contacts, index));
  // Found at the first step past the fingertip's distance (a few of its vertices may sit a
  // little nearer the points than 7.2 mm where its surface curves).
  EXPECT_GE(contacts.threshold_mm, 5.0);
  EXPECT_LE(contacts.threshold_mm, 7.5);
}

TEST_F(ContactsTest, ALoneFingertipCountsOnlyWhereItTouches) {
  const int thumb = 4, middle = 2;
  // Touching, with no second fingertip within the bound: the touching one alone.
  Contacts contacts = Detect({{thumb, 0.3f}});
  ASSERT_EQ(contacts.bones.size(), 1u);
  EXPECT_TRUE(Has(contacts, thumb));
  EXPECT_DOUBLE_EQ(contacts.threshold_mm, 1.0);
  // A fingertip hovering 5 mm off with no second one to make a grasp is no contact.
  contacts = Detect({{middle, 5.0f}});
  EXPECT_TRUE(contacts.bones.empty());
  EXPECT_TRUE(contacts.vertices.empty());
}

}  // namespace
}  // namespace ihs::tracker

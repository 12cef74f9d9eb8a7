// The paper's contact rule on the procedural hand in its rest pose: object points laid out at a
// chosen distance outside chosen fingertips, and which fingertips the rule calls contacts.
#include "tracker/contacts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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

  /// Object points on a surface touching fingertip `end` at its very tip (a plane when
  /// `radius_mm` is 0, else a ball of that radius), `gap_mm` off it, seen only 20-30 mm from
  /// the touch (the finger hides the rest): the tip's vertices are all 12 mm or more from them.
  /// With `wall`, a second face rises from the plane 22 mm beside the touch (a step).
  std::vector<Eigen::Vector3f> SurfaceAtTip(int end, float gap_mm, float radius_mm,
                                            bool wall = false) const {
    Eigen::Vector3f hand_centre = Eigen::Vector3f::Zero(), tip_centre = Eigen::Vector3f::Zero();
    for (const Eigen::Vector3f& v : mesh_.vertices) hand_centre += v;
    hand_centre /= static_cast<float>(mesh_.vertices.size());
    const std::vector<int>& tip = detector_.fingertip_vertices()[end];
    for (int v : tip) tip_centre += mesh_.vertices[v];
    tip_centre /= static_cast<float>(tip.size());
    const Eigen::Vector3f n = (tip_centre - hand_centre).normalized();  // Along the finger.
    float reach = -1e9f;
    Eigen::Vector3f touch = tip_centre;
    for (int v : tip) {
      if (n.dot(mesh_.vertices[v]) > reach)
        reach = n.dot(mesh_.vertices[v]), touch = mesh_.vertices[v];
    }
    touch += (reach - n.dot(touch) + gap_mm) * n;
    const Eigen::Vector3f a = n.unitOrthogonal(), b = n.cross(a);
    std::vector<Eigen::Vector3f> points;
    for (float r = 20; r <= 30; r += 1) {
      for (int k = 0; k < 36; ++k) {
        const float angle = static_cast<float>(k * M_PI / 18);
        const Eigen::Vector3f along = std::cos(angle) * a + std::sin(angle) * b;
        if (radius_mm <= 0) {
          points.push_back(touch + r * along);
        } else {  // The point r along the ball's surface from the touch.
          const float t = r / radius_mm;
          points.push_back(touch + radius_mm * (std::sin(t) * along + (1 - std::cos(t)) * n));
        }
      }
    }
    for (float h = 1; wall && h <= 20; h += 1) {
      for (float t = -10; t <= 10; t += 1) points.push_back(touch + 22 * a - h * n + t * b);
    }
    return points;
  }

  Contacts DetectOn(const ContactDetector& detector, const std::vector<Eigen::Vector3f>& points) {
    PointKdTree tree(points);
    return detector.Detect(mesh_.vertices, tree);
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

// Two fingertips pressed on an object whose surface the camera sees only around them (the
// fingers hide what is under them): too far from the seen points for the paper's rule, found
// where the surface is continued under the fingertips; the same fingertips lifted 8 mm off are
// not in contact either way.
TEST_F(ContactsTest, TheSurfaceContinuedUnderTheFingertipsFindsTheirContacts) {
  const int thumb = 4, index = 3;
  ContactOptions surface;
  surface.surface_patch_mm = 35.0;  // The seen points lie 20-30 mm from the touch.
  const ContactDetector continued(hand_, surface);
  ContactOptions paper = surface;
  paper.surface_mm = 0;
  const ContactDetector paper_rule(hand_, paper);
  for (const float radius : {0.0f, 40.0f}) {  // A box's face, a ball.
    SCOPED_TRACE(radius);
    std::vector<Eigen::Vector3f> touching = SurfaceAtTip(thumb, 0.3f, radius);
    const std::vector<Eigen::Vector3f> other = SurfaceAtTip(index, 0.3f, radius);
    touching.insert(touching.end(), other.begin(), other.end());
    EXPECT_TRUE(DetectOn(paper_rule, touching).bones.empty());
    const Contacts found = DetectOn(continued, touching);
    ASSERT_EQ(found.bones.size(), 2u);
    EXPECT_TRUE(Has(found, thumb) && Has(found, index));
    EXPECT_LE(found.threshold_mm, 4.0);

    std::vector<Eigen::Vector3f> lifted = SurfaceAtTip(thumb, 8.0f, radius);
    const std::vector<Eigen::Vector3f> other_lifted = SurfaceAtTip(index, 8.0f, radius);
    lifted.insert(lifted.end(), other_lifted.begin(), other_lifted.end());
    EXPECT_TRUE(DetectOn(continued, lifted).bones.empty());
  }
  // Too few points around a fingertip: nothing is continued.
  ContactOptions needs_more = surface;
  needs_more.surface_min_points = 100000;
  std::vector<Eigen::Vector3f> touching = SurfaceAtTip(thumb, 0.3f, 0.0f);
  const std::vector<Eigen::Vector3f> other = SurfaceAtTip(index, 0.3f, 0.0f);
  touching.insert(touching.end(), other.begin(), other.end());
  EXPECT_TRUE(DetectOn(ContactDetector(hand_, needs_more), touching).bones.empty());
  // A step beside each touch (two faces): no sphere or plane explains the points, so nothing
  // is continued.
  std::vector<Eigen::Vector3f> step = SurfaceAtTip(thumb, 0.3f, 0.0f, true);
  const std::vector<Eigen::Vector3f> other_step = SurfaceAtTip(index, 0.3f, 0.0f, true);
  step.insert(step.end(), other_step.begin(), other_step.end());
  EXPECT_TRUE(DetectOn(continued, step).bones.empty());
  ContactOptions bad;
  bad.surface_mm = -1;
  EXPECT_THROW(ContactDetector(hand_, bad), std::invalid_argument);
  bad = ContactOptions();
  bad.surface_max_rms_mm = 0;
  EXPECT_THROW(ContactDetector(hand_, bad), std::invalid_argument);
}

}  // namespace
}  // namespace ihs::tracker

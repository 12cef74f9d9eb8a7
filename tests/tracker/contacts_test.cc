// The paper's contact rule on the procedural hand in its rest pose: object points laid out at a
// chosen distance outside chosen fingertips, and which fingertips the rule calls contacts.
#include "tracker/contacts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "core/point_kd_tree.h"
#include "tracker/hand_data.h"
#include "tracker/release_watch.h"

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
  // With surface_trim, the face nearest each fingertip is continued: the touches are found at
  // the first thresholds, as on the plane alone.
  ContactOptions trimmed = surface;
  trimmed.surface_trim = true;
  const Contacts on_step = DetectOn(ContactDetector(hand_, trimmed), step);
  EXPECT_TRUE(Has(on_step, thumb) && Has(on_step, index));
  EXPECT_LE(on_step.threshold_mm, 4.0);
  ContactOptions bad;
  bad.surface_mm = -1;
  EXPECT_THROW(ContactDetector(hand_, bad), std::invalid_argument);
  bad = ContactOptions();
  bad.surface_max_rms_mm = 0;
  EXPECT_THROW(ContactDetector(hand_, bad), std::invalid_argument);
}

TEST_F(ContactsTest, AFingertipsContactDistanceIsWhereItStartsToCount) {
  const int thumb = 4, index = 3, middle = 2;
  const Contacts contacts = Detect({{thumb, 0.3f}, {index, 7.2f}});
  ASSERT_EQ(contacts.tip_distance_mm.size(), ends_.size());
  EXPECT_LE(contacts.tip_distance_mm[thumb], 1.0);
  // The index counts from its distance on: the grown threshold is the first step past it.
  EXPECT_GT(contacts.tip_distance_mm[index], 5.0);
  EXPECT_LE(contacts.tip_distance_mm[index], contacts.threshold_mm);
  EXPECT_GT(contacts.tip_distance_mm[index], contacts.threshold_mm - 0.5 - 1e-9);
  // A fingertip with no object point near it has only a far contact distance.
  EXPECT_GT(contacts.tip_distance_mm[middle], 7.2);
  // Limits keep a fingertip out at any threshold.
  std::vector<double> limits(ends_.size(), kNoContactMm);
  limits[index] = -1;
  const Contacts limited = detector_.Select(contacts.tip_distance_mm, &limits);
  EXPECT_FALSE(Has(limited, index));
  EXPECT_TRUE(Has(limited, thumb));
  EXPECT_THROW(detector_.Select({1.0, 2.0}), std::invalid_argument);
}

// The contact distances of a grasp's two fingertips (thumb 4, index 3) over frames.
class ReleaseWatchTest : public ::testing::Test {
 protected:
  ReleaseWatchTest() { options_.enabled = true; }
  static std::vector<double> Tips(double index_mm, double thumb_mm) {
    return {30.0, 25.0, 20.0, index_mm, thumb_mm};
  }
  ReleaseOptions options_;
  const std::vector<size_t> grasp_{3, 4};
};

TEST_F(ReleaseWatchTest, AGraspWhoseFingertipsRiseTogetherIsLetGoUntilTheyComeBack) {
  ReleaseWatch watch(options_, 5);
  // Held: the fitted fingertips wander by a millimetre or two.
  for (double d : {2.0, 3.0, 2.5, 3.5, 2.8}) EXPECT_FALSE(watch.Observe(Tips(d, d - 1), grasp_));
  // Let go: both rise by 7-8 mm within three frames (on the second of them by 5 or more).
  EXPECT_FALSE(watch.Observe(Tips(5.0, 4.5), grasp_));
  EXPECT_TRUE(watch.Observe(Tips(9.5, 8.5), grasp_));
  std::vector<double> limits = watch.Limits();
  EXPECT_LT(limits[3], 0);
  EXPECT_LT(limits[4], 0);
  EXPECT_GT(limits[0], 100);
  // Swinging back and coming down again: out until each is within return_mm (2.5) of where it
  // was before (2.8 / 1.8 mm).
  for (double d : {10.0, 10.0, 9.0, 6.0}) {
    watch.Observe(Tips(d, d), {});
    EXPECT_LT(watch.Limits()[3], 0);
  }
  watch.Observe(Tips(4.5, 5.2), {});
  EXPECT_GT(watch.Limits()[3], 100);  // 4.5 <= 2.8 + 2.5.
  EXPECT_LT(watch.Limits()[4], 0);    // 5.2 > 1.8 + 2.5, and less than rise_mm below 10.
  watch.Observe(Tips(3.0, 2.0), {});
  EXPECT_GT(watch.Limits()[4], 100);
  // A re-grasp the fit places farther off than the last grasp: back once it has come down by
  // rise_mm from the farthest it went.
  ReleaseWatch again(options_, 5);
  for (double d : {2.0, 2.5, 2.0}) again.Observe(Tips(d, d), grasp_);
  ASSERT_TRUE(again.Observe(Tips(9.0, 9.0), grasp_));
  for (double d : {12.0, 12.0, 8.0}) again.Observe(Tips(d, d), {});
  EXPECT_LT(again.Limits()[3], 0);
  again.Observe(Tips(6.5, 6.5), {});
  EXPECT_GT(again.Limits()[3], 100);
}

TEST_F(ReleaseWatchTest, OneFingertipDriftingOffWhileTheOtherHoldsIsNoRelease) {
  ReleaseWatch watch(options_, 5);
  double thumb = 1.0;
  for (int frame = 0; frame < 10; ++frame, thumb += 2.0)
    EXPECT_FALSE(watch.Observe(Tips(2.0 + 0.3 * (frame % 2), thumb), grasp_));
  // Nor with the watch off, or with a single fingertip.
  ReleaseOptions off;
  ReleaseWatch idle(off, 5);
  idle.Observe(Tips(2.0, 2.0), grasp_);
  EXPECT_FALSE(idle.Observe(Tips(12.0, 12.0), grasp_));
  ReleaseWatch lone(options_, 5);
  lone.Observe(Tips(2.0, 2.0), {4});
  EXPECT_FALSE(lone.Observe(Tips(12.0, 12.0), {4}));
  // A let-go fingertip that never comes back counts again after max_frames.
  ReleaseOptions brief = options_;
  brief.max_frames = 3;
  ReleaseWatch watch2(brief, 5);
  watch2.Observe(Tips(2.0, 2.0), grasp_);
  ASSERT_TRUE(watch2.Observe(Tips(12.0, 12.0), grasp_));
  for (int frame = 0; frame < 2; ++frame) watch2.Observe(Tips(12.0, 12.0), {});
  EXPECT_LT(watch2.Limits()[3], 0);
  watch2.Observe(Tips(12.0, 12.0), {});
  EXPECT_GT(watch2.Limits()[3], 100);
  ReleaseOptions bad = options_;
  bad.rise_mm = 0;
  EXPECT_THROW(ReleaseWatch(bad, 5), std::invalid_argument);
}

}  // namespace
}  // namespace ihs::tracker

#pragma once
// The paper's pairwise registration (§3.3): the object's motion between the previous and the
// current frame from sets of corresponding object points — in the paper SIFT matches
// back-projected to 3D, ISS3D + CSHOT matches, and the fingertip contacts the hand tracker holds;
// here whatever sources correspondence_source.h lists — as the rigid transform minimising
// E = E_feat2d + E_feat3d + γt·E_contact (sums of squared point distances). The visual sets are
// cleaned by RANSAC first; the contacts come from the tracker and are kept.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "core/rigid3.h"

namespace ihs::fusion {

/// One object point seen in both frames (camera frame, mm).
struct PointMatch {
  Eigen::Vector3d previous;
  Eigen::Vector3d current;
  /// What identifies the point from frame to frame where its source knows it (a contact's
  /// touching skin point: the hand model's vertex index); -1: nothing.
  int id = -1;
};

/// How the registration uses a set of pairs: visual pairs (features) are cleaned by RANSAC
/// together and weigh PairwiseOptions::visual_weight each; contact pairs come from the hand, are
/// checked against the visual motion and weigh γt (PairwiseOptions::contact_weight).
enum class MatchKind { kVisual, kContact };

/// One source's pairs (correspondence_source.h), by the source's name.
struct MatchSet {
  std::string source;
  MatchKind kind = MatchKind::kVisual;
  std::vector<PointMatch> pairs;
};

/// The correspondences of one frame pair, one set per source.
struct PairwiseInput {
  std::vector<MatchSet> sets;

  /// The pairs of `source`; an empty set of `kind` is added when there is none.
  std::vector<PointMatch>& Pairs(const std::string& source, MatchKind kind);
  /// Every pair of `kind`, in the sets' order.
  std::vector<PointMatch> All(MatchKind kind) const;
};

/// Options of the pairwise registration (defaults: the paper's γt; RANSAC as usual).
struct PairwiseOptions {
  /// γt, weight of each contact pair against one visual pair (paper: 15; 0 ignores contacts).
  double contact_weight = 15.0;
  /// Weight of the visual pairs (0 ignores them: contacts only).
  double visual_weight = 1.0;
  /// RANSAC over the visual pairs: hypotheses, inlier distance (mm) and the fewest inliers a
  /// visual set needs to count.
  int ransac_iterations = 300;
  double inlier_mm = 5.0;
  int min_visual_inliers = 6;
  /// Contact pairs needed when they are all there is.
  int min_contacts = 3;
  /// Contacts count only when they spread at least this far (their largest standard deviation
  /// in the previous frame, mm): one fingertip's patch (the paper asks for two contact bones)
  /// pins a point of the object, not its turn.
  double min_contact_spread_mm = 20.0;
  /// With a consistent visual set, contacts farther than `inlier_mm` from where its motion puts
  /// them are dropped (a mistracked fingertip; γt times hundreds of contact vertices would
  /// outweigh every feature match).
  bool check_contacts = true;
  /// A motion from the visual pairs alone (no grasp's contacts) keeps its turn in proportion to
  /// how well they fix it: shrunk toward none as the posterior mean under a zero-mean prior of
  /// this standard deviation per frame, degrees, given the pairs' own uncertainty
  /// (PairwiseResult::visual_turn_deg). A handful of matches on one small patch of a bottle's
  /// label turned the scan by 3-16° in frames where the truth turned by 0-2°, and ICP cannot
  /// undo a turn the surface leaves free (the bottle's spin). 0 keeps every turn as fitted.
  double visual_turn_prior_deg = 1.0;
  /// A motion whose pairs lie farther from it than this (RMS, mm) is not used: pairs picked as
  /// one motion within `inlier_mm` that the solve then leaves farther apart are not one motion
  /// (one fingertip's contacts, γt times each, pulling a handful of feature matches about their
  /// patch; a turn the prior above held back). On a left hand's box turn such motions (RMS
  /// 5.4-24 mm, where the others' are 0.3-0.8) moved the box 8-27 mm along its thinnest side in
  /// frames the truth moved it by 0.5 mm; ICP kept part of it (docs/fusion.md). ObjectFusion
  /// turns it off where the surface leaves a turn free (the motion is all that carries it).
  /// 0: never.
  double max_rms_mm = 5.0;
  /// Seed of the RANSAC sampling (results are deterministic).
  std::uint32_t seed = 1;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// The result: `current_from_previous` moves the object's points from the previous camera-frame
/// position to the current one.
struct PairwiseResult {
  bool ok = false;
  /// Why no motion was found (empty when ok).
  std::string reason;
  Rigid3 current_from_previous;
  /// Pairs used: visual inliers and contacts.
  int visual_inliers = 0;
  int contacts = 0;
  /// Contacts dropped because the visual inliers contradict them (PairwiseOptions::check_contacts).
  int contacts_rejected = 0;
  /// The contacts' spread (see PairwiseOptions::min_contact_spread_mm), mm.
  double contact_spread_mm = 0;
  /// The visual inliers' uncertainty of the turn about its worst-fixed axis (one standard
  /// deviation, degrees; 0 without visual inliers). See PairwiseOptions::visual_turn_prior_deg.
  double visual_turn_deg = 0;
  /// The share of the visual pairs' turn kept (1 where contacts took part or no prior is set).
  double visual_turn_kept = 1.0;
  /// Root mean square distance of the used pairs after the solve, mm.
  double rms_mm = 0;
};

/// The largest set of `matches` consistent with one rigid motion (RANSAC: hypotheses from three
/// pairs, `options`' iterations, inlier distance and seed), or none where it has fewer than
/// options.min_visual_inliers. With `rival`: the most inliers of a hypothesis turned by more
/// than `distinct_deg` from the motion kept (a pattern that repeats round an object lets two
/// motions explain its pairs).
std::vector<PointMatch> ConsistentPairs(const std::vector<PointMatch>& matches,
                                        const PairwiseOptions& options, double distinct_deg = 0,
                                        int* rival = nullptr);

/// Solves one frame pair.
PairwiseResult RegisterPair(const PairwiseInput& input, const PairwiseOptions& options = {});

}  // namespace ihs::fusion

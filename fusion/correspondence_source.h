#pragma once
// The registration's extension point: a CorrespondenceSource matches the current frame with the
// previous one and returns object points seen in both, as one named set of one kind
// (pairwise_registration.h says how each kind is weighed). The object stage holds a list of
// them built from the options (app/scan_stages.cc, MakeCorrespondenceSources) and hands their
// sets to ObjectFusion. A new registration term is one class implementing this interface, one
// option that turns it on and one line in that factory.
//
// The sources here: SIFT (sift_matcher.h), ISS3D + CSHOT (shot_matcher.h) and the fingertip
// contacts the hand tracker holds (HandContacts below).

#include <cstdint>
#include <string>
#include <vector>

#include "core/frame.h"
#include "fusion/pairwise_registration.h"

namespace ihs::fusion {

/// What a source may look at in a frame.
struct MatchContext {
  const Frame* frame = nullptr;
  /// Per pixel: non-zero where the object is (the posed hand's pixels removed).
  const std::vector<std::uint8_t>* object_mask = nullptr;
  /// The hand tracker's contact pairs in this frame (ids: the hand model's vertices), or null
  /// when the hand has no pose.
  const std::vector<PointMatch>* hand_contacts = nullptr;
};

/// Matches each frame with the one before (the previous call's). Not thread-safe: the fusion
/// thread owns its sources.
class CorrespondenceSource {
 public:
  virtual ~CorrespondenceSource() = default;
  /// The set's name in the registration's messages and in stats.json ("matches": {name: n}).
  virtual std::string name() const = 0;
  /// How the registration uses the pairs.
  virtual MatchKind kind() const = 0;
  /// The pairs between the previous call's frame and this one (camera frame, mm).
  virtual std::vector<PointMatch> Match(const MatchContext& context) = 0;

  /// The pairs as a named set.
  MatchSet MatchSetFor(const MatchContext& context) { return {name(), kind(), Match(context)}; }
};

/// The fingertip contacts the hand tracker holds (the paper's E_contact), as they come with the
/// frame: each pair is where a touching skin point was in the previous frame and is now, its id
/// the model's vertex.
class HandContacts final : public CorrespondenceSource {
 public:
  std::string name() const override { return "contacts"; }
  MatchKind kind() const override { return MatchKind::kContact; }
  std::vector<PointMatch> Match(const MatchContext& context) override {
    return context.hand_contacts ? *context.hand_contacts : std::vector<PointMatch>{};
  }
};

}  // namespace ihs::fusion

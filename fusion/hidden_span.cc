#include "fusion/hidden_span.h"

#include <algorithm>

#include "core/check.h"

namespace ihs::fusion {

void HiddenOptions::Check() const {
  IHS_CHECK_ARG(share >= 0 && share < 1, "fusion.hidden.share must be in [0, 1)");
  IHS_CHECK_ARG(reference_frames >= 1, "fusion.hidden.reference_frames must be at least 1");
  IHS_CHECK_ARG(shown_share >= 0 && shown_share <= 1,
                "fusion.hidden.shown_share must be in [0, 1]");
  IHS_CHECK_ARG(background_margin_mm >= 0, "fusion.hidden.background_margin_mm must be >= 0");
}

HiddenSpan::HiddenSpan(HiddenOptions options) : options_((options.Check(), options)) {}

bool HiddenSpan::Observe(int points) {
  const int most = reference_.empty() ? 0 : *std::max_element(reference_.begin(), reference_.end());
  if (options_.share > 0 && most > 0 && points < options_.share * most) {
    ++hidden_frames_;
    return true;
  }
  hidden_frames_ = 0;
  reference_.push_back(points);
  while (static_cast<int>(reference_.size()) > options_.reference_frames) reference_.pop_front();
  return false;
}

}  // namespace ihs::fusion

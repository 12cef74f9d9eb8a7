#include "tracker/release_watch.h"

#include <algorithm>

#include "core/check.h"
#include "tracker/contacts.h"

namespace ihs::tracker {

void ReleaseOptions::Check() const {
  IHS_CHECK_ARG(frames >= 1 && frames <= 30, "release.frames must be in [1, 30]");
  IHS_CHECK_ARG(rise_mm > 0 && return_mm >= 0, "release.rise_mm must be > 0, return_mm >= 0");
  IHS_CHECK_ARG(max_frames >= 1, "release.max_frames must be >= 1");
}

ReleaseWatch::ReleaseWatch(ReleaseOptions options, size_t tips)
    : options_(std::move(options)), tips_(tips) {
  options_.Check();
}

double ReleaseWatch::Rise(const Tip& tip, double distance_mm) const {
  if (tip.recent.empty() || distance_mm >= kNoContactMm) return 0;
  return distance_mm - *std::min_element(tip.recent.begin(), tip.recent.end());
}

bool ReleaseWatch::Observe(const std::vector<double>& tip_distance_mm,
                           const std::vector<size_t>& grasp) {
  IHS_CHECK_ARG(tip_distance_mm.size() == tips_.size(), "release watch: one distance per tip");
  bool let_go = false;
  if (options_.enabled && grasp.size() >= 2) {
    let_go = std::all_of(grasp.begin(), grasp.end(), [&](size_t t) {
      return t < tips_.size() && !tips_[t].let_go &&
             Rise(tips_[t], tip_distance_mm[t]) >= options_.rise_mm;
    });
  }
  for (size_t t = 0; t < tips_.size(); ++t) {
    Tip& tip = tips_[t];
    if (let_go && std::find(grasp.begin(), grasp.end(), t) != grasp.end()) {
      tip.let_go = true;
      tip.before_mm = *std::min_element(tip.recent.begin(), tip.recent.end());
      tip.peak_mm = tip_distance_mm[t];
      tip.frames_let_go = 0;
    } else if (tip.let_go) {
      tip.peak_mm = std::max(tip.peak_mm, std::min(tip_distance_mm[t], kNoContactMm / 2));
      // Back where it was, or coming down again from the farthest it went (a re-grasp the fit
      // places a few millimetres off where the last one was).
      if (tip_distance_mm[t] <= tip.before_mm + options_.return_mm ||
          tip_distance_mm[t] <= tip.peak_mm - options_.rise_mm ||
          ++tip.frames_let_go >= options_.max_frames) {
        tip.let_go = false;
      }
    }
    tip.recent.push_back(tip_distance_mm[t]);
    while (static_cast<int>(tip.recent.size()) > options_.frames) tip.recent.pop_front();
  }
  return let_go;
}

std::vector<double> ReleaseWatch::Limits() const {
  std::vector<double> limits;
  for (const Tip& tip : tips_) limits.push_back(tip.let_go ? -1.0 : kNoContactMm);
  return limits;
}

void ReleaseWatch::Reset() {
  for (Tip& tip : tips_) tip = Tip{};
}

}  // namespace ihs::tracker

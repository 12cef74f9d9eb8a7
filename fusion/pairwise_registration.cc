#include "fusion/pairwise_registration.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "core/check.h"
#include "core/rigid_fit.h"

namespace ihs::fusion {

void PairwiseOptions::Check() const {
  IHS_CHECK_ARG(contact_weight >= 0, "pairwise.contact_weight must be >= 0");
  IHS_CHECK_ARG(visual_weight >= 0, "pairwise.visual_weight must be >= 0");
  IHS_CHECK_ARG(contact_weight > 0 || visual_weight > 0,
                "pairwise.contact_weight and visual_weight cannot both be 0");
  IHS_CHECK_ARG(ransac_iterations >= 1 && ransac_iterations <= 100000,
                "pairwise.ransac_iterations must be in [1, 100000]");
  IHS_CHECK_ARG(inlier_mm > 0, "pairwise.inlier_mm must be positive");
  IHS_CHECK_ARG(min_visual_inliers >= 3, "pairwise.min_visual_inliers must be >= 3");
  IHS_CHECK_ARG(min_contacts >= 3, "pairwise.min_contacts must be >= 3");
  IHS_CHECK_ARG(min_contact_spread_mm >= 0, "pairwise.min_contact_spread_mm must be >= 0");
  IHS_CHECK_ARG(visual_turn_prior_deg >= 0, "pairwise.visual_turn_prior_deg must be >= 0");
  IHS_CHECK_ARG(max_rms_mm >= 0, "pairwise.max_rms_mm must be >= 0");
}

std::vector<PointMatch>& PairwiseInput::Pairs(const std::string& source, MatchKind kind) {
  for (MatchSet& set : sets) {
    if (set.source == source) return set.pairs;
  }
  sets.push_back({source, kind, {}});
  return sets.back().pairs;
}

std::vector<PointMatch> PairwiseInput::All(MatchKind kind) const {
  std::vector<PointMatch> all;
  for (const MatchSet& set : sets) {
    if (set.kind == kind) all.insert(all.end(), set.pairs.begin(), set.pairs.end());
  }
  return all;
}

std::vector<PointMatch> ConsistentPairs(const std::vector<PointMatch>& matches,
                                        const PairwiseOptions& options, double distinct_deg,
                                        int* rival) {
  const int n = static_cast<int>(matches.size());
  if (rival) *rival = 0;
  if (n < options.min_visual_inliers) return {};
  std::mt19937 rng(options.seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  const double inlier_sq = options.inlier_mm * options.inlier_mm;
  std::vector<int> best;
  // Every hypothesis's motion and inlier count, for the rival (only when asked for).
  std::vector<std::pair<Rigid3, int>> tried;
  for (int iteration = 0; iteration < options.ransac_iterations; ++iteration) {
    const int a = pick(rng), b = pick(rng), c = pick(rng);
    const Eigen::Vector3d& pa = matches[a].previous;
    const Eigen::Vector3d& pb = matches[b].previous;
    const Eigen::Vector3d& pc = matches[c].previous;
    // Three distinct, non-collinear points whose distances agree in both frames.
    if ((pb - pa).cross(pc - pa).norm() < 25.0) continue;
    bool rigid = true;
    for (auto [i, j] : {std::pair{a, b}, std::pair{b, c}, std::pair{a, c}}) {
      const double d0 = (matches[i].previous - matches[j].previous).norm();
      const double d1 = (matches[i].current - matches[j].current).norm();
      rigid = rigid && std::abs(d0 - d1) < 2 * options.inlier_mm;
    }
    if (!rigid) continue;
    const Rigid3 motion = FitRigidTransform(
        {pa, pb, pc}, {matches[a].current, matches[b].current, matches[c].current});
    std::vector<int> inliers;
    for (int i = 0; i < n; ++i) {
      if ((motion * matches[i].previous - matches[i].current).squaredNorm() < inlier_sq)
        inliers.push_back(i);
    }
    if (rival) tried.emplace_back(motion, static_cast<int>(inliers.size()));
    if (inliers.size() > best.size()) best = std::move(inliers);
  }
  if (static_cast<int>(best.size()) < options.min_visual_inliers) return {};
  // Refit on the inliers and gather them once more.
  std::vector<Eigen::Vector3d> from, to;
  for (int i : best) from.push_back(matches[i].previous), to.push_back(matches[i].current);
  const Rigid3 motion = FitRigidTransform(from, to);
  std::vector<PointMatch> inliers;
  for (const PointMatch& m : matches) {
    if ((motion * m.previous - m.current).squaredNorm() < inlier_sq) inliers.push_back(m);
  }
  if (rival) {
    for (const auto& [other, count] : tried) {
      if (other.RotationAngleToRad(motion) * 180.0 / M_PI > distinct_deg)
        *rival = std::max(*rival, count);
    }
  }
  return static_cast<int>(inliers.size()) >= options.min_visual_inliers ? inliers
                                                                        : std::vector<PointMatch>{};
}

namespace {

// The largest standard deviation of the contacts' previous positions, mm.
double Spread(const std::vector<PointMatch>& contacts) {
  if (contacts.size() < 2) return 0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const PointMatch& m : contacts) mean += m.previous;
  mean /= static_cast<double>(contacts.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const PointMatch& m : contacts) {
    covariance += (m.previous - mean) * (m.previous - mean).transpose();
  }
  covariance /= static_cast<double>(contacts.size());
  return std::sqrt(std::max(
      0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance, Eigen::EigenvaluesOnly)
               .eigenvalues()
               .maxCoeff()));
}

// The visual inliers' own motion, their centroid (previous frame) and how well they fix the
// motion's turn: the information matrix of its rotation vector (rad⁻²). The residuals after the
// fit give the points' noise (at least 0.5 mm: a few matches may fit by chance); their scatter
// about the centroid gives each axis a's information, Σ|q × a|² over the centred points q,
// divided by the noise's variance.
struct VisualFit {
  Rigid3 motion;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Matrix3d turn_information = Eigen::Matrix3d::Zero();
};

VisualFit FitVisual(const std::vector<PointMatch>& matches) {
  VisualFit fit;
  const size_t n = matches.size();
  std::vector<Eigen::Vector3d> from, to;
  for (const PointMatch& m : matches) from.push_back(m.previous), to.push_back(m.current);
  fit.motion = FitRigidTransform(from, to);
  double residual_sq = 0;
  for (size_t i = 0; i < n; ++i) {
    residual_sq += (fit.motion * from[i] - to[i]).squaredNorm();
    fit.centroid += from[i];
  }
  fit.centroid /= static_cast<double>(n);
  // Three coordinates per pair, six of them spent on the motion.
  const double noise_sq =
      std::max(0.25, residual_sq / std::max<double>(1.0, 3.0 * static_cast<double>(n) - 6.0));
  for (const Eigen::Vector3d& p : from) {
    const Eigen::Vector3d q = p - fit.centroid;
    fit.turn_information += q.squaredNorm() * Eigen::Matrix3d::Identity() - q * q.transpose();
  }
  fit.turn_information /= noise_sq;
  return fit;
}

// "12 sift and 0 shot": the pairs of each set of `kind` ("no" without a set).
std::string Counts(const PairwiseInput& input, MatchKind kind) {
  std::vector<std::string> parts;
  for (const MatchSet& set : input.sets) {
    if (set.kind == kind) parts.push_back(std::to_string(set.pairs.size()) + " " + set.source);
  }
  if (parts.empty()) return "no";
  std::string text = parts.front();
  for (size_t i = 1; i < parts.size(); ++i) {
    text += (i + 1 == parts.size() ? " and " : ", ") + parts[i];
  }
  return text;
}

}  // namespace

PairwiseResult RegisterPair(const PairwiseInput& input, const PairwiseOptions& options) {
  options.Check();
  PairwiseResult result;
  std::vector<PointMatch> visual;
  if (options.visual_weight > 0) visual = ConsistentPairs(input.All(MatchKind::kVisual), options);
  const std::vector<PointMatch> input_contacts = input.All(MatchKind::kContact);
  // ConsistentPairs returns a set of at least min_visual_inliers (>= 3) pairs, or none.
  VisualFit visual_fit;
  if (!visual.empty()) {
    visual_fit = FitVisual(visual);
    const double weakest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(
                               visual_fit.turn_information, Eigen::EigenvaluesOnly)
                               .eigenvalues()
                               .minCoeff();
    result.visual_turn_deg =
        weakest > 0 ? std::min(180.0, 180.0 / M_PI / std::sqrt(weakest)) : 180.0;
  }
  // Contacts that a consistent visual set contradicts are a mistracked hand's, not the object's:
  // each counts γt times, and hundreds of them would outweigh every good feature match.
  std::vector<PointMatch> contacts;
  if (options.check_contacts && !visual.empty() && options.contact_weight > 0) {
    const double inlier_sq = options.inlier_mm * options.inlier_mm;
    for (const PointMatch& m : input_contacts) {
      if ((visual_fit.motion * m.previous - m.current).squaredNorm() < inlier_sq)
        contacts.push_back(m);
    }
    result.contacts_rejected = static_cast<int>(input_contacts.size() - contacts.size());
  } else {
    contacts = input_contacts;
  }
  const double spread = Spread(contacts);
  result.contact_spread_mm = spread;
  const bool use_contacts = options.contact_weight > 0 && spread >= options.min_contact_spread_mm &&
                            (static_cast<int>(contacts.size()) >= options.min_contacts ||
                             (!visual.empty() && !contacts.empty()));
  if (visual.empty() && !use_contacts) {
    result.reason = "too few correspondences: " + Counts(input, MatchKind::kVisual) +
                    " feature matches (no consistent set of " +
                    std::to_string(options.min_visual_inliers) + "), " +
                    std::to_string(input_contacts.size()) + " contacts" +
                    (input_contacts.empty()
                         ? ""
                         : " spread over " + std::to_string(std::lround(spread)) + " mm (need " +
                               std::to_string(std::lround(options.min_contact_spread_mm)) + ")");
    return result;
  }
  std::vector<Eigen::Vector3d> from, to;
  std::vector<double> weights;
  for (const PointMatch& m : visual) {
    from.push_back(m.previous), to.push_back(m.current), weights.push_back(options.visual_weight);
  }
  if (use_contacts) {
    for (const PointMatch& m : contacts) {
      from.push_back(m.previous), to.push_back(m.current);
      weights.push_back(options.contact_weight);
    }
  }
  result.current_from_previous = FitRigidTransform(from, to, weights);
  if (!use_contacts && options.visual_turn_prior_deg > 0) {
    // Visual pairs alone: their turn, shrunk toward none where they fix it poorly (the
    // posterior mean of the rotation vector under a zero-mean prior of `visual_turn_prior_deg`
    // per frame and each axis), about their centroid, which stays where the fit puts it.
    const double prior = options.visual_turn_prior_deg * M_PI / 180.0;
    const Eigen::Matrix3d keep =
        (visual_fit.turn_information + Eigen::Matrix3d::Identity() / (prior * prior))
            .ldlt()
            .solve(visual_fit.turn_information);
    const Eigen::Vector3d& centroid = visual_fit.centroid;
    const Rigid3& fitted = result.current_from_previous;
    const Eigen::AngleAxisd turn(fitted.rotation());
    const Eigen::Vector3d fitted_turn = turn.angle() * turn.axis();
    const Eigen::Vector3d kept_turn = keep * fitted_turn;
    const Rigid3 shrunk = Rigid3::FromRotationVector(kept_turn, Eigen::Vector3d::Zero());
    result.current_from_previous =
        Rigid3(shrunk.rotation(), fitted * centroid - shrunk.rotation() * centroid);
    result.visual_turn_kept = fitted_turn.norm() > 0 ? kept_turn.norm() / fitted_turn.norm() : 1.0;
  }
  double sum = 0;
  for (size_t i = 0; i < from.size(); ++i)
    sum += (result.current_from_previous * from[i] - to[i]).squaredNorm();
  result.rms_mm = std::sqrt(sum / from.size());
  result.visual_inliers = static_cast<int>(visual.size());
  if (options.max_rms_mm > 0 && result.rms_mm > options.max_rms_mm) {
    result.reason = "the correspondences disagree with their motion: RMS " +
                    std::to_string(std::lround(result.rms_mm)) + " mm (at most " +
                    std::to_string(std::lround(options.max_rms_mm)) + ")";
    return result;
  }
  result.contacts = use_contacts ? static_cast<int>(contacts.size()) : 0;
  result.ok = true;
  return result;
}

}  // namespace ihs::fusion

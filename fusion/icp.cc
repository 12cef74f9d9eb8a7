#include "fusion/icp.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/check.h"

namespace ihs::fusion {

void IcpOptions::Check() const {
  IHS_CHECK_ARG(iterations >= 1 && iterations <= 100, "icp.iterations must be in [1, 100]");
  IHS_CHECK_ARG(max_distance_mm > 0, "icp.max_distance_mm must be positive");
  IHS_CHECK_ARG(min_inlier_fraction >= 0 && min_inlier_fraction <= 1,
                "icp.min_inlier_fraction must be in [0, 1]");
  IHS_CHECK_ARG(anchor_share >= 0, "icp.anchor_share must be >= 0");
  IHS_CHECK_ARG(min_constraint_over_noise >= 0, "icp.min_constraint_over_noise must be >= 0");
  IHS_CHECK_ARG(min_kept_pair_fraction >= 0 && min_kept_pair_fraction <= 1,
                "icp.min_kept_pair_fraction must be in [0, 1]");
}

namespace {

using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;

// The part of a step in the directions `free` (columns of `basis`) that best meets the anchors
// (normal equations `anchor_matrix`·x = `anchor_rhs`) given the rest of the step, `fixed`;
// directions the anchors hardly know (under a millionth of their strongest) stay at zero.
Vector6 AnchorStep(const Matrix6& basis, const std::vector<int>& free, const Matrix6& anchor_matrix,
                   const Vector6& anchor_rhs, const Vector6& fixed) {
  const int k = static_cast<int>(free.size());
  Eigen::MatrixXd directions(6, k);
  for (int c = 0; c < k; ++c) directions.col(c) = basis.col(free[c]);
  const Eigen::MatrixXd reduced = directions.transpose() * anchor_matrix * directions;
  const Eigen::VectorXd wanted = directions.transpose() * (anchor_rhs - anchor_matrix * fixed);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(reduced);
  const double strongest = anchor_matrix.trace();
  Eigen::VectorXd y = Eigen::VectorXd::Zero(k);
  for (int i = 0; i < k; ++i) {
    const double value = eigen.eigenvalues()[i];
    if (!(value > 1e-6 * strongest)) continue;
    const auto direction = eigen.eigenvectors().col(i);
    y += direction * (direction.dot(wanted) / value);
  }
  return directions * y;
}

// Whether `step` is small enough to end the iterations (it moves less than 0.01 mm).
bool Converged(const Vector6& step) { return step.tail<3>().norm() + step.head<3>().norm() < 0.01; }

// Normal equations of a Gauss–Newton step: matrix·step = rhs.
struct Equations {
  Matrix6 matrix = Matrix6::Zero();
  Vector6 rhs = Vector6::Zero();
};

// A point's partner on the model: the surface seen through the point's nearest pixel.
struct ModelPair {
  int u = 0;
  int v = 0;
  size_t index = 0;
  float depth = 0;
  Eigen::Vector3d normal;
  Eigen::Vector3d target;
};

// What the first iteration gathers about the model's normals, to keep the free directions:
// where the normal lines meet (least squares: Σ(I − nnᵀ)·x = Σ(I − nnᵀ)·p) and their noise.
struct NormalLines {
  Eigen::Matrix3d across = Eigen::Matrix3d::Zero();
  Eigen::Vector3d across_points = Eigen::Vector3d::Zero();
  std::vector<double> jitter;
};

// One AlignToModel call: its inputs and the state its iterations carry.
class Aligner {
 public:
  Aligner(const std::vector<Eigen::Vector3f>& points, const RaycastImage& model,
          const CameraIntrinsics& intrinsics, const IcpOptions& options,
          const std::vector<IcpAnchor>& anchors, const IcpContour* contour,
          const Rigid3& correction);

  // Runs the Gauss–Newton iterations until they converge, fail or run out; then, if the last
  // one lost most of the pairs the first had, goes back to the iterate that paired the most.
  void Run();
  bool slid() const { return slid_; }

  const Rigid3& correction() const { return correction_; }
  int inliers() const { return inliers_; }
  int first_inliers() const { return first_inliers_; }
  double rms() const { return rms_; }
  int iterations() const { return iterations_; }
  int free_directions() const { return free_directions_; }
  int contour_pairs() const { return contour_pairs_; }
  const Eigen::Vector3d& pivot() const { return pivot_; }
  const std::vector<FreeDirection>& free() const { return free_; }
  const Eigen::Vector3d& free_centre() const { return free_centre_; }

 private:
  // One iteration; returns whether another may follow.
  bool Iterate(int iteration);
  // The point pairs' equations at the current correction (counts the inliers, sets the rms);
  // with `lines`, also gathers the model's normal lines.
  Equations PairPoints(NormalLines* lines);
  // The contour points' equations (IcpContour), about the current centre.
  Equations PairContour();
  // `equations` restricted to the directions (columns of `basis`) not in `free`.
  static Equations Outside(const Equations& equations, const Matrix6& basis,
                           const std::vector<int>& free);
  // The model surface paired with `p` (current camera, corrected), if it is near enough.
  bool FindPair(const Eigen::Vector3d& p, ModelPair* pair) const;
  // Adds a pair's normal line and normal noise to `lines`.
  void AddNormalLine(const Eigen::Vector3d& p, const ModelPair& pair, NormalLines* lines) const;
  // Moves the pivot to where the normal lines meet, rewriting `surface` about it.
  void MovePivot(const NormalLines& lines, Equations* surface);
  // The normals' noise: the median of `jitter`, when there is any.
  void MeasureNormalNoise(std::vector<double>* jitter);
  // The anchors' equations, weighed against the iteration's inliers.
  Equations AnchorEquations() const;
  // The Jacobian row of a point `p` moved along `direction` by the twist about the centre.
  Vector6 Row(const Eigen::Vector3d& p, const Eigen::Vector3d& direction) const;
  // The step the (damped) equations ask for; `outline` joins the surface where it has not yet.
  Vector6 Solve(Equations surface, const Equations& anchored, const Equations& outline);
  // The step in the directions the surface constrains (with the outline's help there), the
  // anchors' in the others.
  Vector6 SolveConstrained(const Equations& surface, const Equations& anchored,
                           const Equations& outline);
  // Lists the directions the surface leaves free (free_), where its constraint (an eigenvalue
  // of `surface` per pair) is within min_constraint_over_noise of the normals' noise, unless
  // the direction is mostly a shift and the `outline` constrains it above that floor; returns
  // the eigen decomposition and the free directions' indices into it.
  std::vector<int> JudgeFree(const Equations& surface, const Equations& outline,
                             Eigen::SelfAdjointEigenSolver<Matrix6>* eigen = nullptr);
  // Applies `step` (a twist about the centre) to the correction.
  void ApplyStep(const Vector6& step);

  const std::vector<Eigen::Vector3f>& points_;
  const RaycastImage& model_;
  const CameraIntrinsics& intrinsics_;
  const IcpOptions& options_;
  const std::vector<IcpAnchor>& anchors_;
  const IcpContour* contour_;
  const double max_sq_;
  int contour_pairs_ = 0;
  // predicted_from_current: takes the current camera's points to where the predicted camera
  // sees the same surface (the model's raycast).
  Rigid3 correction_;
  double rms_ = 0;
  int inliers_ = 0;
  int first_inliers_ = 0;
  int iterations_ = 0;
  // The iterate that paired the most points: its correction, pairs and rms.
  Rigid3 best_correction_;
  int best_inliers_ = -1;
  double best_rms_ = 0;
  bool slid_ = false;
  // The twist is taken about a pivot (first the points' centroid), with the turn scaled by the
  // points' spread about it, so that turns and shifts weigh alike.
  Eigen::Vector3d pivot_;
  double spread_sq_ = 0;
  double scale_ = 1;
  // The pivot as the correction moves it, in this iteration.
  Eigen::Vector3d centre_;
  // Without anchors (or with anchors for them alone), the directions the surface leaves free
  // keep the prediction (IcpOptions::min_constraint_over_noise, anchors_free_directions_only).
  bool keep_free_ = false;
  // How many directions kept the prediction in the last iteration (-1: not judged).
  int free_directions_ = -1;
  // What a direction of the motion learns per point pair from the model's normal noise alone.
  double noise_information_ = 0;
  // The free directions of the last iteration that judged them, and the centre they turn about.
  std::vector<FreeDirection> free_;
  Eigen::Vector3d free_centre_ = Eigen::Vector3d::Zero();
};

Aligner::Aligner(const std::vector<Eigen::Vector3f>& points, const RaycastImage& model,
                 const CameraIntrinsics& intrinsics, const IcpOptions& options,
                 const std::vector<IcpAnchor>& anchors, const IcpContour* contour,
                 const Rigid3& correction)
    : points_(points),
      model_(model),
      intrinsics_(intrinsics),
      options_(options),
      anchors_(anchors),
      contour_(contour),
      max_sq_(options.max_distance_mm * options.max_distance_mm),
      correction_(correction) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& point : points) centroid += point.cast<double>();
  centroid /= std::max<size_t>(1, points.size());
  for (const Eigen::Vector3f& point : points)
    spread_sq_ += (point.cast<double>() - centroid).squaredNorm();
  spread_sq_ /= std::max<size_t>(1, points.size());
  pivot_ = centroid;
  scale_ = std::max(1.0, std::sqrt(spread_sq_));
  keep_free_ = (anchors.empty() || options.anchors_free_directions_only) &&
               options.min_constraint_over_noise > 0;
}

void Aligner::Run() {
  for (int iteration = 0; iteration < options_.iterations; ++iteration) {
    if (!Iterate(iteration)) break;
  }
  if (inliers_ < options_.min_kept_pair_fraction * first_inliers_ && best_inliers_ > inliers_) {
    correction_ = best_correction_;
    inliers_ = best_inliers_;
    rms_ = best_rms_;
    slid_ = true;
  }
}

bool Aligner::Iterate(int iteration) {
  centre_ = correction_ * pivot_;
  const bool find_pivot = keep_free_ && iteration == 0;
  // Where the anchors join every direction, the free ones are still judged, aside (reported,
  // not used).
  const bool judge_aside = !keep_free_ && options_.min_constraint_over_noise > 0;
  NormalLines lines;
  Equations surface = PairPoints(find_pivot || (judge_aside && iteration == 0) ? &lines : nullptr);
  if (iteration == 0) first_inliers_ = inliers_;
  if (inliers_ > best_inliers_) {
    best_inliers_ = inliers_, best_correction_ = correction_, best_rms_ = rms_;
  }
  if (find_pivot && inliers_ >= 6) {
    MovePivot(lines, &surface);
    MeasureNormalNoise(&lines.jitter);
  }
  if (judge_aside && iteration == 0) MeasureNormalNoise(&lines.jitter);
  const Equations anchored = AnchorEquations();
  // The free directions are the surface's alone: an outline's normals are noisy enough to make
  // a ball's turn look fixed, though its outline says nothing of that turn.
  const Equations outline = PairContour();
  Equations held = outline;
  if (judge_aside && noise_information_ > 0) {
    Eigen::SelfAdjointEigenSolver<Matrix6> eigen;
    const std::vector<int> free = JudgeFree(surface, outline, &eigen);
    held = Outside(outline, eigen.eigenvectors(), free);
  }
  if (!keep_free_) {
    surface.matrix += anchored.matrix + held.matrix;
    surface.rhs += anchored.rhs + held.rhs;
  }
  if (inliers_ < 6) return false;
  const Vector6 step = Solve(std::move(surface), anchored, outline);
  if (!step.allFinite()) return false;
  ApplyStep(step);
  iterations_ = iteration + 1;
  return !Converged(step);
}

Equations Aligner::PairPoints(NormalLines* lines) {
  Equations surface;
  if (lines) lines->jitter.reserve(points_.size());
  double sum_sq = 0;
  inliers_ = 0;
  for (const Eigen::Vector3f& point : points_) {
    const Eigen::Vector3d p = correction_ * Eigen::Vector3d(point.cast<double>());
    ModelPair pair;
    if (!FindPair(p, &pair)) continue;
    const double residual = pair.normal.dot(p - pair.target);
    // d(residual)/d(θ, t) for p ← exp(θ / scale)·(p − c) + c + t: ((p − c) / scale × n, n).
    const Vector6 row = Row(p, pair.normal);
    // The upper triangle only; the lower one is filled in once per iteration.
    for (int c = 0; c < 6; ++c) surface.matrix.col(c).head(c + 1) += row[c] * row.head(c + 1);
    surface.rhs -= row * residual;
    sum_sq += residual * residual;
    ++inliers_;
    if (lines) AddNormalLine(p, pair, lines);
  }
  surface.matrix.triangularView<Eigen::StrictlyLower>() = surface.matrix.transpose();
  rms_ = inliers_ > 0 ? std::sqrt(sum_sq / inliers_) : 0;
  return surface;
}

Equations Aligner::PairContour() {
  Equations outline;
  contour_pairs_ = 0;
  if (!contour_ || !(contour_->options.weight > 0)) return outline;
  for (const ContourPoint& point : contour_->points) {
    const Eigen::Vector3d p = correction_ * point.point;
    const Eigen::Vector2d normal =
        (correction_.rotation() * Eigen::Vector3d(point.normal.x(), point.normal.y(), 0))
            .head<2>()
            .normalized();
    Eigen::Vector3d direction;
    double residual = 0;
    if (!PairContourPoint(p, normal, model_, intrinsics_, options_.max_distance_mm,
                          contour_->options.search_px, contour_->options.min_edge_facing,
                          &direction, &residual)) {
      continue;
    }
    const Vector6 row = Row(p, direction);
    outline.matrix += contour_->options.weight * row * row.transpose();
    outline.rhs -= contour_->options.weight * row * residual;
    ++contour_pairs_;
  }
  return outline;
}

bool Aligner::FindPair(const Eigen::Vector3d& p, ModelPair* pair) const {
  if (p.z() <= 0) return false;
  const Eigen::Vector2d pixel = intrinsics_.Project(p);
  // The nearest pixel (inside the image, truncation rounds).
  if (!intrinsics_.Contains(pixel.x(), pixel.y())) return false;
  pair->u = static_cast<int>(pixel.x() + 0.5);
  pair->v = static_cast<int>(pixel.y() + 0.5);
  pair->index = static_cast<size_t>(pair->v) * model_.width + pair->u;
  pair->depth = model_.depth_mm[pair->index];
  pair->normal = model_.normals[pair->index].cast<double>();
  if (pair->depth <= 0 || pair->normal.squaredNorm() < 0.5) return false;
  if (contour_ && contour_->pairable && !(*contour_->pairable)[pair->index]) return false;
  pair->target = intrinsics_.BackProject(pair->u, pair->v, pair->depth);
  return !((p - pair->target).squaredNorm() > max_sq_);
}

void Aligner::AddNormalLine(const Eigen::Vector3d& p, const ModelPair& pair,
                            NormalLines* lines) const {
  // The model's normal noise: half the squared difference to the next pixel's normal on the
  // same surface.
  const size_t next = pair.index + 1;
  if (pair.u + 1 < model_.width && model_.depth_mm[next] > 0 &&
      std::abs(model_.depth_mm[next] - pair.depth) < 2 * options_.max_distance_mm) {
    lines->jitter.push_back(0.5 *
                            (model_.normals[next].cast<double>() - pair.normal).squaredNorm());
  }
  const Eigen::Matrix3d off_normal =
      Eigen::Matrix3d::Identity() - pair.normal * pair.normal.transpose();
  lines->across += off_normal;
  lines->across_points += off_normal * p;
}

void Aligner::MovePivot(const NormalLines& lines, Equations* surface) {
  // The surface's free turns (a sphere's, a bottle's about its axis) are turns about where
  // its normal lines meet: taken about that point, they are pure turns, so keeping them at the
  // prediction does not turn the object when its position is corrected. Where the lines do
  // not meet (a plane), the pivot stays near the centroid.
  const double pull = 1e-3 * lines.across.trace();
  const Eigen::Vector3d meet = (lines.across + pull * Eigen::Matrix3d::Identity())
                                   .ldlt()
                                   .solve(lines.across_points + pull * centre_);
  if (!meet.allFinite() || !((meet - centre_).norm() < 3 * scale_)) return;
  // Rows about the new pivot are T·rows: ((p − c′) × n) / s′ = (s/s′)·((p − c) × n) / s
  // + ((c − c′) × n) / s′.
  const double new_scale = std::max(1.0, std::sqrt(spread_sq_ + (meet - centre_).squaredNorm()));
  Matrix6 to_pivot = Matrix6::Identity();
  to_pivot.topLeftCorner<3, 3>() *= scale_ / new_scale;
  const Eigen::Vector3d d = centre_ - meet;
  to_pivot.topRightCorner<3, 3>() << 0, -d.z(), d.y(), d.z(), 0, -d.x(), -d.y(), d.x(), 0;
  to_pivot.topRightCorner<3, 3>() /= new_scale;
  surface->matrix = to_pivot * surface->matrix * to_pivot.transpose();
  surface->rhs = to_pivot * surface->rhs;
  pivot_ = meet;  // The correction is the identity in the first iteration.
  centre_ = meet;
  scale_ = new_scale;
}

void Aligner::MeasureNormalNoise(std::vector<double>* jitter) {
  if (jitter->empty()) return;
  auto middle = jitter->begin() + jitter->size() / 2;
  std::nth_element(jitter->begin(), middle, jitter->end());
  noise_information_ = *middle;
}

Equations Aligner::AnchorEquations() const {
  // The anchors together weigh `anchor_share` of the surface's pairs: they decide what the
  // surface leaves open (a sphere's turn) and hardly move what it fixes.
  double anchor_total = 0;
  for (const IcpAnchor& anchor : anchors_) anchor_total += anchor.weight;
  const double anchor_scale =
      anchor_total > 0 ? options_.anchor_share * std::max(inliers_, 1) / anchor_total : 0.0;
  Equations anchored;
  for (const IcpAnchor& anchor : anchors_) {
    const double weight = anchor.weight * anchor_scale;
    const Eigen::Vector3d p = correction_ * anchor.current;
    const Eigen::Vector3d residual = p - anchor.target;
    for (int k = 0; k < 3; ++k) {
      const Vector6 row = Row(p, Eigen::Vector3d::Unit(k));
      anchored.matrix += weight * row * row.transpose();
      anchored.rhs -= weight * row * residual[k];
    }
  }
  return anchored;
}

Equations Aligner::Outside(const Equations& equations, const Matrix6& basis,
                           const std::vector<int>& free) {
  Matrix6 keep = Matrix6::Zero();
  for (int i = 0; i < 6; ++i) {
    if (std::find(free.begin(), free.end(), i) == free.end())
      keep += basis.col(i) * basis.col(i).transpose();
  }
  Equations kept;
  kept.matrix = keep * equations.matrix * keep;
  kept.rhs = keep * equations.rhs;
  return kept;
}

Vector6 Aligner::Row(const Eigen::Vector3d& p, const Eigen::Vector3d& direction) const {
  Vector6 row;
  row << ((p - centre_) / scale_).cross(direction), direction;
  return row;
}

Vector6 Aligner::Solve(Equations surface, const Equations& anchored, const Equations& outline) {
  // A little (Marquardt) damping keeps directions the data do not constrain at all where the
  // prediction put them.
  surface.matrix.diagonal() *= 1.0 + 1e-4;
  surface.matrix.diagonal().array() += 1e-9;
  if (keep_free_ && noise_information_ > 0) return SolveConstrained(surface, anchored, outline);
  if (keep_free_) {
    // No measure of the normals' noise to tell free directions by: the anchors join in.
    return (surface.matrix + anchored.matrix + outline.matrix)
        .ldlt()
        .solve(surface.rhs + anchored.rhs + outline.rhs);
  }
  return surface.matrix.ldlt().solve(surface.rhs);
}

Vector6 Aligner::SolveConstrained(const Equations& surface, const Equations& anchored,
                                  const Equations& outline) {
  // Only the directions the surface constrains move; the others keep the prediction, or
  // follow the anchors where they have any.
  Eigen::SelfAdjointEigenSolver<Matrix6> eigen;
  const std::vector<int> free = JudgeFree(surface, outline, &eigen);
  Vector6 step = Vector6::Zero();
  if (contour_pairs_ > 0 && free.size() < 6) {
    // The surface and the outline together, within the directions the surface constrains.
    Eigen::MatrixXd fixed(6, 6 - static_cast<int>(free.size()));
    for (int i = 0, c = 0; i < 6; ++i) {
      if (std::find(free.begin(), free.end(), i) == free.end())
        fixed.col(c++) = eigen.eigenvectors().col(i);
    }
    const Eigen::MatrixXd reduced = fixed.transpose() * (surface.matrix + outline.matrix) * fixed;
    step = fixed * reduced.ldlt().solve(fixed.transpose() * (surface.rhs + outline.rhs));
  } else {
    for (int i = 0; i < 6; ++i) {
      if (std::find(free.begin(), free.end(), i) != free.end()) continue;
      const auto direction = eigen.eigenvectors().col(i);
      step += direction * (direction.dot(surface.rhs) / eigen.eigenvalues()[i]);
    }
  }
  free_directions_ = static_cast<int>(free.size());
  if (!free.empty() && !anchors_.empty())
    step += AnchorStep(eigen.eigenvectors(), free, anchored.matrix, anchored.rhs, step);
  return step;
}

std::vector<int> Aligner::JudgeFree(const Equations& surface, const Equations& outline,
                                    Eigen::SelfAdjointEigenSolver<Matrix6>* eigen) {
  Eigen::SelfAdjointEigenSolver<Matrix6> own;
  if (!eigen) eigen = &own;
  eigen->compute(surface.matrix);
  const double floor = options_.min_constraint_over_noise * noise_information_ * inliers_;
  std::vector<int> free;
  free_.clear();
  free_centre_ = centre_;
  for (int i = 0; i < 6; ++i) {
    const double value = eigen->eigenvalues()[i];
    if (!(value <= floor || value <= 0)) continue;
    const auto direction = eigen->eigenvectors().col(i);
    // A face seen head-on leaves its shifts along itself free; its outline fixes them.
    const bool shift = direction.tail<3>().norm() > direction.head<3>().norm();
    if (shift && contour_pairs_ > 0 && direction.dot(outline.matrix * direction) > floor) continue;
    free.push_back(i);
    free_.push_back({direction.head<3>() / scale_, direction.tail<3>()});
  }
  return free;
}

void Aligner::ApplyStep(const Vector6& step) {
  const Rigid3 turn = Rigid3::FromRotationVector(step.head<3>() / scale_, Eigen::Vector3d::Zero());
  correction_ = Rigid3::Translation(centre_ + step.tail<3>()) * turn *
                Rigid3::Translation(-centre_) * correction_;
}

// Accepts `result` when at least `needed` of the `point_count` points paired with the model,
// else says why not.
void CheckEnoughPairs(int needed, size_t point_count, IcpResult* result) {
  if (result->inliers < needed) {
    result->reason = "ICP: " + std::to_string(result->inliers) + " of " +
                     std::to_string(point_count) + " points pair with the model (need " +
                     std::to_string(needed) + ")";
    return;
  }
  result->ok = true;
}

}  // namespace

IcpResult AlignToModel(const std::vector<Eigen::Vector3f>& points, const RaycastImage& model,
                       const CameraIntrinsics& intrinsics, const Rigid3& predicted,
                       const IcpOptions& options, const std::vector<IcpAnchor>& anchors,
                       const IcpContour* contour, const Rigid3* start) {
  options.Check();
  IHS_CHECK_ARG(model.width == intrinsics.width && model.height == intrinsics.height,
                "the raycast is " << model.width << "x" << model.height << ", the camera "
                                  << intrinsics.width << "x" << intrinsics.height);
  const int needed =
      std::max(50, static_cast<int>(std::ceil(options.min_inlier_fraction * points.size())));
  IHS_CHECK_ARG(
      !contour || !contour->pairable || contour->pairable->size() == model.depth_mm.size(),
      "the contour's pairable mask does not cover the raycast");
  // correction · current = predicted (as seen), so the start's is predicted · start⁻¹.
  const Rigid3 correction = start ? predicted * start->Inverse() : Rigid3();
  Aligner aligner(points, model, intrinsics, options, anchors, contour, correction);
  aligner.Run();
  IcpResult result;
  result.iterations = aligner.iterations();
  result.inliers = aligner.inliers();
  result.first_inliers = aligner.first_inliers();
  result.points = static_cast<int>(points.size());
  result.slid = aligner.slid();
  result.rms_mm = aligner.rms();
  result.free_directions = aligner.free_directions();
  result.pivot = aligner.pivot();
  result.free = aligner.free();
  result.free_centre = aligner.free_centre();
  result.contour_pairs = aligner.contour_pairs();
  // correction · current = predicted (as seen): cam_from_volume = correction⁻¹ · predicted.
  result.cam_from_volume = aligner.correction().Inverse() * predicted;
  CheckEnoughPairs(needed, points.size(), &result);
  return result;
}

}  // namespace ihs::fusion

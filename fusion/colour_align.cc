#include "fusion/colour_align.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "core/check.h"

namespace ihs::fusion {

void ColourAlignOptions::Check() const {
  IHS_CHECK_ARG(
      coarse_blur_px > 0 && fine_blur_px > 0 && coarse_blur_px <= 20 && fine_blur_px <= 20,
      "fusion.colour.coarse_blur_px and fine_blur_px must be in (0, 20]");
  IHS_CHECK_ARG(shading_blur_px >= 0 && shading_blur_px <= 50,
                "fusion.colour.shading_blur_px must be in [0, 50]");
  IHS_CHECK_ARG(iterations >= 1 && iterations <= 100,
                "fusion.colour.iterations must be in [1, 100]");
  IHS_CHECK_ARG(stride >= 1 && stride <= 8, "fusion.colour.stride must be in [1, 8]");
  IHS_CHECK_ARG(prior_mm > 0, "fusion.colour.prior_mm must be positive");
  IHS_CHECK_ARG(max_depth_gap_mm > 0, "fusion.colour.max_depth_gap_mm must be positive");
  IHS_CHECK_ARG(min_facing >= 0 && min_facing < 1, "fusion.colour.min_facing must be in [0, 1)");
  IHS_CHECK_ARG(profile_mm > 0, "fusion.colour.profile_mm must be positive");
  IHS_CHECK_ARG(correlated_samples >= 1, "fusion.colour.correlated_samples must be >= 1");
  IHS_CHECK_ARG(min_model_colourings >= 1 && min_model_colourings <= 255,
                "fusion.colour.min_model_colourings must be in [1, 255]");
  IHS_CHECK_ARG(max_points >= 100, "fusion.colour.max_points must be >= 100");
  IHS_CHECK_ARG(max_shading_share >= 0 && max_shading_share <= 1,
                "fusion.colour.max_shading_share must be in [0, 1]");
  IHS_CHECK_ARG(min_points >= 10, "fusion.colour.min_points must be >= 10");
  IHS_CHECK_ARG(min_grey_spread >= 0, "fusion.colour.min_grey_spread must be >= 0");
}

namespace {

// A grey image over a rectangle of the camera's, with the pixels it holds.
struct GreyPatch {
  int u0 = 0, v0 = 0, width = 0, height = 0;
  std::vector<float> grey;
  std::vector<std::uint8_t> valid;

  void Resize(int left, int top, int right, int bottom) {
    u0 = left, v0 = top;
    width = std::max(0, right - left), height = std::max(0, bottom - top);
    grey.assign(static_cast<size_t>(width) * height, 0.0f);
    valid.assign(grey.size(), 0);
  }
  size_t Index(int u, int v) const { return static_cast<size_t>(v - v0) * width + (u - u0); }
  bool Holds(int u, int v) const {
    return u >= u0 && v >= v0 && u < u0 + width && v < v0 + height && valid[Index(u, v)];
  }
};

float Grey(const std::uint8_t* rgb) { return 0.299f * rgb[0] + 0.587f * rgb[1] + 0.114f * rgb[2]; }

// `image`'s sums under a Gaussian of `sigma` pixels, nothing beyond its border (in place).
// Wide blurs are three boxes each way (the same spread, near enough: a few hundred pixels'
// blur costs what a narrow one does).
void GaussianSums(cv::Mat* image, double sigma) {
  const int radius = std::max(1, static_cast<int>(std::ceil(3 * sigma)));
  if (radius <= 4) {
    cv::Mat kernel(2 * radius + 1, 1, CV_32F);
    for (int k = -radius; k <= radius; ++k)
      kernel.at<float>(k + radius) = static_cast<float>(std::exp(-0.5 * k * k / (sigma * sigma)));
    cv::sepFilter2D(*image, *image, CV_32F, kernel, kernel, cv::Point(-1, -1), 0,
                    cv::BORDER_CONSTANT);
    return;
  }
  // Three boxes of 2r + 1 have the variance of a Gaussian's sigma² = (2r + 1)² − 1) / 4.
  const int box =
      std::max(1, static_cast<int>(std::lround((std::sqrt(4 * sigma * sigma + 1) - 1) / 2)));
  for (int pass = 0; pass < 3; ++pass) {
    cv::boxFilter(*image, *image, CV_32F, cv::Size(2 * box + 1, 2 * box + 1), cv::Point(-1, -1),
                  /*normalize=*/false, cv::BORDER_CONSTANT);
  }
}

// The sums of the pixels `patch` holds (1 each) under GaussianSums: the weights that normalise
// its blur (Blurred).
cv::Mat HeldSums(const GreyPatch& patch, double sigma) {
  cv::Mat weights(patch.height, patch.width, CV_32F);
  for (size_t i = 0; i < patch.valid.size(); ++i)
    weights.ptr<float>()[i] = patch.valid[i] ? 1.0f : 0.0f;
  GaussianSums(&weights, sigma);
  return weights;
}

// `patch` blurred by a Gaussian of `sigma` pixels, normalised over the pixels it holds (the
// edge of the object does not darken what lies near it).
GreyPatch Blurred(const GreyPatch& patch, double sigma) {
  GreyPatch blurred = patch;
  if (patch.grey.empty()) return blurred;
  const cv::Mat held = HeldSums(patch, sigma);
  cv::Mat values(patch.height, patch.width, CV_32F);
  for (size_t i = 0; i < patch.grey.size(); ++i)
    values.ptr<float>()[i] = patch.valid[i] ? patch.grey[i] : 0.0f;
  GaussianSums(&values, sigma);
  for (size_t i = 0; i < patch.grey.size(); ++i) {
    const float weight = held.ptr<float>()[i];
    if (patch.valid[i] && weight > 0) blurred.grey[i] = values.ptr<float>()[i] / weight;
  }
  return blurred;
}

// The standard deviation of what `patch` holds.
double Spread(const GreyPatch& patch) {
  double sum = 0, sum_sq = 0;
  int count = 0;
  for (size_t i = 0; i < patch.grey.size(); ++i) {
    if (!patch.valid[i]) continue;
    sum += patch.grey[i], sum_sq += patch.grey[i] * patch.grey[i], ++count;
  }
  if (count < 2) return 0;
  return std::sqrt(std::max(0.0, sum_sq / count - (sum / count) * (sum / count)));
}

// Keeps in each of `a` and `b` only the pixels both hold.
void Intersect(GreyPatch* a, GreyPatch* b) {
  for (GreyPatch* patch : {a, b}) {
    const GreyPatch& other = patch == a ? *b : *a;
    for (int v = patch->v0; v < patch->v0 + patch->height; ++v) {
      for (int u = patch->u0; u < patch->u0 + patch->width; ++u) {
        if (!other.Holds(u, v)) patch->valid[patch->Index(u, v)] = 0;
      }
    }
  }
}

// The pattern without the shading: the log of the grey less its blur by `sigma` pixels (light
// and shading multiply the pattern and change slowly across the object).
GreyPatch Detail(GreyPatch patch, double sigma) {
  for (size_t i = 0; i < patch.grey.size(); ++i) {
    if (patch.valid[i]) patch.grey[i] = 100.0f * std::log1p(patch.grey[i]);
  }
  if (!(sigma > 0)) return patch;
  const GreyPatch shading = Blurred(patch, sigma);
  for (size_t i = 0; i < patch.grey.size(); ++i) {
    if (patch.valid[i]) patch.grey[i] -= shading.grey[i];
  }
  return patch;
}

// Takes out of both details (the same pixels held) what the light's shading explains: each is
// fitted (least squares) by smooth functions of the surface's normal in the camera's frame
// (its components and their products: a light fixed to the camera, wherever it is), given the
// same blur as the details, and the fit subtracted. On a uniform object the shading is all the
// detail there is, and it does not move with the object's turn (a body of revolution turned
// about its axis shows the camera the same normals): left in, it held untextured bottles and
// balls still. Returns the share of the frame's detail the shading explained.
double RemoveShading(const RaycastImage& model, const CameraIntrinsics& intrinsics, double sigma,
                     GreyPatch* frame_detail, GreyPatch* model_detail) {
  constexpr int kFeatures = 8;
  const GreyPatch& grid = *model_detail;
  // The features, one image of eight channels (none where the grid holds nothing).
  cv::Mat features = cv::Mat::zeros(grid.height, grid.width, CV_32FC(kFeatures));
  auto feature_row = [&](int u, int v) {
    return Eigen::Map<Eigen::Matrix<float, kFeatures, 1>>(features.ptr<float>() +
                                                          kFeatures * grid.Index(u, v));
  };
  for (int v = grid.v0; v < grid.v0 + grid.height; ++v) {
    for (int u = grid.u0; u < grid.u0 + grid.width; ++u) {
      if (!grid.valid[grid.Index(u, v)]) continue;
      Eigen::Vector3d n = model.normals[static_cast<size_t>(v) * model.width + u].cast<double>();
      // In the ray's frame, so that a light at the camera shades by n·ray alike everywhere.
      const Eigen::Vector3d ray = intrinsics.BackProject(u, v, 1.0).normalized();
      const double facing = -n.dot(ray);
      const Eigen::Vector3d across = n + facing * ray;
      const Eigen::Matrix<double, kFeatures, 1> values =
          (Eigen::Matrix<double, kFeatures, 1>() << facing, across.x(), across.y(), facing * facing,
           across.x() * across.x(), across.y() * across.y(), across.x() * across.y(),
           facing * across.x())
              .finished();
      feature_row(u, v) = (100 * values).cast<float>();
    }
  }
  // Each feature less its blur (as the details are), all eight blurred at once; they hold the
  // same pixels, so one blur of those normalises them all.
  if (!grid.grey.empty()) {
    const cv::Mat held = HeldSums(grid, sigma);
    cv::Mat sums = features.clone();
    GaussianSums(&sums, sigma);
    for (size_t i = 0; i < grid.grey.size(); ++i) {
      const float weight = held.ptr<float>()[i];
      if (!grid.valid[i] || !(weight > 0)) continue;
      for (int f = 0; f < kFeatures; ++f)
        features.ptr<float>()[i * kFeatures + f] -= sums.ptr<float>()[i * kFeatures + f] / weight;
    }
  }
  double explained = 0;
  for (GreyPatch* detail : {frame_detail, model_detail}) {
    Eigen::Matrix<double, kFeatures, kFeatures> normal =
        Eigen::Matrix<double, kFeatures, kFeatures>::Zero();
    Eigen::Matrix<double, kFeatures, 1> rhs = Eigen::Matrix<double, kFeatures, 1>::Zero();
    double sum = 0, sum_sq = 0;
    int count = 0;
    Eigen::Matrix<double, kFeatures, 1> row;
    for (int v = grid.v0; v < grid.v0 + grid.height; v += 2) {
      for (int u = grid.u0; u < grid.u0 + grid.width; u += 2) {
        if (!grid.Holds(u, v) || !detail->Holds(u, v)) continue;
        row = feature_row(u, v).cast<double>();
        const double d = detail->grey[detail->Index(u, v)];
        normal += row * row.transpose();
        rhs += row * d;
        sum += d, sum_sq += d * d;
        ++count;
      }
    }
    if (count < 2 * kFeatures) continue;
    normal.diagonal().array() += 1e-6 * (normal.trace() / kFeatures + 1e-9);
    const Eigen::Matrix<double, kFeatures, 1> beta = normal.ldlt().solve(rhs);
    const double total = sum_sq - sum * sum / count;
    const double fitted = beta.dot(rhs);
    if (detail == frame_detail && total > 0) explained = std::clamp(fitted / total, 0.0, 1.0);
    for (int v = grid.v0; v < grid.v0 + grid.height; ++v) {
      for (int u = grid.u0; u < grid.u0 + grid.width; ++u) {
        if (!grid.Holds(u, v) || !detail->Holds(u, v)) continue;
        row = feature_row(u, v).cast<double>();
        detail->grey[detail->Index(u, v)] -= static_cast<float>(beta.dot(row));
      }
    }
  }
  return explained;
}

// The model's grey, its gradient (per pixel) and depth at a point of the image.
struct ModelSample {
  float grey = 0;
  Eigen::Vector2d gradient;
};

class ModelImage {
 public:
  ModelImage(const GreyPatch& grey, const RaycastImage& model) : grey_(grey), model_(model) {}

  // Bilinear, where the four pixels around (x, y) and their neighbours hold the model.
  bool Sample(double x, double y, ModelSample* sample) const {
    const int u = static_cast<int>(std::floor(x)), v = static_cast<int>(std::floor(y));
    if (!grey_.Holds(u - 1, v) || !grey_.Holds(u + 2, v + 1) || !grey_.Holds(u, v - 1) ||
        !grey_.Holds(u + 1, v + 2)) {
      return false;
    }
    const double a = x - u, b = y - v;
    double value = 0;
    Eigen::Vector2d gradient = Eigen::Vector2d::Zero();
    for (int dv = 0; dv < 2; ++dv) {
      for (int du = 0; du < 2; ++du) {
        const int uu = u + du, vv = v + dv;
        if (!grey_.Holds(uu, vv) || !grey_.Holds(uu - 1, vv) || !grey_.Holds(uu + 1, vv) ||
            !grey_.Holds(uu, vv - 1) || !grey_.Holds(uu, vv + 1)) {
          return false;
        }
        const double weight = (du ? a : 1 - a) * (dv ? b : 1 - b);
        value += weight * grey_.grey[grey_.Index(uu, vv)];
        gradient.x() += weight * 0.5 *
                        (grey_.grey[grey_.Index(uu + 1, vv)] - grey_.grey[grey_.Index(uu - 1, vv)]);
        gradient.y() += weight * 0.5 *
                        (grey_.grey[grey_.Index(uu, vv + 1)] - grey_.grey[grey_.Index(uu, vv - 1)]);
      }
    }
    sample->grey = static_cast<float>(value);
    sample->gradient = gradient;
    return true;
  }

  float DepthAt(double x, double y) const {
    const int u = static_cast<int>(x + 0.5), v = static_cast<int>(y + 0.5);
    return model_.depth_mm[static_cast<size_t>(v) * model_.width + u];
  }

 private:
  const GreyPatch& grey_;
  const RaycastImage& model_;
};

// One of the frame's points: where it is (current camera) and its blurred grey.
struct ColourPoint {
  Eigen::Vector3d point;
  int u = 0, v = 0;
  float grey = 0;
};

// The Gauss–Newton problem of one blur level.
class ColourProblem {
 public:
  ColourProblem(const std::vector<ColourPoint>& points, const ModelImage& model,
                const CameraIntrinsics& intrinsics, const std::vector<FreeDirection>& free,
                const Eigen::Vector3d& centre, const ColourAlignOptions& options)
      : points_(points),
        model_(model),
        intrinsics_(intrinsics),
        free_(free),
        centre_(centre),
        options_(options) {}

  // Fits the gain and offset (model ≈ gain·frame + offset) and the residuals' scale at
  // `correction`; false where too few points pair or the frame shows no pattern.
  bool Calibrate(const Rigid3& correction) {
    const std::vector<std::pair<double, double>> pairs = Greys(correction);
    if (static_cast<int>(pairs.size()) < options_.min_points) return false;
    const Moments moments = MomentsOf(pairs);
    if (!(moments.ff > 0) || moments.fm <= 0) return false;
    gain_ = moments.fm / moments.ff;
    offset_ = moments.mean_model - gain_ * moments.mean_frame;
    std::vector<double> residuals;
    for (const auto& [f, m] : pairs) residuals.push_back(std::abs(m - gain_ * f - offset_));
    std::nth_element(residuals.begin(), residuals.begin() + residuals.size() / 2, residuals.end());
    sigma_ = std::max(1.0, 1.4826 * residuals[residuals.size() / 2]);
    return true;
  }

  // The robust cost at `correction` (a point that pairs with nothing counts as an outlier
  // three scales off) and, with `matrix`, its normal equations in the free directions.
  double Cost(const Rigid3& correction, Eigen::MatrixXd* matrix = nullptr,
              Eigen::VectorXd* rhs = nullptr, int* paired = nullptr) const {
    const int k = static_cast<int>(free_.size());
    if (matrix) *matrix = Eigen::MatrixXd::Zero(k, k), *rhs = Eigen::VectorXd::Zero(k);
    const double huber = 1.345 * sigma_;
    const double outlier = Huber(3 * sigma_, huber);
    double cost = 0;
    int count = 0;
    Eigen::VectorXd row(k);
    for (const ColourPoint& point : points_) {
      const Eigen::Vector3d q = correction * point.point;
      ModelSample sample;
      if (!Pair(q, &sample)) {
        cost += outlier;
        continue;
      }
      ++count;
      const double residual = sample.grey - gain_ * point.grey - offset_;
      cost += Huber(residual, huber);
      if (!matrix) continue;
      // d(pixel)/d(q), then along each free direction.
      const double z = q.z();
      Eigen::Matrix<double, 2, 3> projection;
      projection << intrinsics_.fx / z, 0, -intrinsics_.fx * q.x() / (z * z), 0, intrinsics_.fy / z,
          -intrinsics_.fy * q.y() / (z * z);
      const Eigen::Vector3d pulled = projection.transpose() * sample.gradient;
      for (int c = 0; c < k; ++c)
        row[c] = pulled.dot(free_[c].turn.cross(q - centre_) + free_[c].shift);
      const double weight = std::abs(residual) <= huber ? 1.0 : huber / std::abs(residual);
      *matrix += weight * row * row.transpose();
      *rhs -= weight * row * residual;
    }
    if (paired) *paired = count;
    return cost;
  }

  double sigma() const { return sigma_; }

  // How alike the frame's grey and the model's are at `correction`: their correlation over the
  // points that pair (0 where fewer than `min_points` do or either is flat).
  double Correlation(const Rigid3& correction) const {
    const std::vector<std::pair<double, double>> pairs = Greys(correction);
    if (static_cast<int>(pairs.size()) < options_.min_points) return 0;
    const Moments moments = MomentsOf(pairs);
    return moments.ff > 0 && moments.mm > 0 ? moments.fm / std::sqrt(moments.ff * moments.mm) : 0;
  }

 private:
  // The means of (frame, model) greys and their summed central second moments.
  struct Moments {
    double mean_frame = 0, mean_model = 0;
    double ff = 0, mm = 0, fm = 0;
  };
  static Moments MomentsOf(const std::vector<std::pair<double, double>>& pairs) {
    Moments s;
    for (const auto& [f, m] : pairs) s.mean_frame += f, s.mean_model += m;
    s.mean_frame /= pairs.size(), s.mean_model /= pairs.size();
    for (const auto& [f, m] : pairs) {
      const double df = f - s.mean_frame, dm = m - s.mean_model;
      s.ff += df * df, s.mm += dm * dm, s.fm += df * dm;
    }
    return s;
  }

  // The (frame, model) greys of the points that pair at `correction`.
  std::vector<std::pair<double, double>> Greys(const Rigid3& correction) const {
    std::vector<std::pair<double, double>> pairs;
    for (const ColourPoint& point : points_) {
      ModelSample sample;
      if (Pair(correction * point.point, &sample)) pairs.emplace_back(point.grey, sample.grey);
    }
    return pairs;
  }

  static double Huber(double residual, double threshold) {
    const double a = std::abs(residual);
    return a <= threshold ? 0.5 * a * a : threshold * (a - 0.5 * threshold);
  }

  bool Pair(const Eigen::Vector3d& q, ModelSample* sample) const {
    if (q.z() <= 0) return false;
    const Eigen::Vector2d pixel = intrinsics_.Project(q);
    if (!intrinsics_.Contains(pixel.x(), pixel.y())) return false;
    const float depth = model_.DepthAt(pixel.x(), pixel.y());
    if (!(depth > 0) || std::abs(depth - q.z()) > options_.max_depth_gap_mm) return false;
    return model_.Sample(pixel.x(), pixel.y(), sample);
  }

  const std::vector<ColourPoint>& points_;
  const ModelImage& model_;
  const CameraIntrinsics& intrinsics_;
  const std::vector<FreeDirection>& free_;
  const Eigen::Vector3d centre_;
  const ColourAlignOptions& options_;
  double gain_ = 1, offset_ = 0, sigma_ = 1;
};

// The motion `x` (one entry per free direction) makes about `centre`.
Rigid3 Motion(const std::vector<FreeDirection>& free, const Eigen::Vector3d& centre,
              const Eigen::VectorXd& x) {
  Eigen::Vector3d turn = Eigen::Vector3d::Zero(), shift = Eigen::Vector3d::Zero();
  for (size_t c = 0; c < free.size(); ++c)
    turn += x[c] * free[c].turn, shift += x[c] * free[c].shift;
  return Rigid3::Translation(centre + shift) *
         Rigid3::FromRotationVector(turn, Eigen::Vector3d::Zero()) * Rigid3::Translation(-centre);
}

// Every `stride`-th pixel of the frame's object (where `grey` holds it) as a point.
std::vector<ColourPoint> SamplePoints(const Frame& frame, const GreyPatch& grey,
                                      const CameraIntrinsics& intrinsics, int stride) {
  std::vector<ColourPoint> points;
  for (int v = grey.v0; v < grey.v0 + grey.height; v += stride) {
    for (int u = grey.u0; u < grey.u0 + grey.width; u += stride) {
      if (!grey.Holds(u, v)) continue;
      const double depth = frame.depth_mm[static_cast<size_t>(v) * frame.width + u];
      points.push_back({intrinsics.BackProject(u, v, depth), u, v, 0.0f});
    }
  }
  return points;
}

// Scales each direction to move `points` (taken by `correction`) by 1 mm RMS, so that the prior
// is in mm; false where one does not move them.
bool ScaleDirections(const std::vector<ColourPoint>& points, const Rigid3& correction,
                     const Eigen::Vector3d& centre, std::vector<FreeDirection>* directions) {
  for (FreeDirection& direction : *directions) {
    double sum_sq = 0;
    for (const ColourPoint& point : points) {
      const Eigen::Vector3d q = correction * point.point;
      sum_sq += (direction.turn.cross(q - centre) + direction.shift).squaredNorm();
    }
    const double rms = std::sqrt(sum_sq / points.size());
    if (!(rms > 1e-9)) return false;
    direction.turn /= rms, direction.shift /= rms;
  }
  return true;
}

// Gauss–Newton from `x` (and the correction it made, `current`) on one blur level, the prior
// pulling `x` toward zero; returns whether it moved.
bool FitLevel(const ColourProblem& problem, const std::vector<FreeDirection>& directions,
              const Eigen::Vector3d& centre, double prior, int iterations, Eigen::VectorXd* x,
              Rigid3* current, int* paired) {
  const int k = static_cast<int>(directions.size());
  const double scale = 1.0 / (problem.sigma() * problem.sigma());
  bool moved_any = false;
  for (int iteration = 0; iteration < iterations; ++iteration) {
    Eigen::MatrixXd matrix;
    Eigen::VectorXd rhs;
    const double cost =
        scale * problem.Cost(*current, &matrix, &rhs, paired) + 0.5 * prior * x->squaredNorm();
    const Eigen::MatrixXd normal = scale * matrix + prior * Eigen::MatrixXd::Identity(k, k);
    const Eigen::VectorXd step = normal.ldlt().solve(scale * rhs - prior * *x);
    if (!step.allFinite()) break;
    const Rigid3 moved = Motion(directions, centre, step) * *current;
    const double moved_cost = scale * problem.Cost(moved) + 0.5 * prior * (*x + step).squaredNorm();
    if (!(moved_cost < cost)) break;
    *current = moved;
    *x += step;
    moved_any = true;
    if (step.norm() < 0.01) break;
  }
  return moved_any;
}

// What the colour tells of each free direction (1/mm²): how much deeper its basin is at
// `current` than `profile_mm` either way (the shallower side), as a Gaussian's information,
// divided among the samples that one blur footprint correlates. A local curvature overstates a
// shallow or rugged basin, where a label's alike spots or a smeared model leave several minima.
std::vector<double> ProfileInformation(const ColourProblem& problem,
                                       const std::vector<FreeDirection>& directions,
                                       const Eigen::Vector3d& centre, const Rigid3& current,
                                       const ColourAlignOptions& options) {
  const double scale = 1.0 / (problem.sigma() * problem.sigma());
  const double h = options.profile_mm;
  const double at = scale * problem.Cost(current);
  std::vector<double> information;
  for (size_t c = 0; c < directions.size(); ++c) {
    double depth = std::numeric_limits<double>::infinity();
    for (const double sign : {-1.0, 1.0}) {
      Eigen::VectorXd off = Eigen::VectorXd::Zero(directions.size());
      off[c] = sign * h;
      depth = std::min(depth, scale * problem.Cost(Motion(directions, centre, off) * current) - at);
    }
    information.push_back(std::max(0.0, 2 * depth / (h * h * options.correlated_samples)));
  }
  return information;
}

// Fits `x` (and `current`, the correction it makes) on the coarse blur, then the fine one;
// returns what the fine one's basin says of each direction (ProfileInformation), none where a
// blur showed no pattern (then nothing is applied).
std::vector<double> FitBlurs(const GreyPatch& frame_grey, const GreyPatch& model_grey,
                             const RaycastImage& model, const CameraIntrinsics& intrinsics,
                             const std::vector<FreeDirection>& directions,
                             const Eigen::Vector3d& centre, const ColourAlignOptions& options,
                             std::vector<ColourPoint>* points, Eigen::VectorXd* x, Rigid3* current,
                             ColourAlignResult* result) {
  const double prior = 1.0 / (options.prior_mm * options.prior_mm);
  std::vector<double> information;
  for (const double blur : {options.coarse_blur_px, options.fine_blur_px}) {
    const GreyPatch blurred_frame = Blurred(frame_grey, blur);
    for (ColourPoint& point : *points)
      point.grey = blurred_frame.grey[blurred_frame.Index(point.u, point.v)];
    const GreyPatch blurred_model = Blurred(model_grey, blur);
    const ModelImage image(blurred_model, model);
    ColourProblem problem(*points, image, intrinsics, directions, centre, options);
    if (!problem.Calibrate(*current)) {
      result->reason = "no pattern to align";
      result->applied = false;
      return {};
    }
    result->applied |= FitLevel(problem, directions, centre, prior, options.iterations, x, current,
                                &result->points);
    result->sigma = problem.sigma();
    if (blur == options.fine_blur_px) {
      information = ProfileInformation(problem, directions, centre, *current, options);
      result->correlation = problem.Correlation(*current);
    }
  }
  return information;
}

// The frame's grey over the object's box (its pixels under the mask with depth).
GreyPatch FrameGrey(const Frame& frame, const std::vector<std::uint8_t>& mask,
                    const std::array<int, 4>& box) {
  GreyPatch patch;
  patch.Resize(std::max(0, box[0]), std::max(0, box[1]), std::min(frame.width, box[2]),
               std::min(frame.height, box[3]));
  for (int v = patch.v0; v < patch.v0 + patch.height; ++v) {
    for (int u = patch.u0; u < patch.u0 + patch.width; ++u) {
      const size_t pixel = static_cast<size_t>(v) * frame.width + u;
      if (!mask[pixel] || frame.depth_mm[pixel] == 0) continue;
      patch.grey[patch.Index(u, v)] = Grey(&frame.rgb[3 * pixel]);
      patch.valid[patch.Index(u, v)] = 1;
    }
  }
  return patch;
}

// The model's grey where the raycast hit surface that faces the camera by `min_facing` and
// that at least `min_weight` pixels coloured.
GreyPatch ModelGrey(const RaycastImage& model, const CameraIntrinsics& intrinsics, int min_weight,
                    double min_facing) {
  GreyPatch patch;
  patch.Resize(std::max(0, model.written[0]), std::max(0, model.written[1]),
               std::min(model.width, model.written[2]), std::min(model.height, model.written[3]));
  for (int v = patch.v0; v < patch.v0 + patch.height; ++v) {
    for (int u = patch.u0; u < patch.u0 + patch.width; ++u) {
      const size_t pixel = static_cast<size_t>(v) * model.width + u;
      if (!(model.depth_mm[pixel] > 0) || model.color_weights[pixel] < min_weight) continue;
      const Eigen::Vector3d ray = intrinsics.BackProject(u, v, 1.0).normalized();
      if (!(-model.normals[pixel].cast<double>().dot(ray) >= min_facing)) continue;
      const TriangleMesh::Color& colour = model.colors[pixel];
      const std::uint8_t rgb[3] = {colour[0], colour[1], colour[2]};
      patch.grey[patch.Index(u, v)] = Grey(rgb);
      patch.valid[patch.Index(u, v)] = 1;
    }
  }
  return patch;
}

}  // namespace

ColourAlignResult AlignColour(const Frame& frame, const std::vector<std::uint8_t>& mask,
                              const std::array<int, 4>& box, const RaycastImage& model,
                              const CameraIntrinsics& intrinsics, const Rigid3& correction,
                              const std::vector<FreeDirection>& free, const Eigen::Vector3d& centre,
                              const ColourAlignOptions& options) {
  options.Check();
  ColourAlignResult result;
  result.correction = correction;
  auto skip = [&result](const char* reason) {
    result.reason = reason;
    return result;
  };
  if (free.empty()) return skip("no free direction");
  if (!frame.HasColor() || model.colors.size() != model.depth_mm.size() ||
      model.color_weights.size() != model.depth_mm.size() || mask.size() != frame.depth_mm.size()) {
    return skip("no colour");
  }
  // Both over the pixels where both hold the object (the motion between them is a few pixels):
  // the shading's blur must average the same pixels in both, or an edge of one's support (the
  // pattern just turning into view at the outline, which the model does not compare yet) would
  // shift the other's detail.
  GreyPatch frame_raw = FrameGrey(frame, mask, box);
  GreyPatch model_raw =
      ModelGrey(model, intrinsics, options.min_model_colourings, options.min_facing);
  Intersect(&frame_raw, &model_raw);
  GreyPatch frame_grey = Detail(frame_raw, options.shading_blur_px);
  GreyPatch model_grey = Detail(model_raw, options.shading_blur_px);
  if (options.remove_shading) {
    result.shading_share =
        RemoveShading(model, intrinsics, options.shading_blur_px, &frame_grey, &model_grey);
    if (result.shading_share > options.max_shading_share) {
      result.no_pattern = true;
      return skip("shading, no pattern");
    }
  }
  // Both must show it: a pattern of the object's is in the model as well (hand pixels at the
  // mask's edge, a shadow, are in one frame).
  result.pattern_spread = std::min(Spread(frame_grey), Spread(model_grey));
  if (result.pattern_spread < options.min_grey_spread) {
    result.no_pattern = true;
    return skip("no pattern to align");
  }
  // Every stride-th pixel, fewer on a large object (max_points).
  int held = 0;
  for (std::uint8_t valid : frame_grey.valid) held += valid;
  const int stride = std::max(
      options.stride,
      static_cast<int>(std::ceil(std::sqrt(static_cast<double>(held) / options.max_points))));
  std::vector<ColourPoint> points = SamplePoints(frame, frame_grey, intrinsics, stride);
  if (static_cast<int>(points.size()) < options.min_points) return skip("too few points");
  std::vector<FreeDirection> directions = free;
  if (!ScaleDirections(points, correction, centre, &directions))
    return skip("degenerate free direction");
  const int k = static_cast<int>(directions.size());
  const double prior = 1.0 / (options.prior_mm * options.prior_mm);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(k);
  Rigid3 current = correction;
  const std::vector<double> information =
      FitBlurs(frame_grey, model_grey, model, intrinsics, directions, centre, options, &points, &x,
               &current, &result);
  // Each direction kept as far as the colour's basin fixes it against the prior.
  double least = std::numeric_limits<double>::infinity();
  for (int c = 0; c < k && c < static_cast<int>(information.size()); ++c) {
    x[c] *= information[c] / (information[c] + prior);
    least = std::min(least, information[c]);
  }
  if (information.empty()) least = 0, x.setZero();
  result.uncertainty_mm = 1.0 / std::sqrt(least + prior);
  current = Motion(directions, centre, x) * correction;
  if (!result.applied) {
    if (result.reason.empty()) result.reason = "no better alignment";
    return result;
  }
  result.reason.clear();
  result.correction = current;
  double sum_sq = 0;
  for (const ColourPoint& point : points)
    sum_sq += (current * point.point - correction * point.point).squaredNorm();
  result.moved_mm = std::sqrt(sum_sq / points.size());
  result.turn_deg =
      Eigen::AngleAxisd((current * correction.Inverse()).rotation()).angle() * 180.0 / M_PI;
  return result;
}

}  // namespace ihs::fusion

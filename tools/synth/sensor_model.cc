#include "tools/synth/sensor_model.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "core/check.h"

namespace ihs::synth {

void SensorModelOptions::Check() const {
  IHS_CHECK_ARG(noise_coefficient_per_mm >= 0, "sensor.noise_coefficient_per_mm must be >= 0");
  IHS_CHECK_ARG(baseline_mm > 0, "sensor.baseline_mm must be positive");
  IHS_CHECK_ARG(subpixel >= 1, "sensor.subpixel must be at least 1");
  IHS_CHECK_ARG(max_incidence_deg > 0 && max_incidence_deg <= 90,
                "sensor.max_incidence_deg must be in (0, 90]");
  IHS_CHECK_ARG(edge_jump_mm > 0, "sensor.edge_jump_mm must be positive");
  IHS_CHECK_ARG(edge_dropout_probability >= 0 && flying_probability >= 0 &&
                    edge_dropout_probability + flying_probability <= 1,
                "sensor edge probabilities must be >= 0 and sum to at most 1");
  IHS_CHECK_ARG(color_sigma >= 0, "sensor.color_sigma must be >= 0");
  IHS_CHECK_ARG(max_misregistration_px >= 0, "sensor.max_misregistration_px must be >= 0");
}

SensorModelOptions SensorModelOptions::Ideal() {
  SensorModelOptions options;
  options.depth_noise = options.quantization = options.grazing_dropout = false;
  options.silhouette_effects = options.color_noise = options.misregistration = false;
  return options;
}

Frame ApplySensorModel(const render::RenderOutput& rendering, const CameraIntrinsics& intrinsics,
                       const SensorModelOptions& options, std::mt19937& rng) {
  options.Check();
  const int w = rendering.width, h = rendering.height;
  IHS_CHECK_ARG(w == intrinsics.width && h == intrinsics.height,
                "rendering and intrinsics differ in size");
  std::vector<double> depth(rendering.depth_mm.begin(), rendering.depth_mm.end());
  auto at = [&](int u, int v) { return depth[static_cast<size_t>(v) * w + u]; };
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);

  // Geometry decisions use the noise-free depth.
  std::vector<double> out = depth;
  const double cos_limit = std::cos(options.max_incidence_deg * M_PI / 180.0);
  for (int v = 1; v + 1 < h; ++v) {
    for (int u = 1; u + 1 < w; ++u) {
      const size_t i = static_cast<size_t>(v) * w + u;
      const double z = depth[i];
      if (z <= 0) continue;
      if (options.silhouette_effects) {
        // A foreground pixel at a silhouette: a neighbour is empty or much farther away.
        bool edge = false;
        double behind = 0;
        for (const auto& [du, dv] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
          const double n = at(u + du, v + dv);
          if (n <= 0) {
            edge = true;
          } else if (n - z > options.edge_jump_mm) {
            edge = true;
            behind = std::max(behind, n);
          }
        }
        if (edge) {
          const double r = uniform(rng);
          if (r < options.edge_dropout_probability) {
            out[i] = 0;
            continue;
          }
          if (behind > 0 && r < options.edge_dropout_probability + options.flying_probability) {
            out[i] = z + uniform(rng) * (behind - z);
            continue;
          }
        }
      }
      if (options.grazing_dropout) {
        const double zr = at(u + 1, v), zl = at(u - 1, v), zd = at(u, v + 1), zu = at(u, v - 1);
        if (zr > 0 && zl > 0 && zd > 0 && zu > 0) {
          const Eigen::Vector3d dx =
              intrinsics.BackProject(u + 1, v, zr) - intrinsics.BackProject(u - 1, v, zl);
          const Eigen::Vector3d dy =
              intrinsics.BackProject(u, v + 1, zd) - intrinsics.BackProject(u, v - 1, zu);
          const Eigen::Vector3d n = dx.cross(dy);
          const Eigen::Vector3d ray = intrinsics.BackProject(u, v, z);
          if (n.norm() > 0 && std::abs(n.dot(ray)) / (n.norm() * ray.norm()) < cos_limit) {
            out[i] = 0;
            continue;
          }
        }
      }
    }
  }
  const double f_b = intrinsics.fx * options.baseline_mm;
  Frame frame = Frame::Blank(w, h);
  for (size_t i = 0; i < out.size(); ++i) {
    double z = out[i];
    if (z <= 0) continue;
    if (options.depth_noise) z += options.noise_coefficient_per_mm * z * z * normal(rng);
    if (options.quantization) {
      const double disparity = std::round(f_b / z * options.subpixel) / options.subpixel;
      z = disparity > 0 ? f_b / disparity : 0;
    }
    frame.depth_mm[i] = z > 0 && z < 65535 ? static_cast<std::uint16_t>(std::lround(z)) : 0;
  }
  // Colour: shifted by the misregistration, then noisy.
  int shift_u = 0, shift_v = 0;
  if (options.misregistration && options.max_misregistration_px > 0) {
    std::uniform_int_distribution<int> shift(-static_cast<int>(options.max_misregistration_px),
                                             static_cast<int>(options.max_misregistration_px));
    shift_u = shift(rng);
    shift_v = shift(rng);
  }
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const int su = std::clamp(u + shift_u, 0, w - 1), sv = std::clamp(v + shift_v, 0, h - 1);
      for (int c = 0; c < 3; ++c) {
        double value = rendering.rgb[3 * (static_cast<size_t>(sv) * w + su) + c];
        if (options.color_noise) value += options.color_sigma * normal(rng);
        frame.rgb[3 * (static_cast<size_t>(v) * w + u) + c] =
            static_cast<std::uint8_t>(std::clamp(std::lround(value), 0L, 255L));
      }
    }
  }
  return frame;
}

}  // namespace ihs::synth

#pragma once
// What a structured-light depth camera (Kinect v1 / Carmine) does to a perfect rendering:
// depth noise growing with z² (Khoshelham & Elberink 2012), disparity quantisation, missing
// depth at grazing angles and along silhouettes, flying pixels between foreground and
// background, colour noise, and a small depth–colour misregistration. Every effect can be
// switched off; with all off the output is the rendering rounded to whole millimetres.

#include <random>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "render/offscreen_renderer.h"

namespace ihs::synth {

/// Parameters of the sensor model. Defaults: a Carmine 1.09 / Kinect v1 at arm's length.
struct SensorModelOptions {
  /// Gaussian depth noise σ = coefficient · z² (z and σ in mm); 1.425e-6 gives 0.51 mm at 600 mm.
  bool depth_noise = true;
  double noise_coefficient_per_mm = 1.425e-6;
  /// Disparity quantisation in 1/`subpixel` steps of d = f·b/z (about 1.1 mm at 600 mm).
  bool quantization = true;
  double baseline_mm = 75.0;
  int subpixel = 8;
  /// Surfaces seen at more than this angle from the viewing ray return no depth.
  bool grazing_dropout = true;
  double max_incidence_deg = 78.0;
  /// Pixels next to a depth jump larger than `edge_jump_mm`: dropped with this probability, else
  /// (flying pixels) given a depth between the two sides with `flying_probability`.
  bool silhouette_effects = true;
  double edge_jump_mm = 15.0;
  double edge_dropout_probability = 0.5;
  double flying_probability = 0.2;
  /// Gaussian colour noise, σ in grey levels.
  bool color_noise = true;
  double color_sigma = 3.0;
  /// Colour shifted against depth by a random offset of up to this many pixels (one per call).
  bool misregistration = true;
  double max_misregistration_px = 1.0;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
  /// All effects off.
  static SensorModelOptions Ideal();
};

/// Turns a rendering into the frame a sensor would deliver (depth in whole mm, RGB8). Uses only
/// `rng` for randomness, so a fixed seed gives the same frame.
Frame ApplySensorModel(const render::RenderOutput& rendering, const CameraIntrinsics& intrinsics,
                       const SensorModelOptions& options, std::mt19937& rng);

}  // namespace ihs::synth

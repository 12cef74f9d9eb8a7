#pragma once
// Skin colour: the skin and non-skin Gaussian mixtures of Jones & Rehg ("Statistical Color Models
// with Application to Skin Detection", IJCV 2002; Compaq CRL 98/11, Table 1): 16 diagonal
// Gaussians each in RGB, fitted to about a billion labelled web-image pixels. A pixel is skin when
// the log-likelihood ratio log p(rgb | skin) − log p(rgb | non-skin) exceeds a threshold.

#include <array>
#include <cstdint>
#include <vector>

namespace ihs::tracker {

/// The two mixtures, tabulated over RGB quantised to 64 levels per channel for speed.
class SkinColorModel {
 public:
  SkinColorModel();

  /// log p(rgb | skin) − log p(rgb | non-skin), from the mixtures directly.
  static double LogLikelihoodRatioExact(double r, double g, double b);

  /// The same from the table (at the centre of the quantisation cell), fast.
  float LogLikelihoodRatio(std::uint8_t r, std::uint8_t g, std::uint8_t b) const {
    return table_[(static_cast<int>(r) >> 2) << 12 | (static_cast<int>(g) >> 2) << 6 |
                  (static_cast<int>(b) >> 2)];
  }

 private:
  std::vector<float> table_;
};

}  // namespace ihs::tracker

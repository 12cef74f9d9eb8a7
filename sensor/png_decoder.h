#pragma once
// PNG images decoded with libpng directly, its messages kept: through OpenCV, libpng's default
// handlers print "libpng error: ..." lines of their own on stderr for a damaged file, beside the
// scanner's one-line warning about the same frame.

#include <opencv2/core.hpp>
#include <string>

namespace ihs::sensor {

/// Whether `bytes` start with the PNG signature.
bool IsPng(const std::string& bytes);

/// Decodes the PNG in `bytes`: a 16-bit greyscale image as CV_16UC1 (its samples as they are,
/// no gamma applied) when `depth`, and any other image (or any image when not `depth`) as 8-bit
/// BGR, CV_8UC3. Returns an empty Mat and sets `*problem` (libpng's message) when the file is
/// damaged or declares more than `max_pixels` pixels.
cv::Mat DecodePng(const std::string& bytes, bool depth, std::uint64_t max_pixels,
                  std::string* problem);

}  // namespace ihs::sensor

// libFuzzer target for the JPEG decoder of .oni colour frames and TUM folders' images
// (sensor/jpeg_decoder.h): the input is the file. A damaged file must come back as an empty image
// with its problem said; a decoded one must be 8-bit BGR within the pixels allowed.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "sensor/jpeg_decoder.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  constexpr std::uint64_t kMaxPixels = 1024 * 1024;
  std::string problem;
  const cv::Mat image = ihs::sensor::DecodeJpeg(
      std::string_view(reinterpret_cast<const char*>(data), size), kMaxPixels, &problem);
  if (image.empty() == problem.empty()) std::abort();  // Either an image or a reason.
  if (!image.empty() && (image.type() != CV_8UC3 || image.total() > kMaxPixels)) std::abort();
  return 0;
}

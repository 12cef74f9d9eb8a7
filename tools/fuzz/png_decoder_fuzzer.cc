// libFuzzer target for the PNG decoder of TUM folders' images (sensor/png_decoder.h): the first
// byte chooses depth (16-bit grey wanted) or colour, the rest is the file. A damaged file must
// come back as an empty image with its problem said; a decoded one must be of the size and type
// asked for.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "sensor/png_decoder.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const bool depth = data[0] & 1;
  const std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  std::string problem;
  const cv::Mat image = ihs::sensor::DecodePng(bytes, depth, 1024 * 1024, &problem);
  if (image.empty() == problem.empty()) std::abort();  // Either an image or a reason.
  if (!image.empty() && image.type() != CV_16UC1 && image.type() != CV_8UC3) std::abort();
  if (!image.empty() && image.type() == CV_16UC1 && !depth) std::abort();
  return 0;
}

#pragma once
// JPEG images decoded with libjpeg directly, its messages kept: through OpenCV, libjpeg prints
// "Corrupt JPEG data: ..." and "Premature end of JPEG file" lines of its own on stderr for damaged
// data, beside the scanner's one-line warning about the same frame, and decodes such data to a
// damaged image without saying so.

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>

namespace ihs::sensor {

/// Whether `bytes` start with a JPEG's start-of-image marker (FF D8 FF).
bool IsJpeg(std::string_view bytes);

/// Decodes the JPEG in `bytes` to 8-bit BGR, CV_8UC3: the pixels cv::imdecode(IMREAD_COLOR)
/// gives for a colour or greyscale JPEG, and a CMYK one converted as OpenCV converts it (no EXIF
/// orientation is applied: a camera's frame pairs pixel for pixel with its depth). Returns an
/// empty Mat and sets `*problem` (libjpeg's message) when the data is damaged — libjpeg's
/// corrupt-data warnings included: such an image is not used — or declares more than
/// `max_pixels` pixels (refused before the image is allocated).
cv::Mat DecodeJpeg(std::string_view bytes, std::uint64_t max_pixels, std::string* problem);

}  // namespace ihs::sensor

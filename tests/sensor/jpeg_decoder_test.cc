// The JPEG decoder of .oni colour frames and TUM folders' images (libjpeg used directly): the
// pixels OpenCV's decoder gives for good files, a one-line reason and nothing on stderr for
// damaged ones.

#include "sensor/jpeg_decoder.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>
// clang-format off
#include <jpeglib.h>
// clang-format on

namespace ihs::sensor {
namespace {

constexpr std::uint64_t kMaxPixels = 4096ull * 4096ull;

// A 64x48 image with smooth gradients and sharp edges (chroma subsampling and the DCT both
// matter), of `channels` 1 or 3.
cv::Mat TestImage(int channels) {
  cv::Mat image(48, 64, CV_8UC(channels));
  for (int v = 0; v < image.rows; ++v) {
    for (int u = 0; u < image.cols; ++u) {
      for (int c = 0; c < channels; ++c) {
        const int edge = ((u / 7 + v / 5) % 2) * 90;
        image.ptr(v)[u * channels + c] =
            static_cast<std::uint8_t>((3 * u + 5 * v + 60 * c + edge) % 256);
      }
    }
  }
  return image;
}

std::string Encode(const cv::Mat& image, const std::vector<int>& params = {}) {
  std::vector<std::uint8_t> bytes;
  EXPECT_TRUE(cv::imencode(".jpg", image, bytes, params));
  return std::string(bytes.begin(), bytes.end());
}

cv::Mat OpenCvDecode(const std::string& bytes) {
  return cv::imdecode(
      cv::Mat(1, static_cast<int>(bytes.size()), CV_8UC1, const_cast<char*>(bytes.data())),
      cv::IMREAD_COLOR);
}

void ExpectSamePixels(const cv::Mat& ours, const cv::Mat& theirs) {
  ASSERT_EQ(ours.type(), CV_8UC3);
  ASSERT_EQ(ours.size(), theirs.size());
  EXPECT_EQ(cv::norm(ours, theirs, cv::NORM_INF), 0.0);
}

// A CMYK JPEG (OpenCV writes none), made with libjpeg.
std::string EncodeCmyk(const cv::Mat& cmyk) {
  jpeg_compress_struct info{};
  jpeg_error_mgr errors{};
  info.err = jpeg_std_error(&errors);
  jpeg_create_compress(&info);
  unsigned char* buffer = nullptr;
  unsigned long size = 0;
  jpeg_mem_dest(&info, &buffer, &size);
  info.image_width = static_cast<JDIMENSION>(cmyk.cols);
  info.image_height = static_cast<JDIMENSION>(cmyk.rows);
  info.input_components = 4;
  info.in_color_space = JCS_CMYK;
  jpeg_set_defaults(&info);
  jpeg_start_compress(&info, TRUE);
  for (int v = 0; v < cmyk.rows; ++v) {
    JSAMPROW row = const_cast<std::uint8_t*>(cmyk.ptr(v));
    jpeg_write_scanlines(&info, &row, 1);
  }
  jpeg_finish_compress(&info);
  jpeg_destroy_compress(&info);
  std::string bytes(reinterpret_cast<const char*>(buffer), size);
  std::free(buffer);
  return bytes;
}

TEST(JpegDecoderTest, ColourJpegsDecodeToOpenCvsPixelsExactly) {
  const cv::Mat image = TestImage(3);
  const std::vector<std::vector<int>> settings = {
      {},                                                                 // 4:2:0, quality 95
      {cv::IMWRITE_JPEG_QUALITY, 60, cv::IMWRITE_JPEG_PROGRESSIVE, 1},    // progressive
      {cv::IMWRITE_JPEG_OPTIMIZE, 1, cv::IMWRITE_JPEG_RST_INTERVAL, 2}};  // restart markers
  for (const auto& params : settings) {
    const std::string bytes = Encode(image, params);
    ASSERT_TRUE(IsJpeg(bytes));
    std::string problem;
    ExpectSamePixels(DecodeJpeg(bytes, kMaxPixels, &problem), OpenCvDecode(bytes));
    EXPECT_EQ(problem, "");
  }
}

TEST(JpegDecoderTest, GreyAndCmykJpegsDecodeToOpenCvsBgr) {
  const std::string grey = Encode(TestImage(1));
  std::string problem;
  const cv::Mat decoded = DecodeJpeg(grey, kMaxPixels, &problem);
  ExpectSamePixels(decoded, OpenCvDecode(grey));
  EXPECT_EQ(decoded.at<cv::Vec3b>(10, 20)[0], decoded.at<cv::Vec3b>(10, 20)[2]);
  cv::Mat cmyk;
  cv::merge(std::vector<cv::Mat>{TestImage(3), TestImage(1)}, cmyk);
  const std::string bytes = EncodeCmyk(cmyk);
  ExpectSamePixels(DecodeJpeg(bytes, kMaxPixels, &problem), OpenCvDecode(bytes));
  EXPECT_EQ(problem, "");
}

// Each damaged form comes back empty with libjpeg's reason, and libjpeg prints nothing (through
// OpenCV it printed "Corrupt JPEG data: ..." lines and returned an image for most of them).
TEST(JpegDecoderTest, DamagedJpegsGiveAReasonAndPrintNothing) {
  const std::string good = Encode(TestImage(3));
  const std::size_t scan = good.find("\xFF\xDA");
  ASSERT_NE(scan, std::string::npos);
  std::string marker_in_scan = good, bad_huffman = good, extra_bytes = good;
  marker_in_scan.replace(scan + 40, 2, "\xFF\xD9");  // The end marker inside the image's data.
  const std::size_t huffman = good.find("\xFF\xC4");
  bad_huffman.replace(huffman + 5, 4, "\xFF\xFF\xFF\xFF");  // Code counts summing over 256.
  extra_bytes.insert(good.size() - 2, "twelve bytes");      // Before the end marker.
  const std::vector<std::pair<std::string, std::string>> damaged = {
      {good.substr(0, good.size() / 2), "Premature end of JPEG file"},
      {marker_in_scan, "Corrupt JPEG data"},
      {bad_huffman, "Huffman"},
      {extra_bytes, "extraneous bytes before marker 0xd9"},
      {"\xFF\xD8\xFF garbage", "JPEG"},
      {"", "JPEG"}};
  for (const auto& [bytes, reason] : damaged) {
    std::string problem;
    testing::internal::CaptureStderr();
    const cv::Mat image = DecodeJpeg(bytes, kMaxPixels, &problem);
    const std::string printed = testing::internal::GetCapturedStderr();
    EXPECT_TRUE(image.empty()) << reason;
    EXPECT_EQ(problem.rfind("damaged JPEG (", 0), 0u) << problem;
    EXPECT_NE(problem.find(reason), std::string::npos) << problem;
    EXPECT_EQ(printed, "") << reason;
  }
}

// A header declaring 20000 x 20000 pixels (1.2 GB decoded) is refused once read, before
// decompressing: the same bytes allowed that many pixels fail later, on their missing tables.
TEST(JpegDecoderTest, JpegsDeclaringTooManyPixelsAreRefusedBeforeDecoding) {
  const std::string huge(
      "\xFF\xD8"                                                                      // SOI
      "\xFF\xC0\x00\x11\x08\x4E\x20\x4E\x20\x03\x01\x22\x00\x02\x11\x01\x03\x11\x01"  // SOF0
      "\xFF\xDA\x00\x0C\x03\x01\x00\x02\x11\x03\x11\x00\x3F\x00"                      // SOS
      "\xFF\xD9",                                                                     // EOI
      37);
  std::string problem;
  EXPECT_TRUE(DecodeJpeg(huge, kMaxPixels, &problem).empty());
  EXPECT_EQ(problem, "JPEG of 20000x20000 pixels, more than the 16777216 allowed");
  problem.clear();
  EXPECT_TRUE(DecodeJpeg(huge, 20000ull * 20000ull, &problem).empty());
  EXPECT_EQ(problem.rfind("damaged JPEG (", 0), 0u) << problem;
}

}  // namespace
}  // namespace ihs::sensor

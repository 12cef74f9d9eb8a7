#include "sensor/jpeg_decoder.h"

// jpeglib.h needs FILE and size_t declared before it.
#include <cstddef>
#include <cstdio>
// clang-format off
#include <jpeglib.h>
// clang-format on

#include <csetjmp>

namespace ihs::sensor {
namespace {

// What one decode reads and makes; libjpeg's callbacks reach it through the decompressor's
// client_data, so its fields live in memory when an error jumps back.
struct JpegRead {
  jpeg_error_mgr errors{};
  std::jmp_buf jump{};
  std::string_view bytes;
  std::uint64_t max_pixels = 0;
  std::string problem;
  cv::Mat image;  // BGR, or CMYK before ToBgr.
};

// libjpeg's message into the problem, and back to Decode's setjmp. Nothing here needs a
// destructor when the jump leaves.
[[noreturn]] void Fail(j_common_ptr info) {
  auto* read = static_cast<JpegRead*>(info->client_data);
  char text[JMSG_LENGTH_MAX];
  (*info->err->format_message)(info, text);
  read->problem = std::string("damaged JPEG (") + text + ")";
  std::longjmp(read->jump, 1);
}

// Warnings (level -1) are libjpeg's corrupt-data reports ("Corrupt JPEG data: ...", "Premature
// end of JPEG file"): the image it would go on to make is damaged, so the decode stops there, as
// libjpeg-turbo's TJFLAG_STOPONWARNING does. Trace messages (levels 0 and up) are dropped.
void OnMessage(j_common_ptr info, int level) {
  if (level < 0) Fail(info);
}

// Nothing is printed: every message reaches the caller through `*problem`.
void DropMessage(j_common_ptr) {}

// The libjpeg calls; an error comes back here by longjmp, so nothing in this frame may need a
// destructor: what the decode makes lives in `read`.
bool Decode(jpeg_decompress_struct* info, JpegRead* read) {
  if (setjmp(read->jump)) return false;
  jpeg_create_decompress(info);
  jpeg_mem_src(info, reinterpret_cast<const unsigned char*>(read->bytes.data()),
               static_cast<unsigned long>(read->bytes.size()));
  jpeg_read_header(info, TRUE);
  if (static_cast<std::uint64_t>(info->image_width) * info->image_height > read->max_pixels) {
    read->problem = "JPEG of " + std::to_string(info->image_width) + "x" +
                    std::to_string(info->image_height) + " pixels, more than the " +
                    std::to_string(read->max_pixels) + " allowed";
    return false;
  }
  const bool cmyk = info->num_components == 4;  // CMYK or YCCK, as OpenCV tells them apart.
  info->out_color_space = cmyk ? JCS_CMYK : JCS_EXT_BGR;
  jpeg_start_decompress(info);
  read->image.create(static_cast<int>(info->output_height), static_cast<int>(info->output_width),
                     cmyk ? CV_8UC4 : CV_8UC3);
  while (info->output_scanline < info->output_height) {
    JSAMPROW row = read->image.ptr(static_cast<int>(info->output_scanline));
    jpeg_read_scanlines(info, &row, 1);
  }
  jpeg_finish_decompress(info);  // Reads up to the end marker: damage after the image shows.
  return true;
}

// OpenCV's conversion of (Adobe's inverted) CMYK samples to BGR.
cv::Mat ToBgr(const cv::Mat& cmyk) {
  cv::Mat bgr(cmyk.rows, cmyk.cols, CV_8UC3);
  for (int v = 0; v < cmyk.rows; ++v) {
    const std::uint8_t* in = cmyk.ptr(v);
    std::uint8_t* out = bgr.ptr(v);
    for (int u = 0; u < cmyk.cols; ++u, in += 4, out += 3) {
      const int k = in[3];
      for (int c = 0; c < 3; ++c)
        out[2 - c] = static_cast<std::uint8_t>(k - ((255 - in[c]) * k >> 8));
    }
  }
  return bgr;
}

}  // namespace

bool IsJpeg(std::string_view bytes) {
  return bytes.size() >= 3 && static_cast<unsigned char>(bytes[0]) == 0xFF &&
         static_cast<unsigned char>(bytes[1]) == 0xD8 &&
         static_cast<unsigned char>(bytes[2]) == 0xFF;
}

cv::Mat DecodeJpeg(std::string_view bytes, std::uint64_t max_pixels, std::string* problem) {
  JpegRead read;
  read.bytes = bytes;
  read.max_pixels = max_pixels;
  jpeg_decompress_struct info{};
  info.client_data = &read;  // jpeg_create_decompress keeps it.
  info.err = jpeg_std_error(&read.errors);
  read.errors.error_exit = Fail;
  read.errors.emit_message = OnMessage;
  read.errors.output_message = DropMessage;
  const bool ok = Decode(&info, &read);
  jpeg_destroy_decompress(&info);
  if (!ok) {
    *problem = read.problem;
    return {};
  }
  return read.image.type() == CV_8UC4 ? ToBgr(read.image) : read.image;
}

}  // namespace ihs::sensor

#include "sensor/png_decoder.h"

#include <png.h>

#include <csetjmp>
#include <cstring>
#include <vector>

namespace ihs::sensor {
namespace {

// What one decode reads and makes; libpng's callbacks reach it through their pointers, so its
// fields live in memory when libpng jumps back on an error.
struct PngRead {
  const std::string* bytes = nullptr;
  std::size_t at = 0;
  std::uint64_t max_pixels = 0;
  bool depth = false;
  std::string message;
  cv::Mat image;
  std::vector<png_bytep> rows;
};

void ReadData(png_structp png, png_bytep out, png_size_t count) {
  auto* read = static_cast<PngRead*>(png_get_io_ptr(png));
  if (read->bytes->size() - read->at < count) png_error(png, "the file ends inside the image");
  std::memcpy(out, read->bytes->data() + read->at, count);
  read->at += count;
}

[[noreturn]] void OnError(png_structp png, png_const_charp message) {
  static_cast<PngRead*>(png_get_error_ptr(png))->message = message;
  png_longjmp(png, 1);
}

// Warnings (an ancillary chunk's bad CRC, a known incorrect sRGB profile) change nothing in the
// samples used here.
void OnWarning(png_structp, png_const_charp) {}

// The libpng calls; an error comes back here by longjmp, so nothing in this frame may need a
// destructor: what the decode makes lives in `read`.
bool Decode(png_structp png, png_infop info, PngRead* read) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_read_fn(png, read, ReadData);
  png_read_info(png, info);
  const png_uint_32 width = png_get_image_width(png, info);
  const png_uint_32 height = png_get_image_height(png, info);
  if (static_cast<std::uint64_t>(width) * height > read->max_pixels) {
    png_error(png, "more pixels than a depth camera's frame can have");
  }
  const int color_type = png_get_color_type(png, info);
  const int bit_depth = png_get_bit_depth(png, info);
  const bool depth = read->depth && color_type == PNG_COLOR_TYPE_GRAY && bit_depth == 16;
  if (depth) {
    png_set_swap(png);  // PNG's samples are big-endian.
  } else {
    png_set_expand(png);  // Palette and low-bit grey to 8 bits, tRNS to alpha.
    png_set_strip_16(png);
    png_set_strip_alpha(png);
    png_set_gray_to_rgb(png);
    png_set_bgr(png);
  }
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  read->image.create(static_cast<int>(height), static_cast<int>(width), depth ? CV_16UC1 : CV_8UC3);
  if (png_get_rowbytes(png, info) != read->image.step[0]) png_error(png, "unexpected row size");
  read->rows.resize(height);
  for (png_uint_32 v = 0; v < height; ++v) read->rows[v] = read->image.ptr(static_cast<int>(v));
  png_read_image(png, read->rows.data());
  png_read_end(png, nullptr);
  return true;
}

}  // namespace

bool IsPng(const std::string& bytes) {
  return bytes.size() >= 8 &&
         png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8) == 0;
}

cv::Mat DecodePng(const std::string& bytes, bool depth, std::uint64_t max_pixels,
                  std::string* problem) {
  PngRead read;
  read.bytes = &bytes;
  read.max_pixels = max_pixels;
  read.depth = depth;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &read, OnError, OnWarning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  bool ok = info != nullptr;
  if (ok) ok = Decode(png, info, &read);
  png_destroy_read_struct(png ? &png : nullptr, info ? &info : nullptr, nullptr);
  if (!ok) {
    *problem = "damaged PNG (" + (read.message.empty() ? "out of memory" : read.message) + ")";
    return {};
  }
  return read.image;
}

}  // namespace ihs::sensor

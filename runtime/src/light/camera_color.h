// The camera's colour at a pixel on the host, from whichever form the frame came in: RGB8
// (InputFrame::color, or the runtime's upload words, 4 bytes a pixel: frame/camera_view.h) or Y'CbCr
// (InputFrame::color_yuv, decoded here with the formula and the
// chroma siting the GPU conversion uses: shared/mrgi_shared.h yuv_to_rgb8_packed,
// shaders/recon/yuv_to_rgb.comp). For the light stage's host readers, which sample the frame
// sparsely (every 8th pixel, the probeless grid's blocks): no full-frame conversion on the host.
#pragma once
#include <array>
#include <cstdint>

#include "frame/camera_view.h"
#include "mrgi/frame.h"
#include "shared/mrgi_shared.h"

namespace mrgi::light {

class CameraColor {
 public:
  explicit CameraColor(const frame::CameraView& view)
      : rgb_(view.rgb), yuv_(view.yuv), stride_(size_t(view.rgb_stride)), width_(view.has_color() ? view.color_width : 0),
        height_(view.has_color() ? view.color_height : 0) {}
  int width() const { return width_; }
  int height() const { return height_; }
  bool empty() const { return width_ <= 0 || height_ <= 0; }
  // sRGB 8-bit codes of pixel (x, y), inside the image.
  std::array<uint8_t, 3> at(int x, int y) const {
    if (!yuv_) {
      const uint8_t* p = rgb_ + (size_t(y) * size_t(width_) + size_t(x)) * stride_;
      return {p[0], p[1], p[2]};
    }
    const size_t w = size_t(yuv_->width), h = size_t(yuv_->height);
    const uint8_t* d = yuv_->data.data();
    uint32_t luma, cb, cr;
    if (yuv_->layout == YuvImage::Layout::Yuyv) {
      const uint8_t* pair = d + (size_t(y) * w + (size_t(x) & ~size_t(1))) * 2;
      luma = pair[(x & 1) ? 2 : 0];
      cb = pair[1];
      cr = pair[3];
    } else {
      luma = d[size_t(y) * w + size_t(x)];
      const uint8_t* c = d + w * h + size_t(y / 2) * w + (size_t(x) & ~size_t(1));
      cb = c[0];
      cr = c[1];
    }
    const uint32_t v = shader::yuv_to_rgb8_packed(float(luma), float(cb), float(cr),
                                                  yuv_->matrix == YuvImage::Matrix::Bt709 ? MRGI_YUV_BT709 : MRGI_YUV_BT601,
                                                  yuv_->range == YuvImage::Range::Full);
    return {uint8_t(v & 0xffu), uint8_t((v >> 8) & 0xffu), uint8_t((v >> 16) & 0xffu)};
  }

 private:
  const uint8_t* rgb_;
  const YuvImage* yuv_;
  size_t stride_;  // bytes a pixel of rgb_
  int width_, height_;
};

}  // namespace mrgi::light

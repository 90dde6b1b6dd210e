// Y'CbCr camera frames (InputFrame::color_yuv): converted on the GPU (shaders/recon/yuv_to_rgb.comp)
// within one 8-bit level of a CPU reference conversion written here from the standards' equations
// in double precision (ITU-R BT.601 / BT.709 luma coefficients, limited and full range), for NV12
// and YUYV; the shared formula (shared/mrgi_shared.h) against the same reference on every code;
// a composite from a Y'CbCr frame against the composite from the reference's RGB; and the bad
// frames refused by name.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "mrgi/platform/capture.h"
#include "mrgi/runtime.h"
#include "shared/mrgi_shared.h"

namespace mrgi::test {
namespace {

const std::string kSample = std::string(MRGI_SOURCE_DIR) + "/data/sample";

// The reference: Y'CbCr codes -> R'G'B' codes, double precision, rounded to nearest.
std::array<int, 3> reference_rgb(int y, int cb, int cr, YuvImage::Matrix m, YuvImage::Range r) {
  const double kr = m == YuvImage::Matrix::Bt709 ? 0.2126 : 0.299;
  const double kb = m == YuvImage::Matrix::Bt709 ? 0.0722 : 0.114;
  const double kg = 1.0 - kr - kb;
  const bool full = r == YuvImage::Range::Full;
  const double ey = full ? y / 255.0 : (y - 16) / 219.0;
  const double pb = (cb - 128) / (full ? 255.0 : 224.0), pr = (cr - 128) / (full ? 255.0 : 224.0);
  const double rgb[3] = {ey + 2.0 * (1.0 - kr) * pr, ey - (2.0 * kb * (1.0 - kb) * pb + 2.0 * kr * (1.0 - kr) * pr) / kg,
                         ey + 2.0 * (1.0 - kb) * pb};
  std::array<int, 3> out{};
  for (int c = 0; c < 3; ++c) out[size_t(c)] = int(std::lround(std::clamp(rgb[c], 0.0, 1.0) * 255.0));
  return out;
}

// R'G'B' codes -> Y'CbCr codes (the inverse equations, for making test frames).
std::array<int, 3> reference_yuv(const uint8_t* rgb, YuvImage::Matrix m, YuvImage::Range r) {
  const double kr = m == YuvImage::Matrix::Bt709 ? 0.2126 : 0.299;
  const double kb = m == YuvImage::Matrix::Bt709 ? 0.0722 : 0.114;
  const double R = rgb[0] / 255.0, G = rgb[1] / 255.0, B = rgb[2] / 255.0;
  const double ey = kr * R + (1.0 - kr - kb) * G + kb * B;
  const double pb = (B - ey) / (2.0 * (1.0 - kb)), pr = (R - ey) / (2.0 * (1.0 - kr));
  const bool full = r == YuvImage::Range::Full;
  auto code = [](double v) { return int(std::clamp(std::lround(v), 0l, 255l)); };
  return {code(full ? ey * 255.0 : 16.0 + 219.0 * ey), code(128.0 + (full ? 255.0 : 224.0) * pb),
          code(128.0 + (full ? 255.0 : 224.0) * pr)};
}

// `rgb` as a Y'CbCr frame (chroma of the pair / 2 x 2 block's first pixel, the siting the
// conversion reads back).
YuvImage encode(const ImageRGB8& rgb, YuvImage::Layout layout, YuvImage::Matrix m, YuvImage::Range r) {
  YuvImage y;
  y.layout = layout;
  y.matrix = m;
  y.range = r;
  y.width = rgb.width;
  y.height = rgb.height;
  y.data.assign(y.expected_bytes(), 0);
  const size_t w = size_t(rgb.width), h = size_t(rgb.height);
  for (size_t py = 0; py < h; ++py)
    for (size_t px = 0; px < w; ++px) {
      const auto c = reference_yuv(rgb.at(int(px), int(py)), m, r);
      if (layout == YuvImage::Layout::Yuyv) {
        uint8_t* pair = &y.data[(py * w + (px & ~size_t(1))) * 2];
        pair[(px & 1) ? 2 : 0] = uint8_t(c[0]);
        if ((px & 1) == 0) pair[1] = uint8_t(c[1]), pair[3] = uint8_t(c[2]);
      } else {
        y.data[py * w + px] = uint8_t(c[0]);
        if ((px & 1) == 0 && (py & 1) == 0) {
          uint8_t* uv = &y.data[w * h + (py / 2) * w + px];
          uv[0] = uint8_t(c[1]);
          uv[1] = uint8_t(c[2]);
        }
      }
    }
  return y;
}

// The reference conversion of a whole frame (the same siting as the GPU's).
ImageRGB8 decode_reference(const YuvImage& y) {
  ImageRGB8 out(y.width, y.height);
  const size_t w = size_t(y.width), h = size_t(y.height);
  for (size_t py = 0; py < h; ++py)
    for (size_t px = 0; px < w; ++px) {
      int luma, cb, cr;
      if (y.layout == YuvImage::Layout::Yuyv) {
        const uint8_t* pair = &y.data[(py * w + (px & ~size_t(1))) * 2];
        luma = pair[(px & 1) ? 2 : 0], cb = pair[1], cr = pair[3];
      } else {
        luma = y.data[py * w + px];
        const uint8_t* uv = &y.data[w * h + (py / 2) * w + (px & ~size_t(1))];
        cb = uv[0], cr = uv[1];
      }
      const auto c = reference_rgb(luma, cb, cr, y.matrix, y.range);
      for (int k = 0; k < 3; ++k) out.at(int(px), int(py))[k] = uint8_t(c[size_t(k)]);
    }
  return out;
}

TEST(YuvInput, TheSharedFormulaIsWithinOneLevelOfTheReferenceOnEveryCode) {
  for (auto m : {YuvImage::Matrix::Bt601, YuvImage::Matrix::Bt709})
    for (auto r : {YuvImage::Range::Limited, YuvImage::Range::Full})
      for (int y = 0; y < 256; y += 3)
        for (int cb = 0; cb < 256; cb += 5)
          for (int cr = 0; cr < 256; cr += 5) {
            const auto want = reference_rgb(y, cb, cr, m, r);
            const uint32_t got = shader::yuv_to_rgb8_packed(float(y), float(cb), float(cr),
                                                            m == YuvImage::Matrix::Bt709 ? MRGI_YUV_BT709 : MRGI_YUV_BT601,
                                                            r == YuvImage::Range::Full);
            for (int c = 0; c < 3; ++c)
              ASSERT_LE(std::abs(int((got >> (8 * c)) & 0xffu) - want[size_t(c)]), 1)
                  << "Y'CbCr " << y << " " << cb << " " << cr << " channel " << c;
          }
}

struct Player {
  std::unique_ptr<Runtime> runtime;
  std::vector<FrameOutput> outputs;
};

// A runtime on the sample's cameras; `objects` false: the scene without its virtual objects, so
// every output is the camera frame itself (the GPU's conversion, read back unchanged).
Player make_player(bool objects) {
  Player p;
  auto capture = CaptureReader::open(kSample);
  EXPECT_TRUE(capture.ok());
  if (!capture) return p;
  const CaptureInfo& info = capture->info();
  SceneDesc scene = *capture->scene();
  if (!objects) scene.virtual_objects.clear();
  RuntimeSettings s;
  s.device.validate = true;
  s.technique = "baseline";
  s.level = 1;
  s.exposure = info.exposure;
  auto rt = create_runtime(s, CameraSetup{info.color, info.depth, info.depth_scale, info.exposure, info.env_camera}, scene);
  EXPECT_TRUE(rt.ok()) << (rt.ok() ? "" : rt.error().message);
  if (rt) p.runtime = std::move(*rt);
  return p;
}

std::vector<FrameOutput> run_frames(Runtime& rt, std::vector<InputFrame> frames) {
  std::vector<FrameOutput> out;
  for (InputFrame& f : frames) {
    auto o = rt.process(f);
    EXPECT_TRUE(o.ok()) << (o.ok() ? "" : o.error().message);
    if (o) for (FrameOutput& x : *o) out.push_back(std::move(x));
  }
  auto rest = rt.flush();
  EXPECT_TRUE(rest.ok());
  if (rest) for (FrameOutput& x : *rest) out.push_back(std::move(x));
  return out;
}

InputFrame sample_frame(size_t i) {
  auto capture = CaptureReader::open(kSample);
  auto f = capture->read_frame(i);
  EXPECT_TRUE(f.ok());
  f->index = int64_t(i);
  return std::move(*f);
}

TEST(YuvInput, TheGpuConversionIsWithinOneLevelOfTheReferenceForEveryLayoutAndFormat) {
  Player p = make_player(false);
  ASSERT_TRUE(p.runtime);
  const InputFrame base = sample_frame(0);
  std::vector<InputFrame> frames;
  std::vector<ImageRGB8> want;
  int index = 0;
  for (auto layout : {YuvImage::Layout::Nv12, YuvImage::Layout::Yuyv})
    for (auto m : {YuvImage::Matrix::Bt601, YuvImage::Matrix::Bt709})
      for (auto r : {YuvImage::Range::Limited, YuvImage::Range::Full}) {
        InputFrame f = base;
        f.index = index++;
        f.color_yuv = encode(base.color, layout, m, r);
        f.color = ImageRGB8();  // only the Y'CbCr frame goes in
        want.push_back(decode_reference(*f.color_yuv));
        frames.push_back(std::move(f));
      }
  const std::vector<FrameOutput> outs = run_frames(*p.runtime, frames);
  ASSERT_EQ(outs.size(), want.size());
  for (size_t i = 0; i < outs.size(); ++i) {
    const ImageRGBA8& got = outs[i].image;
    ASSERT_EQ(got.width, want[i].width);
    int worst = 0;
    size_t off = 0;
    for (int y = 0; y < got.height; ++y)
      for (int x = 0; x < got.width; ++x)
        for (int c = 0; c < 3; ++c) {
          const int d = std::abs(int(got.at(x, y)[c]) - int(want[i].at(x, y)[c]));
          worst = std::max(worst, d);
          off += d > 0;
        }
    EXPECT_LE(worst, 1) << "frame " << i << " (layout/matrix/range combination " << i << ")";
    EXPECT_LT(double(off), 0.001 * 3.0 * got.width * got.height) << "frame " << i << ": values off by one";
  }
}

TEST(YuvInput, ACompositeFromAYuvFrameMatchesTheOneFromItsRgb) {
  Player from_yuv = make_player(true), from_rgb = make_player(true);
  ASSERT_TRUE(from_yuv.runtime && from_rgb.runtime);
  std::vector<InputFrame> yuv_frames, rgb_frames;
  for (size_t i = 0; i < 3; ++i) {
    InputFrame f = sample_frame(i);
    InputFrame g = f;
    f.color_yuv = encode(f.color, YuvImage::Layout::Nv12, YuvImage::Matrix::Bt709, YuvImage::Range::Limited);
    f.color = ImageRGB8();
    g.color = decode_reference(*f.color_yuv);
    yuv_frames.push_back(std::move(f));
    rgb_frames.push_back(std::move(g));
  }
  const auto a = run_frames(*from_yuv.runtime, yuv_frames);
  const auto b = run_frames(*from_rgb.runtime, rgb_frames);
  ASSERT_EQ(a.size(), 3u);
  ASSERT_EQ(b.size(), 3u);
  for (size_t i = 0; i < a.size(); ++i) {
    int worst = 0;
    for (size_t k = 0; k < a[i].image.data.size(); ++k)
      worst = std::max(worst, std::abs(int(a[i].image.data[k]) - int(b[i].image.data[k])));
    EXPECT_LE(worst, 2) << "frame " << i;
    EXPECT_TRUE(a[i].virtual_mask.data == b[i].virtual_mask.data) << "frame " << i;
  }
}

TEST(YuvInput, BadYuvFramesAreRefusedNamingTheFieldAndRule) {
  Player p = make_player(true);
  ASSERT_TRUE(p.runtime);
  const InputFrame base = sample_frame(0);
  auto refused = [&](const std::function<void(YuvImage&)>& spoil, const std::string& says) {
    InputFrame f = base;
    f.color_yuv = encode(base.color, YuvImage::Layout::Nv12, YuvImage::Matrix::Bt601, YuvImage::Range::Limited);
    spoil(*f.color_yuv);
    auto o = p.runtime->process(f);
    ASSERT_FALSE(o.ok()) << says;
    EXPECT_EQ(o.error().kind, ErrorKind::BadInput);
    EXPECT_NE(o.error().message.find("InputFrame::color_yuv"), std::string::npos) << o.error().message;
    EXPECT_NE(o.error().message.find(says), std::string::npos) << o.error().message;
  };
  refused([](YuvImage& y) { y.data.pop_back(); }, "bytes; NV12 at 640x480 is 460800");
  refused([](YuvImage& y) { y.width = 320; }, "colour intrinsics' size");
  refused([](YuvImage& y) { y.layout = YuvImage::Layout(7); }, "neither NV12 nor YUYV");
  refused([](YuvImage& y) { y.matrix = YuvImage::Matrix(3); }, "neither BT.601 nor BT.709");
  refused([](YuvImage& y) { y.range = YuvImage::Range(9); }, "neither limited nor full");
}

}  // namespace
}  // namespace mrgi::test

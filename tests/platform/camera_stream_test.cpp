// V4L2/libcamera without devices: format conversions on generated and real (JPEG) buffers, and
// the streaming state machine driven by a recorded-buffer backend (open -> configure -> stream
// -> timeout / unplug -> closed).
#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <fstream>

#include "common/camera_stream.h"
#include "mrgi/platform/devices.h"
#include "mrgi/runtime.h"
#include "test_support.h"

#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

namespace mrgi {
namespace {

ImageRGB8 test_pattern(int w, int h) {
  ImageRGB8 img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = img.at(x, y);
      // Smooth ramps (chroma subsampling keeps them) plus a few saturated primaries.
      p[0] = uint8_t(255 * x / (w - 1));
      p[1] = uint8_t(255 * y / (h - 1));
      p[2] = uint8_t(128 + 100 * std::sin(0.05 * (x + y)));
    }
  return img;
}

double max_abs_diff(const ImageRGB8& a, const ImageRGB8& b) {
  double m = 0;
  for (size_t i = 0; i < a.data.size(); ++i) m = std::max(m, std::abs(double(a.data[i]) - double(b.data[i])));
  return m;
}
double mean_abs_diff(const ImageRGB8& a, const ImageRGB8& b) {
  double s = 0;
  for (size_t i = 0; i < a.data.size(); ++i) s += std::abs(double(a.data[i]) - double(b.data[i]));
  return s / double(a.data.size());
}

std::vector<uint8_t> encode_jpeg(const ImageRGB8& img, int quality) {
  std::vector<uint8_t> out;
  stbi_write_jpg_to_func([](void* ctx, void* data, int size) {
    auto* v = static_cast<std::vector<uint8_t>*>(ctx);
    v->insert(v->end(), static_cast<uint8_t*>(data), static_cast<uint8_t*>(data) + size);
  }, &out, img.width, img.height, 3, img.data.data(), quality);
  return out;
}

// Removes every DHT segment, as UVC MJPEG cameras send frames.
std::vector<uint8_t> strip_dht(const std::vector<uint8_t>& j) {
  std::vector<uint8_t> out(j.begin(), j.begin() + 2);
  size_t at = 2;
  while (at + 4 <= j.size()) {
    const uint8_t m = j[at + 1];
    if (m == 0xDA) {
      out.insert(out.end(), j.begin() + long(at), j.end());
      break;
    }
    const size_t len = (size_t(j[at + 2]) << 8) | j[at + 3];
    if (m != 0xC4) out.insert(out.end(), j.begin() + long(at), j.begin() + long(at + 2 + len));
    at += 2 + len;
  }
  return out;
}

TEST(PixelConvert, RGB24AndBGR24AreExactWithStride) {
  const ImageRGB8 src = test_pattern(37, 11);
  const int stride = 37 * 3 + 5;
  std::vector<uint8_t> rgb(size_t(stride) * 11, 0xEE), bgr(size_t(stride) * 11, 0xEE);
  for (int y = 0; y < 11; ++y)
    for (int x = 0; x < 37; ++x)
      for (int c = 0; c < 3; ++c) {
        rgb[size_t(y) * stride + 3 * x + c] = src.at(x, y)[c];
        bgr[size_t(y) * stride + 3 * x + c] = src.at(x, y)[2 - c];
      }
  ImageRGB8 out;
  ASSERT_TRUE(convert_to_rgb8({PixelFormat::RGB24, 37, 11, stride, rgb.data(), rgb.size()}, out).ok());
  EXPECT_EQ(out.data, src.data);
  ASSERT_TRUE(convert_to_rgb8({PixelFormat::BGR24, 37, 11, stride, bgr.data(), bgr.size()}, out).ok());
  EXPECT_EQ(out.data, src.data);
}

TEST(PixelConvert, YUYVRoundTripWithinChromaSubsamplingError) {
  const ImageRGB8 src = test_pattern(64, 48);
  const auto yuyv = encode_yuyv(src);
  ImageRGB8 out;
  ASSERT_TRUE(convert_to_rgb8({PixelFormat::YUYV, 64, 48, 0, yuyv.data(), yuyv.size()}, out).ok());
  EXPECT_LT(mean_abs_diff(out, src), 2.0);
  EXPECT_LT(max_abs_diff(out, src), 8.0);
  // Known BT.601 values: Y=235 U=V=128 is white, Y=16 black, Y=81 U=90 V=240 pure red.
  const uint8_t px[] = {235, 128, 16, 128, 81, 90, 81, 240};
  ImageRGB8 two;
  ASSERT_TRUE(convert_to_rgb8({PixelFormat::YUYV, 2, 1, 0, px, 4}, two).ok());
  EXPECT_EQ(two.at(0, 0)[0], 255);
  EXPECT_EQ(two.at(0, 0)[1], 255);
  EXPECT_EQ(two.at(1, 0)[2], 0);
  ASSERT_TRUE(convert_to_rgb8({PixelFormat::YUYV, 2, 1, 0, px + 4, 4}, two).ok());
  EXPECT_NEAR(two.at(0, 0)[0], 255, 2);
  EXPECT_NEAR(two.at(0, 0)[1], 0, 2);
  EXPECT_NEAR(two.at(0, 0)[2], 0, 2);
}

TEST(PixelConvert, NV12RoundTrip) {
  const ImageRGB8 src = test_pattern(64, 48);
  const auto nv12 = encode_nv12(src);
  ImageRGB8 out;
  ASSERT_TRUE(convert_to_rgb8({PixelFormat::NV12, 64, 48, 0, nv12.data(), nv12.size()}, out).ok());
  EXPECT_LT(mean_abs_diff(out, src), 2.5);
}

TEST(PixelConvert, ShortBuffersAndOddSizesAreNamedErrors) {
  const ImageRGB8 src = test_pattern(64, 48);
  const auto yuyv = encode_yuyv(src);
  ImageRGB8 out;
  auto st = convert_to_rgb8({PixelFormat::YUYV, 64, 48, 0, yuyv.data(), yuyv.size() - 1}, out);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().kind, ErrorKind::BadInput);
  EXPECT_NE(st.error().message.find("YUYV 64x48"), std::string::npos) << st.error().message;
  EXPECT_NE(st.error().message.find("truncated"), std::string::npos);
  EXPECT_FALSE(convert_to_rgb8({PixelFormat::YUYV, 63, 48, 0, yuyv.data(), yuyv.size()}, out).ok());
  EXPECT_FALSE(convert_to_rgb8({PixelFormat::NV12, 64, 47, 0, yuyv.data(), yuyv.size()}, out).ok());
}

TEST(PixelConvert, MJPEGDecodesRealPhotoAndDHTLessFrames) {
  MRGI_SKIP_WITHOUT_SHARED(test::shared_data("apriltag/33369213973_9d9bb4cc96_c.jpg"));
  // A real JPEG photo (800x534, with its own Huffman tables).
  std::ifstream in(test::shared_data("apriltag/33369213973_9d9bb4cc96_c.jpg"), std::ios::binary);
  std::vector<uint8_t> photo((std::istreambuf_iterator<char>(in)), {});
  ASSERT_GT(photo.size(), 1000u);
  ImageRGB8 out;
  auto st = convert_to_rgb8({PixelFormat::MJPEG, 799, 533, 0, photo.data(), photo.size()}, out);
  ASSERT_TRUE(st.ok()) << st.error().message;
  EXPECT_EQ(out.width, 799);
  // The size in the JPEG must match the negotiated one.
  auto wrong = convert_to_rgb8({PixelFormat::MJPEG, 640, 480, 0, photo.data(), photo.size()}, out);
  ASSERT_FALSE(wrong.ok());
  EXPECT_NE(wrong.error().message.find("799x533"), std::string::npos) << wrong.error().message;
  // A truncated JPEG is a named error.
  auto cut = convert_to_rgb8({PixelFormat::MJPEG, 799, 533, 0, photo.data(), 600}, out);
  ASSERT_FALSE(cut.ok());
  EXPECT_NE(cut.error().message.find("corrupt JPEG"), std::string::npos) << cut.error().message;

  // MJPEG as UVC cameras send it: no DHT segment. stb_image_write uses the Annex K tables, so the
  // frame with the tables stripped must decode to exactly the same pixels once they are put back.
  const ImageRGB8 src = test_pattern(96, 64);
  const auto jpeg = encode_jpeg(src, 90);
  const auto bare = strip_dht(jpeg);
  ASSERT_LT(bare.size(), jpeg.size() - 400);
  ImageRGB8 a, b;
  ASSERT_TRUE(convert_to_rgb8({PixelFormat::MJPEG, 96, 64, 0, jpeg.data(), jpeg.size()}, a).ok());
  auto sb = convert_to_rgb8({PixelFormat::MJPEG, 96, 64, 0, bare.data(), bare.size()}, b);
  ASSERT_TRUE(sb.ok()) << sb.error().message;
  EXPECT_EQ(a.data, b.data);
  EXPECT_LT(mean_abs_diff(a, src), 3.0);
}

// Replays recorded buffers; scripted events stand in for a driver's timeouts and an unplug.
class RecordedBackend final : public CameraBackend {
 public:
  enum class Event { Frame, Timeout, Unplug };
  OfferedFormats offered;
  std::vector<std::vector<uint8_t>> buffers;
  std::deque<Event> script;
  bool absent = false, opened = false, started = false, closed = false;
  int releases = 0;
  FormatOption configured;

  std::string name() const override { return "recorded:test"; }
  Status open() override {
    if (absent) return fail(ErrorKind::NotFound, "recorded:test: no such device");
    opened = true;
    return ok_status();
  }
  Expected<OfferedFormats> formats() override { return offered; }
  Expected<FormatOption> configure(const FormatOption& wanted, const CameraSettings&) override {
    configured = wanted;
    return wanted;
  }
  Status start() override {
    started = true;
    return ok_status();
  }
  Expected<RawFrame> dequeue(std::chrono::milliseconds) override {
    if (script.empty()) return fail(ErrorKind::EndOfStream, "recorded:test: end of recording");
    const Event e = script.front();
    script.pop_front();
    if (e == Event::Timeout) return fail(ErrorKind::Timeout, "recorded:test: no frame");
    if (e == Event::Unplug) return fail(ErrorKind::Device, "recorded:test: device unplugged (ENODEV)");
    const auto& b = buffers[next_++ % buffers.size()];
    return RawFrame{configured.format, configured.width, configured.height, 0, b.data(), b.size(), 0.1 * next_, uint64_t(next_)};
  }
  Status release() override {
    ++releases;
    return ok_status();
  }
  void stop() override { started = false; }
  void close() override { closed = true; }

 private:
  size_t next_ = 0;
};

TEST(CameraStream, StateMachineStreamsTimesOutAndLosesTheDevice) {
  auto backend = std::make_unique<RecordedBackend>();
  RecordedBackend* rec = backend.get();
  const ImageRGB8 src = test_pattern(64, 48);
  rec->offered.supported = {{PixelFormat::MJPEG, 64, 48}, {PixelFormat::YUYV, 64, 48}, {PixelFormat::YUYV, 1280, 720}};
  rec->buffers = {encode_yuyv(src)};
  using E = RecordedBackend::Event;
  rec->script = {E::Frame, E::Timeout, E::Frame, E::Unplug, E::Frame};
  CameraSettings settings;
  settings.width = 64;
  settings.height = 48;
  auto opened = CameraStreamSource::open(std::move(backend), settings);
  ASSERT_TRUE(opened.ok()) << opened.error().message;
  CameraStreamSource& s = **opened;
  EXPECT_EQ(s.state(), CameraState::Streaming);
  EXPECT_EQ(s.format().format, PixelFormat::YUYV);  // uncompressed preferred at equal size
  EXPECT_EQ(s.format().width, 64);
  EXPECT_NE(s.name().find("uncalibrated"), std::string::npos);
  EXPECT_NEAR(s.info().color.fx, 32.0 / std::tan(M_PI / 6), 1e-9);

  auto f0 = s.next(std::chrono::milliseconds(10));
  ASSERT_TRUE(f0.ok()) << f0.error().message;
  EXPECT_EQ(f0->index, 0);
  EXPECT_LT(mean_abs_diff(f0->color, src), 2.0);
  EXPECT_EQ(f0->depth.width, 64);
  EXPECT_EQ(f0->depth.data, std::vector<uint16_t>(64 * 48, 0));  // colour-only: nothing measured
  auto t = s.next(std::chrono::milliseconds(10));
  ASSERT_FALSE(t.ok());
  EXPECT_EQ(t.error().kind, ErrorKind::Timeout);
  EXPECT_EQ(s.state(), CameraState::Streaming);
  auto f1 = s.next(std::chrono::milliseconds(10));
  ASSERT_TRUE(f1.ok());
  EXPECT_EQ(f1->index, 1);
  EXPECT_GT(f1->timestamp, f0->timestamp);
  auto u = s.next(std::chrono::milliseconds(10));
  ASSERT_FALSE(u.ok());
  EXPECT_EQ(u.error().kind, ErrorKind::Device);
  EXPECT_EQ(s.state(), CameraState::Lost);
  EXPECT_TRUE(rec->closed);
  EXPECT_FALSE(rec->started);
  auto after = s.next(std::chrono::milliseconds(10));  // stays lost, says why
  ASSERT_FALSE(after.ok());
  EXPECT_EQ(after.error().kind, ErrorKind::Device);
  EXPECT_NE(after.error().message.find("unplugged"), std::string::npos) << after.error().message;
  EXPECT_EQ(rec->releases, 2);
}

// CameraSettings::yuv_to_runtime: YUYV and NV12 buffers go on as the camera delivered them (the
// stride dropped), and the runtime's GPU conversion of them matches the host conversion of the
// same buffer (platform/src/common/pixel_convert.cpp) within its rounding.
TEST(CameraStream, YuvFramesGoToTheRuntimeAsDeliveredAndConvertThereAsOnTheHost) {
  const ImageRGB8 src = test_pattern(64, 48);
  for (const PixelFormat format : {PixelFormat::YUYV, PixelFormat::NV12}) {
    SCOPED_TRACE(to_string(format));
    auto backend = std::make_unique<RecordedBackend>();
    RecordedBackend* rec = backend.get();
    rec->offered.supported = {{format, 64, 48}};
    rec->buffers = {format == PixelFormat::YUYV ? encode_yuyv(src) : encode_nv12(src)};
    using E = RecordedBackend::Event;
    rec->script = {E::Frame};
    CameraSettings settings;
    settings.width = 64;
    settings.height = 48;
    settings.yuv_to_runtime = true;
    auto opened = CameraStreamSource::open(std::move(backend), settings);
    ASSERT_TRUE(opened.ok()) << opened.error().message;
    auto f = (*opened)->next(std::chrono::milliseconds(10));
    ASSERT_TRUE(f.ok()) << f.error().message;
    ASSERT_TRUE(f->color_yuv.has_value());
    EXPECT_TRUE(f->color.empty());
    EXPECT_EQ(f->color_yuv->layout, format == PixelFormat::YUYV ? YuvImage::Layout::Yuyv : YuvImage::Layout::Nv12);
    EXPECT_EQ(f->color_yuv->data, rec->buffers[0]);
    // Through a runtime with nothing virtual: its output is the converted camera frame.
    ImageRGB8 host;
    ASSERT_TRUE(convert_to_rgb8(RawFrame{format, 64, 48, 0, rec->buffers[0].data(), rec->buffers[0].size(), 0.0, 0}, host).ok());
    RuntimeSettings rs;
    rs.device.validate = true;
    CameraSetup cams{(*opened)->info().color, (*opened)->info().depth, 5000.0, 1.0, std::nullopt};
    auto rt = create_runtime(rs, cams, SceneDesc{});
    ASSERT_TRUE(rt.ok()) << rt.error().message;
    auto outs = (*rt)->process(*f);
    ASSERT_TRUE(outs.ok()) << outs.error().message;
    auto rest = (*rt)->flush();
    ASSERT_TRUE(rest.ok());
    const ImageRGBA8& gpu = (outs->empty() ? *rest : *outs).front().image;
    int worst = 0;
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 64; ++x)
        for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(int(gpu.at(x, y)[c]) - int(host.at(x, y)[c])));
    EXPECT_LE(worst, 1);
  }
}

TEST(CameraStream, EndOfRecordingClosesAndCorruptFrameIsSkippable) {
  auto backend = std::make_unique<RecordedBackend>();
  RecordedBackend* rec = backend.get();
  rec->offered.supported = {{PixelFormat::MJPEG, 96, 64}};
  const auto good = encode_jpeg(test_pattern(96, 64), 85);
  rec->buffers = {std::vector<uint8_t>(good.begin(), good.begin() + 300), good};
  using E = RecordedBackend::Event;
  rec->script = {E::Frame, E::Frame};
  auto opened = CameraStreamSource::open(std::move(backend), CameraSettings{});
  ASSERT_TRUE(opened.ok()) << opened.error().message;
  CameraStreamSource& s = **opened;
  auto bad = s.next(std::chrono::milliseconds(10));
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().kind, ErrorKind::BadInput);
  EXPECT_EQ(s.state(), CameraState::Streaming);  // one corrupt frame does not end the stream
  auto ok = s.next(std::chrono::milliseconds(10));
  ASSERT_TRUE(ok.ok()) << ok.error().message;
  auto end = s.next(std::chrono::milliseconds(10));
  ASSERT_FALSE(end.ok());
  EXPECT_EQ(end.error().kind, ErrorKind::EndOfStream);
  EXPECT_EQ(s.state(), CameraState::Closed);
  EXPECT_TRUE(rec->closed);
  EXPECT_EQ(rec->releases, 2);
}

TEST(CameraStream, UnsupportedFormatAndAbsentDeviceAreNamedErrors) {
  auto backend = std::make_unique<RecordedBackend>();
  backend->offered.unsupported = {"Z16 ", "GREY"};
  auto a = CameraStreamSource::open(std::move(backend), CameraSettings{});
  ASSERT_FALSE(a.ok());
  EXPECT_EQ(a.error().kind, ErrorKind::BadInput);
  EXPECT_NE(a.error().message.find("unsupported format"), std::string::npos);
  EXPECT_NE(a.error().message.find("GREY"), std::string::npos) << a.error().message;

  auto b2 = std::make_unique<RecordedBackend>();
  b2->offered.supported = {{PixelFormat::YUYV, 64, 48}};
  CameraSettings want_mjpeg;
  want_mjpeg.format = "MJPEG";
  auto b = CameraStreamSource::open(std::move(b2), want_mjpeg);
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.error().message.find("'MJPEG' is not offered"), std::string::npos) << b.error().message;

  auto b3 = std::make_unique<RecordedBackend>();
  b3->absent = true;
  auto c = CameraStreamSource::open(std::move(b3), CameraSettings{});
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.error().kind, ErrorKind::NotFound);
}

TEST(RealDevices, AbsentDevicesAreNotFoundAndListingsAreClean) {
  auto v = open_v4l2_source("/dev/video-mrgi-absent");
  ASSERT_FALSE(v.ok());
  EXPECT_EQ(v.error().kind, ErrorKind::NotFound);
  EXPECT_NE(v.error().message.find("v4l2:/dev/video-mrgi-absent"), std::string::npos);
  auto cams = list_libcamera_cameras();
  ASSERT_TRUE(cams.ok()) << cams.error().message;
  auto lc = open_libcamera_source("mrgi-absent-camera");
  ASSERT_FALSE(lc.ok());
  EXPECT_EQ(lc.error().kind, ErrorKind::NotFound) << lc.error().message;
  for (const auto& n : list_v4l2_nodes()) EXPECT_EQ(n.path.rfind("/dev/video", 0), 0u);
  auto bad = open_source("webcam:0", SourceOptions{});
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().kind, ErrorKind::BadUsage);
}

TEST(UsbDiscovery, KnownIdsAndScanWithoutBusAccess) {
  const KnownUsbSensor* kinect = match_usb_sensor(0x045e, 0x02ae);
  ASSERT_NE(kinect, nullptr);
  EXPECT_STREQ(kinect->adapter, "v4l2");
  const KnownUsbSensor* xtion = match_usb_sensor(0x1d27, 0x0601);
  ASSERT_NE(xtion, nullptr);
  EXPECT_STREQ(xtion->adapter, "openni");
  EXPECT_NE(match_usb_sensor(0x2bc5, 0x0401), nullptr);  // vendor-wide Orbbec entry
  EXPECT_NE(match_usb_sensor(0x8086, 0x0b07), nullptr);
  EXPECT_EQ(match_usb_sensor(0x8086, 0x1234), nullptr);  // other Intel devices are not sensors
  EXPECT_EQ(match_usb_sensor(0x045e, 0x0001), nullptr);
  const UsbScan scan = scan_usb();  // must not fail or hang without /dev/bus/usb
  EXPECT_FALSE(scan.status.empty());
  if (!scan.available) {
    EXPECT_TRUE(scan.devices.empty());
  }
}

// The tests build only with every adapter (CMakeLists.txt): the list says so, names each
// adapter's option and package, and `mrgi devices` prints it.
TEST(BuildAdapters, EveryAdapterIsInTheTestedBuildAndNamesItsOption) {
  const auto& adapters = build_adapters();
  ASSERT_EQ(adapters.size(), 5u);
  for (const BuildAdapter& a : adapters) {
    EXPECT_TRUE(a.built) << a.name;
    EXPECT_EQ(std::string(a.option).rfind("MRGI_WITH_", 0), 0u) << a.option;
    EXPECT_NE(std::string(a.package).find("-dev"), std::string::npos) << a.package;
  }
}

TEST(EnvCamera, FrameToRadianceDecodesSRGBAndExposure) {
  ImageRGB8 f(2, 1);
  f.data = {0, 128, 255, 255, 255, 255};
  ImageRGBF out;
  env_frame_to_radiance(f, 0.5, out);
  EXPECT_FLOAT_EQ(out.data[0], 0.0f);
  EXPECT_NEAR(out.data[1], 2.0 * 0.2158605, 1e-4);  // sRGB 128 -> 0.21586 linear
  EXPECT_NEAR(out.data[2], 2.0, 1e-6);
}

TEST(EnvCamera, SecondStreamIsPairedAsLinearRadiance) {
  using E = RecordedBackend::Event;
  auto main_backend = std::make_unique<RecordedBackend>();
  main_backend->offered.supported = {{PixelFormat::RGB24, 64, 48}};
  const ImageRGB8 main_img = test_pattern(64, 48);
  main_backend->buffers = {main_img.data};
  main_backend->script = {E::Frame, E::Frame, E::Frame};
  auto env_backend = std::make_unique<RecordedBackend>();
  env_backend->offered.supported = {{PixelFormat::RGB24, 32, 32}};
  env_backend->buffers = {std::vector<uint8_t>(32 * 32 * 3, 255), std::vector<uint8_t>(32 * 32 * 3, 128)};
  // Frame 1: env frame 0 (white). Frame 2: env times out, frame 0 reused. Frame 3: env frame 1.
  env_backend->script = {E::Frame, E::Timeout, E::Timeout, E::Frame, E::Timeout};
  CameraSettings main_settings, env_settings;
  env_settings.width = env_settings.height = 32;
  auto m = CameraStreamSource::open(std::move(main_backend), main_settings);
  auto e = CameraStreamSource::open(std::move(env_backend), env_settings);
  ASSERT_TRUE(m.ok() && e.ok());
  SourceOptions o;
  EnvCamera fisheye;
  fisheye.model = EnvModel::FisheyeEquidistant;
  fisheye.f = 10.0;
  fisheye.cx = fisheye.cy = 15.5;
  o.env_model = fisheye;
  o.env_exposure = 0.25;
  auto paired = pair_with_env_camera(std::move(m.value()), std::move(e.value()), o);
  ASSERT_TRUE(paired->info().env_camera.has_value());
  EXPECT_EQ(paired->info().env_camera->f, 10.0);
  auto f0 = paired->next(std::chrono::milliseconds(10));
  ASSERT_TRUE(f0.ok()) << f0.error().message;
  ASSERT_TRUE(f0->env.has_value());
  EXPECT_EQ(f0->env->width, 32);
  EXPECT_NEAR(f0->env->data[0], 4.0, 1e-5);  // white / exposure 0.25
  auto f1 = paired->next(std::chrono::milliseconds(10));
  ASSERT_TRUE(f1.ok());
  ASSERT_TRUE(f1->env.has_value());
  EXPECT_NEAR(f1->env->data[0], 4.0, 1e-5);  // reused
  auto f2 = paired->next(std::chrono::milliseconds(10));
  ASSERT_TRUE(f2.ok());
  EXPECT_NEAR(f2->env->data[0], 4.0 * 0.2158605, 1e-3);  // the newer frame (sRGB 128)
  EXPECT_EQ(f2->color.data, main_img.data);
}

}  // namespace
}  // namespace mrgi

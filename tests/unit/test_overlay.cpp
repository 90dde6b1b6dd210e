// The passthrough overlay (mrgi/overlay.h): blended over the camera frame it gives the composite,
// a shadow follows the passthrough it is blended over, added light is additive, bad sizes refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>

#include "image/srgb.h"
#include "mrgi/overlay.h"

namespace mrgi {
namespace {

struct Frames {
  ImageRGBA8 composite;
  ImageU8 mask;
  ImageRGB8 camera;
};

// A camera frame of random colours and a composite that changes it as a renderer would: shadows
// (every channel scaled down, some more in one channel), added light (bounce, caustics), colour
// shifts, pixels left as they were, virtual pixels of any colour, and saturated and black ones.
Frames random_frames(int w, int h, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> byte(0, 255), kind(0, 6);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Frames f{ImageRGBA8(w, h), ImageU8(w, h), ImageRGB8(w, h)};
  const auto& decode = srgb8_to_linear_table();
  for (size_t i = 0; i < size_t(w) * size_t(h); ++i) {
    uint8_t* c = &f.camera.data[3 * i];
    uint8_t* o = &f.composite.data[4 * i];
    for (int ch = 0; ch < 3; ++ch) c[ch] = uint8_t(byte(rng));
    if (i % 97 == 0) c[0] = c[1] = c[2] = 0;
    if (i % 89 == 0) c[1] = 255;
    const int k = kind(rng);
    const float shade = u(rng), tint = u(rng), add = 0.3f * u(rng);
    for (int ch = 0; ch < 3; ++ch) {
      float lin = decode[c[ch]];
      switch (k) {
        case 0:
          break;  // unchanged
        case 1:
          lin *= shade;
          break;  // grey shadow
        case 2:
          lin *= ch == 2 ? shade * tint : shade;
          break;  // coloured shadow
        case 3:
          lin += ch == 0 ? add : 0.3f * add;
          break;  // bounce light
        case 4:
          lin = lin * shade + (ch == 1 ? add : 0.0f);
          break;  // shadow and bleed
        case 5:
          lin = u(rng);
          break;  // anything
        default:
          lin = u(rng);
          f.mask.data[i] = 255;
          break;  // virtual
      }
      o[ch] = linear_to_srgb8(lin);
    }
    o[3] = f.mask.data[i];
  }
  return f;
}

TEST(Overlay, BlendedOverTheCameraFrameGivesTheCompositeWithinOneLevel) {
  const Frames f = random_frames(160, 120, 7);
  auto overlay = make_overlay(f.composite, f.mask, f.camera);
  ASSERT_TRUE(overlay.ok()) << overlay.error().message;
  auto shown = blend_overlay(*overlay, f.camera);
  ASSERT_TRUE(shown.ok()) << shown.error().message;
  int worst = 0;
  size_t off_by_one = 0;
  for (size_t i = 0; i < f.camera.data.size() / 3; ++i)
    for (int ch = 0; ch < 3; ++ch) {
      const int d = std::abs(int(shown->data[3 * i + size_t(ch)]) - int(f.composite.data[4 * i + size_t(ch)]));
      worst = std::max(worst, d);
      off_by_one += d > 0;
    }
  EXPECT_LE(worst, 1);
  EXPECT_LT(off_by_one, f.camera.data.size() / 10) << "most channels exact";
  // Unchanged real pixels are fully transparent; virtual ones opaque.
  for (size_t i = 0; i < f.mask.data.size(); ++i) {
    const uint8_t* o = &f.composite.data[4 * i];
    const uint8_t* c = &f.camera.data[3 * i];
    if (f.mask.data[i]) {
      EXPECT_EQ(overlay->data[4 * i + 3], 255);
    } else if (o[0] == c[0] && o[1] == c[1] && o[2] == c[2]) {
      EXPECT_EQ(overlay->data[4 * i + 3], 0);
      EXPECT_EQ(overlay->data[4 * i], 0);
    }
  }
}

TEST(Overlay, AShadowDarkensAnyPassthroughByTheSameFactor) {
  // A grey shadow keeping 40 % of the light, made on one camera frame, blended over another:
  // the other frame is darkened to 40 % (the additive part is empty), which is what a
  // passthrough compositor needs when its video differs from mrgi's camera.
  const auto& decode = srgb8_to_linear_table();
  ImageRGB8 camera(4, 1), other(4, 1);
  ImageRGBA8 composite(4, 1);
  ImageU8 mask(4, 1);
  const uint8_t cam[4] = {200, 120, 60, 250}, oth[4] = {90, 240, 30, 180};
  for (int x = 0; x < 4; ++x) {
    for (int ch = 0; ch < 3; ++ch) {
      camera.data[3 * size_t(x) + size_t(ch)] = cam[x];
      other.data[3 * size_t(x) + size_t(ch)] = oth[x];
      composite.data[4 * size_t(x) + size_t(ch)] = linear_to_srgb8(0.4f * decode[cam[x]]);
    }
  }
  auto overlay = make_overlay(composite, mask, camera);
  ASSERT_TRUE(overlay.ok());
  auto shown = blend_overlay(*overlay, other);
  ASSERT_TRUE(shown.ok());
  for (int x = 0; x < 4; ++x) {
    EXPECT_NEAR(overlay->data[4 * size_t(x) + 3], 153, 2) << "alpha = 1 - 0.4";
    for (int ch = 0; ch < 3; ++ch) {
      EXPECT_LE(overlay->data[4 * size_t(x) + size_t(ch)], 12) << "next to nothing added back";
      EXPECT_NEAR(decode[shown->data[3 * size_t(x) + size_t(ch)]], 0.4f * decode[oth[x]], 0.01f) << x;
    }
  }
}

TEST(Overlay, AddedLightIsAdditiveAndTransparent) {
  const auto& decode = srgb8_to_linear_table();
  ImageRGB8 camera(1, 1);
  ImageRGBA8 composite(1, 1);
  ImageU8 mask(1, 1);
  const uint8_t c[3] = {100, 110, 120};
  const float add[3] = {0.12f, 0.05f, 0.0f};
  for (int ch = 0; ch < 3; ++ch) {
    camera.data[size_t(ch)] = c[ch];
    composite.data[size_t(ch)] = linear_to_srgb8(decode[c[ch]] + add[ch]);
  }
  auto overlay = make_overlay(composite, mask, camera);
  ASSERT_TRUE(overlay.ok());
  EXPECT_EQ(overlay->data[3], 0) << "brightening darkens nothing";
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(decode[overlay->data[size_t(ch)]], add[ch], 0.004f) << ch;
}

TEST(Overlay, ImagesOfAnotherSizeAreRefusedByName) {
  const Frames f = random_frames(8, 6, 1);
  auto bad_mask = make_overlay(f.composite, ImageU8(8, 5), f.camera);
  ASSERT_FALSE(bad_mask.ok());
  EXPECT_EQ(bad_mask.error().kind, ErrorKind::BadUsage);
  EXPECT_NE(bad_mask.error().message.find("the virtual mask is 8x5"), std::string::npos) << bad_mask.error().message;
  auto bad_camera = make_overlay(f.composite, f.mask, ImageRGB8(7, 6));
  ASSERT_FALSE(bad_camera.ok());
  EXPECT_NE(bad_camera.error().message.find("the camera frame is 7x6"), std::string::npos)
      << bad_camera.error().message;
  auto bad_blend = blend_overlay(ImageRGBA8(8, 6), ImageRGB8(8, 7));
  ASSERT_FALSE(bad_blend.ok());
  EXPECT_NE(bad_blend.error().message.find("the passthrough frame is 8x7"), std::string::npos)
      << bad_blend.error().message;
}

}  // namespace
}  // namespace mrgi

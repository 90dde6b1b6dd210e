// Builds small capture folders inside a test's temp dir, line by line, so each refusal test
// breaks exactly one rule of capture format v1.
#pragma once
#include <string>
#include <vector>

#include "capture/temp_dir.h"
#include "mrgi/image.h"

namespace mrgi::testing {

inline constexpr int kW = 8, kH = 6;  // intrinsics written to capture.json by default

inline ImageRGB8 test_color(int w, int h, int seed) {
  ImageRGB8 img(w, h);
  for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = uint8_t((i * 7 + size_t(seed) * 31) % 256);
  return img;
}
inline ImageU16 test_depth(int w, int h, int seed) {
  ImageU16 img(w, h);
  for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = uint16_t(1000 + i * 97 + size_t(seed) * 13);
  return img;
}

inline std::string capture_json(int w, int h) {
  return R"({"version": 1, "color": {"width": )" + std::to_string(w) + R"(, "height": )" +
         std::to_string(h) + R"(, "fx": 10, "fy": 10, "cx": 4, "cy": 3}})";
}

// A folder with N frames at timestamps 1.0, 1.1, ...: rgb/i.png, depth/i.png, lists and a
// capture.json for kW x kH images. Tests then overwrite the piece they want broken.
struct CaptureFixture {
  TempDir dir;
  int frames;
  explicit CaptureFixture(int n = 3) : frames(n) {
    std::string rgb = "# colour\n", depth = "# depth\n";
    for (int i = 0; i < n; ++i) {
      const std::string name = std::to_string(i) + ".png";
      EXPECT_TRUE(write_png(file("rgb/" + name), test_color(kW, kH, i)).ok());
      EXPECT_TRUE(write_png(file("depth/" + name), test_depth(kW, kH, i)).ok());
      rgb += time(i) + " rgb/" + name + "\n";
      depth += time(i) + " depth/" + name + "\n";
    }
    write_text(file("rgb.txt"), rgb);
    write_text(file("depth.txt"), depth);
    write_text(file("capture.json"), capture_json(kW, kH));
  }
  static std::string time(int i) { return std::to_string(1.0 + 0.1 * i); }
  std::string file(const std::string& rel) const {
    const std::string p = dir.file(rel);
    std::filesystem::create_directories(std::filesystem::path(p).parent_path());
    return p;
  }
  std::string folder() const { return dir.str(); }
};

}  // namespace mrgi::testing

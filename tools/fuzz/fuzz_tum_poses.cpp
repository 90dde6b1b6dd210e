// Fuzz target: groundtruth.txt (TUM poses) read in context: a one-frame capture folder made once
// per process, whose groundtruth.txt is replaced by each input before CaptureReader::open and
// read_frame (the pose interpolation at the colour timestamp).
#include <cmath>

#include "fuzz_input.h"
#include "mrgi/image.h"
#include "mrgi/platform/capture.h"

namespace {

const std::string& capture_folder() {
  static const std::string folder = [] {
    const auto& dir = mrgi::fuzz::InputFolder::get().path();
    std::filesystem::create_directories(dir / "rgb");
    std::filesystem::create_directories(dir / "depth");
    mrgi::ImageRGB8 rgb(8, 6);
    mrgi::ImageU16 depth(8, 6);
    for (auto& v : depth.data) v = 5000;
    (void)mrgi::write_png((dir / "rgb/0.png").string(), rgb);
    (void)mrgi::write_png((dir / "depth/0.png").string(), depth);
    std::ofstream(dir / "rgb.txt") << "1.0 rgb/0.png\n";
    std::ofstream(dir / "depth.txt") << "1.0 depth/0.png\n";
    std::ofstream(dir / "capture.json")
        << R"({"version": 1, "color": {"width": 8, "height": 6, "fx": 8, "fy": 8, "cx": 4, "cy": 3},
              "depth": {"width": 8, "height": 6, "fx": 8, "fy": 8, "cx": 4, "cy": 3},
              "depth_scale": 5000, "exposure": 1})";
    return dir.string();
  }();
  return folder;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& folder = capture_folder();
  mrgi::fuzz::InputFolder::get().write("groundtruth.txt", data, size);
  auto reader = mrgi::CaptureReader::open(folder);
  if (!reader.ok()) return 0;
  auto frame = reader->read_frame(0);
  if (frame.ok() && frame->pose) {
    const glm::dmat4 m = frame->pose->matrix();
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        if (!std::isfinite(m[c][r])) std::abort();  // a pose is never NaN
  }
  return 0;
}

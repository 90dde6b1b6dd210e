// Frames from memory through mrgi, the composited image back: what an app with its own camera
// does. The frames here are made up on the spot (a grey floor a metre below a camera looking
// straight down, lit by a lamp beside it); a virtual object from a glTF file stands on it.
//
//   frames_from_memory OBJECT.gltf [OUT.ppm]
//
// Prints the version, the device, each frame's output and how many pixels the object changed;
// writes the last composited frame as a PPM when asked. Exit 0 when the object changed pixels.
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include <mrgi/runtime.h>
#include <mrgi/version.h>

namespace {

// One frame of a camera 1 m above a floor, looking down (+z of the camera is -y of the world).
mrgi::InputFrame make_frame(int64_t index, const mrgi::Intrinsics& k, double depth_scale) {
  mrgi::InputFrame f;
  f.index = index;
  f.timestamp = double(index) / 30.0;
  f.depth_timestamp = f.timestamp;
  f.color = mrgi::ImageRGB8(k.width, k.height);
  f.depth = mrgi::ImageU16(k.width, k.height);
  for (int y = 0; y < k.height; ++y)
    for (int x = 0; x < k.width; ++x) {
      f.depth.at(x, y)[0] = uint16_t(1.0 * depth_scale);  // the floor, 1 m along the view axis
      for (int c = 0; c < 3; ++c) f.color.at(x, y)[c] = 150;
    }
  // Camera-to-world: at (0, 1, 0), its +z (view) along world -y, its +y (image down) along +z.
  mrgi::Pose pose;
  pose.translation = {0.0, 1.0, 0.0};
  pose.rotation = glm::dquat(glm::dmat3(glm::dvec3(1, 0, 0), glm::dvec3(0, 0, 1), glm::dvec3(0, -1, 0)));
  f.pose = pose;
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help") {
    std::fprintf(stderr, "usage: %s OBJECT.gltf [OUT.ppm]\n", argv[0]);
    return 2;
  }
  std::printf("mrgi %s\n", mrgi::version());

  mrgi::SceneDesc scene;
  mrgi::VirtualObjectDesc object;
  object.gltf = argv[1];
  object.placement.scale = glm::vec3(1.5f);
  object.placement.rotation = glm::quat(0.70710678f, 0.70710678f, 0.0f, 0.0f);  // w, x, y, z
  scene.virtual_objects.push_back(object);
  mrgi::LightDesc lamp;  // a real lamp: its light is in the camera image
  lamp.position = {0.4f, 1.2f, 0.3f};
  lamp.intensity = 1.0f;
  scene.lights.push_back(lamp);

  mrgi::CameraSetup cameras;
  cameras.color = cameras.depth = mrgi::Intrinsics{320, 240, 260.0, 260.0, 159.5, 119.5};
  mrgi::RuntimeSettings settings;
  settings.technique = "baseline";
  auto levels = mrgi::technique_levels(settings.technique);
  if (!levels) {
    std::fprintf(stderr, "error: %s\n", levels.error().message.c_str());
    return 1;
  }
  settings.level = int(levels->size()) - 1;  // the cheapest level
  auto runtime = mrgi::create_runtime(settings, cameras, scene);
  if (!runtime) {
    std::fprintf(stderr, "error: %s\n", runtime.error().message.c_str());
    return 1;
  }
  std::printf("device: %s; level %s\n", (*runtime)->device().name.c_str(), levels->back().c_str());

  int changed = 0;
  mrgi::FrameOutput last;
  auto take = [&](std::vector<mrgi::FrameOutput>& outs) {
    for (mrgi::FrameOutput& out : outs) {
      changed = 0;
      for (int y = 0; y < out.image.height; ++y)
        for (int x = 0; x < out.image.width; ++x) changed += out.virtual_mask.at(x, y)[0] != 0;
      std::printf("frame %lld: %dx%d, %d pixels of the object\n", static_cast<long long>(out.stats.frame_index),
                  out.image.width, out.image.height, changed);
      last = std::move(out);
    }
  };
  for (int64_t i = 0; i < 4; ++i) {
    auto outs = (*runtime)->process(make_frame(i, cameras.color, cameras.depth_scale));
    if (!outs) {
      std::fprintf(stderr, "error: frame %lld: %s\n", static_cast<long long>(i), outs.error().message.c_str());
      return 1;
    }
    take(*outs);
  }
  auto rest = (*runtime)->flush();
  if (!rest) {
    std::fprintf(stderr, "error: %s\n", rest.error().message.c_str());
    return 1;
  }
  take(*rest);
  if (argc > 2) {
    std::ofstream ppm(argv[2], std::ios::binary);
    ppm << "P6\n" << last.image.width << " " << last.image.height << "\n255\n";
    for (int y = 0; y < last.image.height; ++y)
      for (int x = 0; x < last.image.width; ++x) ppm.write(reinterpret_cast<const char*>(last.image.at(x, y)), 3);
    if (!ppm) {
      std::fprintf(stderr, "error: %s: could not write\n", argv[2]);
      return 1;
    }
  }
  return changed > 0 ? 0 : 1;
}

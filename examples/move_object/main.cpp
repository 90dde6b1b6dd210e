// An app's object moving: every frame the app places its virtual object somewhere new
// (Runtime::set_object_placement; nothing is allocated, the scene's objects are fixed at
// start-up) and the runtime draws, lights and shadows it there. The frames are made up as in
// frames_from_memory (a floor a metre below a camera looking down, a lamp beside it); the object
// slides across the view. Prints where the object's pixels are each frame.
//
//   move_object OBJECT.gltf
//
// Exit 0 when the object's pixels moved the way it did (rightwards in the image).
#include <cstdio>
#include <cstdlib>
#include <vector>
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
  if (argc != 2 || std::string(argv[1]) == "--help") {
    std::fprintf(stderr, "usage: %s OBJECT.gltf\n", argv[0]);
    return 2;
  }
  mrgi::SceneDesc scene;
  mrgi::VirtualObjectDesc object;
  object.gltf = argv[1];
  object.placement.scale = glm::vec3(1.5f);
  object.placement.rotation = glm::quat(0.70710678f, 0.70710678f, 0.0f, 0.0f);  // w, x, y, z
  scene.virtual_objects.push_back(object);
  mrgi::LightDesc lamp;
  lamp.position = {0.4f, 1.2f, 0.3f};
  scene.lights.push_back(lamp);
  mrgi::CameraSetup cameras;
  cameras.color = cameras.depth = mrgi::Intrinsics{320, 240, 260.0, 260.0, 159.5, 119.5};
  mrgi::RuntimeSettings settings;
  settings.level = int(mrgi::technique_levels(settings.technique)->size()) - 1;
  auto runtime = mrgi::create_runtime(settings, cameras, scene);
  if (!runtime) {
    std::fprintf(stderr, "error: %s\n", runtime.error().message.c_str());
    return 1;
  }
  std::vector<double> centres;
  auto take = [&](std::vector<mrgi::FrameOutput>& outs) {
    for (mrgi::FrameOutput& out : outs) {
      double sum = 0.0;
      int n = 0;
      for (int y = 0; y < out.image.height; ++y)
        for (int x = 0; x < out.image.width; ++x)
          if (out.virtual_mask.at(x, y)[0] != 0) sum += x, ++n;
      const double centre = n > 0 ? sum / n : -1.0;
      std::printf("frame %lld: %d pixels of the object, centred at x = %.1f\n",
                  static_cast<long long>(out.stats.frame_index), n, centre);
      centres.push_back(centre);
      (*runtime)->recycle(std::move(out));  // a live loop hands its frames back
    }
  };
  constexpr int kFrames = 6;
  for (int64_t i = 0; i < kFrames; ++i) {
    // Slides 5 cm a frame along world +x (image right: the camera's x is world x here).
    mrgi::Placement p = object.placement;
    p.position.x = -0.12f + 0.05f * float(i);
    if (auto s = (*runtime)->set_object_placement(0, p); !s) {
      std::fprintf(stderr, "error: %s\n", s.error().message.c_str());
      return 1;
    }
    auto outs = (*runtime)->process(make_frame(i, cameras.color, cameras.depth_scale));
    if (!outs) {
      std::fprintf(stderr, "error: %s\n", outs.error().message.c_str());
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
  bool rightwards = centres.size() == size_t(kFrames);
  for (size_t i = 1; i < centres.size(); ++i) rightwards = rightwards && centres[i - 1] >= 0.0 && centres[i] > centres[i - 1];
  return rightwards ? 0 : 1;
}

// An app placing an object while the camera runs: a recorded capture plays in a loop (forwards
// and back through its frames, as a live camera never stops), and after 10 frames the user
// places a new object beside the scene's first one (Runtime::add_object, within the room stated
// at creation: RuntimeSettings::objects); 10 frames later it is taken away again
// (Runtime::remove_object). Nothing is allocated for the frames on the way. Prints the object
// pixels of every frame.
//
//   place_object CAPTURE_DIR OBJECT.gltf [FRAMES]
//
// Exit 0 when the frames with the new object show more object pixels than the frames before
// and after it.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <mrgi/platform/capture.h>
#include <mrgi/runtime.h>

namespace {

int fail(const std::string& message) {
  std::fprintf(stderr, "error: %s\n", message.c_str());
  return 1;
}

// Frame i of a loop through `count` frames: 0, 1, ..., count - 1, count - 2, ..., 1, 0, 1, ...
size_t looped(int i, size_t count) {
  if (count < 2) return 0;
  const size_t period = 2 * (count - 1), k = size_t(i) % period;
  return k < count ? k : period - k;
}

int object_pixels(const mrgi::FrameOutput& out) {
  int n = 0;
  for (uint8_t m : out.virtual_mask.data) n += m != 0;
  return n;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3 || std::string(argv[1]) == "--help") {
    std::fprintf(stderr, "usage: %s CAPTURE_DIR OBJECT.gltf [FRAMES]\n", argv[0]);
    return 2;
  }
  const int frames = argc > 3 ? std::atoi(argv[3]) : 30;
  constexpr int kPlaceAt = 10, kRemoveAt = 20;
  if (frames <= kRemoveAt) return fail("FRAMES must be more than " + std::to_string(kRemoveAt));
  auto capture = mrgi::CaptureReader::open(argv[1]);
  if (!capture) return fail(capture.error().message);
  const mrgi::CaptureInfo& info = capture->info();
  const mrgi::SceneDesc& scene = *capture->scene();
  if (scene.virtual_objects.empty()) return fail(std::string(argv[1]) + ": the scene has no object to place beside");

  // Room for the user's object, stated now and allocated at start-up: one object of up to 8
  // meshes, 100k triangles and vertices, 4 textures.
  mrgi::RuntimeSettings settings;
  settings.exposure = info.exposure;
  settings.level = int(mrgi::technique_levels(settings.technique)->size()) - 1;
  settings.objects.objects = 1;
  settings.objects.meshes = 8;
  settings.objects.triangles = 100000;
  settings.objects.vertices = 100000;
  settings.objects.textures = 4;
  auto runtime = mrgi::create_runtime(
      settings, mrgi::CameraSetup{info.color, info.depth, info.depth_scale, info.exposure, info.env_camera}, scene);
  if (!runtime) return fail(runtime.error().message);
  mrgi::Runtime& r = **runtime;

  // Beside the scene's first object: as large, one of its widths along world x.
  const mrgi::Placement& first = scene.virtual_objects[0].placement;
  auto first_model = mrgi::load_gltf(scene.virtual_objects[0].gltf, first);
  if (!first_model) return fail(first_model.error().message);
  mrgi::Placement place = first;
  place.position.x += first_model->bounds_max.x - first_model->bounds_min.x;

  std::vector<int> pixels;
  auto take = [&](std::vector<mrgi::FrameOutput>& outs) {
    for (mrgi::FrameOutput& out : outs) {
      pixels.push_back(object_pixels(out));
      std::printf("frame %lld: %d object pixels\n", static_cast<long long>(out.stats.frame_index), pixels.back());
      r.recycle(std::move(out));
    }
  };
  size_t placed = 0;
  for (int i = 0; i < frames; ++i) {
    if (i == kPlaceAt) {
      auto slot = r.add_object(argv[2], place);
      if (!slot) return fail(slot.error().message);
      placed = *slot;
      std::printf("placed %s in slot %zu\n", argv[2], placed);
    }
    if (i == kRemoveAt) {
      if (auto s = r.remove_object(placed); !s) return fail(s.error().message);
      std::printf("removed slot %zu\n", placed);
    }
    auto frame = capture->read_frame(looped(i, capture->frame_count()));
    if (!frame) return fail(frame.error().message);
    frame->index = i;
    frame->timestamp = double(i) / 30.0;
    frame->depth_timestamp = frame->timestamp;
    auto outs = r.process(*frame);
    if (!outs) return fail(outs.error().message);
    take(*outs);
  }
  auto rest = r.flush();
  if (!rest) return fail(rest.error().message);
  take(*rest);
  if (pixels.size() != size_t(frames)) return fail("not every frame came back");
  // The placed object adds pixels: every frame with it shows more than the most of the frames
  // without it.
  int most_without = 0, least_with = 1 << 30;
  for (int i = 0; i < frames; ++i) {
    if (i >= kPlaceAt && i < kRemoveAt) least_with = std::min(least_with, pixels[size_t(i)]);
    else most_without = std::max(most_without, pixels[size_t(i)]);
  }
  std::printf("object pixels: at most %d without the placed object, at least %d with it\n", most_without, least_with);
  return least_with > most_without ? 0 : 1;
}

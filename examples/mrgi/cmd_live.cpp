// mrgi live SOURCE --technique NAME [--scene FILE] [--out DIR] [--frames N]
// Runs a live source (openni:, openni:FILE.oni, v4l2:/dev/videoN, libcamera:ID, or a capture
// folder) through the runtime and writes what `mrgi replay` writes (frames/, stats.json,
// summary.json, side_by_side.png) to --out, through the same ReplayOutput.
//
// Without --scene, a default virtual object is placed in front of the camera: a 15 cm box,
// generated here as a .glb (in a temp folder, removed at exit), at 80% of the nearest measured
// depth (10th percentile) of the first frame's central quarter, at most 1.2 m (1 m when there is
// no depth), lit by one real directional light from above and behind the camera. Camera poses: the source's own (capture groundtruth), else
// AprilTag tracking when the source's info has AprilTag settings, else a fixed pose (camera at
// the world origin looking along world -z with world +y up) -- without tracking it stays fixed.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "live_view.h"
#include "mrgi/platform/apriltag.h"
#include "mrgi/platform/devices.h"
#include "mrgi/runtime.h"
#include "replay_output.h"
#include "stage_thread.h"

namespace mrgi::tool {
namespace {

std::atomic<bool> g_stop{false};
void on_sigint(int) { g_stop = true; }

struct LiveOptions {
  std::string source, scene, out, device, env, env_model;
  ViewOptions view;
  QualityOptions quality;
  OutputImagesOption output_images;
  int frames = 0, timeout_ms = 3000;
  bool quiet = false;
};

// A unit-centred box of edge `edge` metres as a binary glTF (positions, normals, indices; one
// grey-blue diffuse material).
Status write_box_glb(const std::string& path, float edge) {
  std::vector<float> pos, nrm;
  std::vector<uint16_t> idx;
  const float h = 0.5f * edge;
  const int axes[6][3] = {{0, 1, 2}, {0, 1, 2}, {1, 2, 0}, {1, 2, 0}, {2, 0, 1}, {2, 0, 1}};
  for (int f = 0; f < 6; ++f) {
    const float sign = (f % 2) ? -1.0f : 1.0f;
    const int n = axes[f][2], u = axes[f][0], v = axes[f][1];
    const float uv[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    const uint16_t base = uint16_t(pos.size() / 3);
    for (auto& c : uv) {
      float p[3], q[3] = {0, 0, 0};
      p[n] = sign * h;
      p[u] = c[0] * h;
      p[v] = c[1] * h * sign;  // flip winding on the negative face so triangles face outwards
      q[n] = sign;
      pos.insert(pos.end(), p, p + 3);
      nrm.insert(nrm.end(), q, q + 3);
    }
    for (uint16_t k : {0, 1, 2, 0, 2, 3}) idx.push_back(uint16_t(base + k));
  }
  std::vector<uint8_t> bin(pos.size() * 4 + nrm.size() * 4 + idx.size() * 2);
  std::memcpy(bin.data(), pos.data(), pos.size() * 4);
  std::memcpy(bin.data() + pos.size() * 4, nrm.data(), nrm.size() * 4);
  std::memcpy(bin.data() + pos.size() * 8, idx.data(), idx.size() * 2);
  while (bin.size() % 4) bin.push_back(0);
  using nlohmann::json;
  const size_t vbytes = pos.size() * 4;
  json j = {
      {"asset", {{"version", "2.0"}, {"generator", "mrgi live (default object)"}}},
      {"scene", 0},
      {"scenes", json::array({{{"nodes", json::array({0})}}})},
      {"nodes", json::array({{{"mesh", 0}}})},
      {"meshes", json::array({{{"primitives", json::array({{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}}},
                                                            {"indices", 2}, {"material", 0}}})}}})},
      {"materials", json::array({{{"pbrMetallicRoughness", {{"baseColorFactor", {0.55, 0.6, 0.8, 1.0}},
                                                              {"metallicFactor", 0.0}, {"roughnessFactor", 0.8}}}}})},
      {"buffers", json::array({{{"byteLength", bin.size()}}})},
      {"bufferViews", json::array({{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", vbytes}, {"target", 34962}},
                                   {{"buffer", 0}, {"byteOffset", vbytes}, {"byteLength", vbytes}, {"target", 34962}},
                                   {{"buffer", 0}, {"byteOffset", 2 * vbytes}, {"byteLength", idx.size() * 2}, {"target", 34963}}})},
      {"accessors", json::array({{{"bufferView", 0}, {"componentType", 5126}, {"count", pos.size() / 3}, {"type", "VEC3"},
                                  {"min", {-h, -h, -h}}, {"max", {h, h, h}}},
                                 {{"bufferView", 1}, {"componentType", 5126}, {"count", nrm.size() / 3}, {"type", "VEC3"}},
                                 {{"bufferView", 2}, {"componentType", 5123}, {"count", idx.size()}, {"type", "SCALAR"}}})},
  };
  std::string text = j.dump();
  while (text.size() % 4) text.push_back(' ');
  std::ofstream out(path, std::ios::binary);
  auto u32 = [&](uint32_t v) { out.write(reinterpret_cast<const char*>(&v), 4); };
  u32(0x46546C67);  // "glTF"
  u32(2);
  u32(uint32_t(12 + 8 + text.size() + 8 + bin.size()));
  u32(uint32_t(text.size()));
  u32(0x4E4F534A);  // "JSON"
  out.write(text.data(), std::streamsize(text.size()));
  u32(uint32_t(bin.size()));
  u32(0x004E4942);  // "BIN\0"
  out.write(reinterpret_cast<const char*>(bin.data()), std::streamsize(bin.size()));
  if (!out) return fail(ErrorKind::Device, path + ": cannot write the default object");
  return ok_status();
}

// 10th percentile of the valid depth samples in the central quarter (the nearest real surface
// there, robust to a few outliers), metres; 0 when none.
double central_depth_m(const InputFrame& f, double depth_scale) {
  std::vector<uint16_t> v;
  const ImageU16& d = f.depth;
  for (int y = d.height * 3 / 8; y < d.height * 5 / 8; ++y)
    for (int x = d.width * 3 / 8; x < d.width * 5 / 8; ++x)
      if (*d.at(x, y)) v.push_back(*d.at(x, y));
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + long(v.size() / 10), v.end());
  return double(v[v.size() / 10]) / depth_scale;
}

Pose fixed_camera_pose() {
  Pose p;  // camera x -> world x, camera y (down) -> world -y, camera z (forward) -> world -z
  p.rotation = glm::dquat(0.0, 1.0, 0.0, 0.0);
  return p;
}

SceneDesc default_scene(const std::string& glb, double depth_m) {
  SceneDesc s;
  s.path = "(mrgi live default scene)";
  VirtualObjectDesc box;
  box.gltf = glb;
  // In front of the nearest central surface, and no farther than 1.2 m so the box stays visible.
  const double d = depth_m > 0.0 ? std::clamp(0.8 * depth_m, 0.4, 1.2) : 1.0;
  box.placement.position = glm::vec3(0.0f, 0.0f, float(-d));  // straight ahead of the fixed camera
  box.placement.rotation = glm::angleAxis(glm::radians(30.0f), glm::vec3(0, 1, 0)) *
                           glm::angleAxis(glm::radians(20.0f), glm::vec3(1, 0, 0));
  s.virtual_objects.push_back(box);
  LightDesc sun;
  sun.type = LightType::Directional;
  sun.real = true;
  sun.direction = glm::normalize(glm::vec3(0.3f, -0.7f, -0.65f));  // from above and behind the camera
  sun.intensity = 3.0f;
  s.lights.push_back(sun);
  return s;
}

struct TempFolder {
  std::filesystem::path path;
  ~TempFolder() {
    std::error_code ec;
    if (!path.empty()) std::filesystem::remove_all(path, ec);
  }
};

// The source's options: the environment camera with its calibration from --env-model.
SourceOptions source_options(const LiveOptions& o) {
  SourceOptions so;
  so.env = o.env;
  if (!o.env.empty()) {
    if (o.env_model.empty()) throw CommandFailure(2, "--env needs --env-model CAPTURE_JSON (its env_camera calibration)");
    const CaptureInfo calib = take(load_capture_json(o.env_model));
    if (!calib.env_camera) throw CommandFailure(1, o.env_model + ": has no env_camera calibration");
    so.env_model = calib.env_camera;
    so.env_exposure = calib.exposure;
  }
  return so;
}

// --scene's scene, or a box at the first frame's central depth (its glTF written into `temp`).
SceneDesc live_scene(const LiveOptions& o, const InputFrame& first, double depth_scale, TempFolder& temp) {
  SceneDesc scene;
  if (!o.scene.empty()) {
    scene = take(load_scene_json(o.scene));
  } else {
    temp.path = std::filesystem::temp_directory_path() / ("mrgi-live-" + std::to_string(::getpid()));
    std::filesystem::create_directories(temp.path);
    const std::string glb = (temp.path / "default_box.glb").string();
    auto st = write_box_glb(glb, 0.15f);
    if (!st.ok()) fail_with(st.error());
    scene = default_scene(glb, central_depth_m(first, depth_scale));
  }
  return scene;
}

// The next frame into `frame`: `pending` if it holds one, else the source's. False at the end of
// the stream.
bool next_frame(InputSource& source, std::optional<InputFrame>& pending, int timeout_ms, InputFrame& frame) {
  if (pending) {
    frame = std::move(*pending);
    pending.reset();
  } else {
    auto next = source.next(std::chrono::milliseconds(timeout_ms));
    if (!next.ok()) {
      if (next.error().kind == ErrorKind::EndOfStream) return false;
      fail_with(next.error());
    }
    frame = std::move(next.value());
  }
  return true;
}

// The frame's pose: its own, the tracker's (counted by tracking state), or the last one.
void set_pose(InputFrame& frame, std::optional<AprilTagTracker>& tracker, std::map<std::string, int>& tracking_states,
              Pose& last_pose) {
  if (!frame.pose && tracker) {
    const TrackingResult r = tracker->fill_pose(frame);
    ++tracking_states[to_string(r.state)];
  }
  if (frame.pose) last_pose = *frame.pose;
  else frame.pose = last_pose;  // without tracking the camera pose stays where it was
}

void run_live(const LiveOptions& o) {
  RuntimeSettings settings;
  o.quality.apply(settings);  // before the source is opened: a bad level or knob ends here
  const int level = settings.level;
  auto source = take(open_source(o.source, source_options(o)));
  const CaptureInfo& info = source->info();

  std::optional<AprilTagTracker> tracker;
  if (info.apriltag) tracker = take(AprilTagTracker::create(*info.apriltag, info.color));

  // The first frame decides the default object's distance.
  auto first = source->next(std::chrono::milliseconds(o.timeout_ms));
  if (!first.ok()) fail_with(first.error());
  TempFolder temp;
  const SceneDesc scene = live_scene(o, *first, info.depth_scale, temp);

  settings.device.device = o.device;
  settings.exposure = info.exposure;
  CameraSetup cameras{info.color, info.depth, info.depth_scale, info.exposure, info.env_camera};
  const int out_w = info.color.width, out_h = info.color.height;
  // --view: the window's own device (the view is the app), mrgi on it; declared before the
  // runtime so that it outlives it.
  std::unique_ptr<LiveView> view;
  if (o.view.view) {
    view = take(LiveView::open("mrgi live " + source->name(), out_w, out_h, o.device));
    settings.device.app_device = &view->device();
  }
  std::unique_ptr<Runtime> runtime = take(create_runtime(settings, cameras, scene));
  // Without --out (only with --view) nothing is written.
  std::optional<ReplayOutput> output;
  if (!o.out.empty()) {
    ReplayMeta meta{source->name(), runtime->technique(), level,
                    level == kAutoLevel ? "auto" : runtime->level_names()[size_t(level)], runtime->device().name,
                    runtime->device().type == "cpu", runtime->memory_mib(), out_w, out_h};
    output.emplace(take(ReplayOutput::create(o.out, meta)));
    if (Status st = output->set_images(o.output_images.wants("composite"), o.output_images.wants("overlay")); !st.ok())
      fail_with(st.error());
  }

  std::signal(SIGINT, on_sigint);
  std::map<int64_t, ImageRGB8> cameras_by_frame;
  std::map<std::string, int> tracking_states;
  Pose last_pose = fixed_camera_pose();
  size_t submitted = 0, written = 0;
  const auto t0 = std::chrono::steady_clock::now();
  // Encoding (PNG writes, stats) runs on its own thread behind a bounded queue, so the runtime's
  // loop only waits for the sensor and the GPU.
  struct Finished {
    FrameOutput output;
    ImageRGB8 camera;
  };
  BoundedQueue<Finished> finished(2);
  ReturnQueue<FrameOutput> encoded;  // outputs written, for Runtime::recycle
  StageThread encode(
      [&] {
        while (auto f = finished.pop()) {
          if (output) {
            auto st = output->add(f->output, f->camera, nullptr, nullptr);
            if (!st.ok()) fail_with(st.error());
          }
          encoded.put(std::move(f->output));
          ++written;
          if (!o.quiet)
            progress("live " + o.quality.technique, written, o.frames > 0 ? size_t(o.frames) : written,
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        }
      },
      [&] { finished.close(); });
  // Declared after `encode`, so on an error below the queue is closed before the encoder is
  // joined (and it drains instead of waiting forever).
  struct CloseOnExit {
    BoundedQueue<Finished>& q;
    ~CloseOnExit() { q.close(); }
  } close_on_exit{finished};
  bool technique_requested = false;
  auto consume = [&](std::vector<FrameOutput>&& outs) {
    for (FrameOutput& f : outs) {
      auto cam = cameras_by_frame.find(f.stats.frame_index);
      if (cam == cameras_by_frame.end()) throw CommandFailure(1, "internal: output for unknown frame " + std::to_string(f.stats.frame_index));
      if (view) {  // on this thread: the window belongs to it
        if (Status st = view->show(f.image, cam->second, view_status(*runtime, f.stats)); !st.ok()) fail_with(st.error());
        const ViewRequests r = view->poll();
        if (r.quit) g_stop = true;
        technique_requested = technique_requested || r.next_technique;
        if (Status st = step_level(*runtime, f.stats, r.level_step); !st.ok()) fail_with(st.error());
      }
      Finished item{std::move(f), std::move(cam->second)};
      cameras_by_frame.erase(cam);
      if (!finished.push(std::move(item))) encode.join();  // the encoder failed: rethrow its error
    }
  };
  std::optional<InputFrame> pending = std::move(first.value());
  while (!g_stop && (o.frames == 0 || submitted < size_t(o.frames))) {
    InputFrame frame;
    if (!next_frame(*source, pending, o.timeout_ms, frame)) break;
    set_pose(frame, tracker, tracking_states, last_pose);
    frame.index = int64_t(submitted++);
    cameras_by_frame[frame.index] = resize_bilinear(frame.color, out_w, out_h);
    for (FrameOutput& done : encoded.take_all()) runtime->recycle(std::move(done));
    consume(take(runtime->process(frame)));
    if (technique_requested) {  // the view's T: this runtime's frames out, the next one on the same device
      consume(take(runtime->flush()));
      const RuntimeSettings next = take(next_technique_settings(settings, runtime->technique()));
      runtime.reset();
      runtime = take(create_runtime(next, cameras, scene));
      technique_requested = false;
      std::cerr << "mrgi live: view: technique " << next.technique << " from frame " << submitted << "\n";
    }
  }
  consume(take(runtime->flush()));
  finished.close();
  encode.join();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (written != submitted)
    throw CommandFailure(1, "internal: " + std::to_string(written) + " of " + std::to_string(submitted) + " frames came back");
  if (output) output->set_achieved({written, seconds, "from the first frame to the last encoded, sensor waits included"});
  if (!o.quiet && seconds > 0.0)
    std::cerr << "mrgi live: " << written << " frames in " << seconds << " s: " << double(written) / seconds
              << " fps achieved\n";
  nlohmann::json summary = output ? take(output->finish()) : nlohmann::json{{"frames", written}, {"written", "nothing (no --out)"}};
  if (!tracking_states.empty()) {
    std::cerr << "mrgi live: AprilTag tracking:";
    for (auto& [state, n] : tracking_states) std::cerr << " " << state << " " << n;
    std::cerr << "\n";
  }
  std::cout << summary.dump(2) << "\n";
  if (view && !o.view.screenshot.empty()) {
    if (Status st = write_png(o.view.screenshot, take(view->screenshot())); !st.ok()) fail_with(st.error());
  } else if (view && !g_stop) {
    std::cerr << "mrgi live: view: the last frame stays up until the window is closed (Q or Esc)\n";
    view->hold();
  }
}

void setup(CLI::App& app) {
  auto o = std::make_shared<LiveOptions>();
  CLI::App* cmd = app.add_subcommand("live", "Run a live source through a technique and write frames, stats and a summary");
  cmd->add_option("source", o->source, "openni:, openni:FILE.oni, v4l2:/dev/videoN, libcamera:ID, or a capture folder")->required();
  o->quality.add(*cmd);
  cmd->add_option("--scene", o->scene, "scene.json (default: a 15 cm box in front of the camera, one real light)");
  o->output_images.add(*cmd);
  cmd->add_option("--out,-o", o->out, "output folder (frames/, stats.json, summary.json, side_by_side.png); "
                                      "required unless --view shows the frames instead");
  o->view.add(*cmd, "as it comes back", "at the end of the stream");
  cmd->add_option("--frames,-n", o->frames, "stop after N frames (0 = until the stream ends or Ctrl-C)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--device", o->device, "Vulkan device: index, cpu / lavapipe, gpu, or name part");
  cmd->add_option("--env", o->env, "fisheye environment camera, v4l2:/dev/videoN or libcamera:ID (needs a calibrated model)");
  cmd->add_option("--env-model", o->env_model, "capture.json whose env_camera (fisheye equidistant) and exposure calibrate --env");
  cmd->add_option("--timeout-ms", o->timeout_ms, "longest wait for one frame before failing (ms)")->check(CLI::Range(1, 600000))->capture_default_str();
  cmd->add_flag("--quiet,-q", o->quiet, "no progress on stderr");
  cmd->callback([o] {
    if (o->out.empty() && !o->view.view) throw CommandFailure(2, "live: --out is required (or --view to show the frames instead)");
    if (!o->view.screenshot.empty() && !o->view.view) throw CommandFailure(2, "live: --view-screenshot: only with --view");
    run_live(*o);
  });
}

}  // namespace

MRGI_COMMAND(live, setup);

}  // namespace mrgi::tool

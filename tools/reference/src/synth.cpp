// `mrgi synth`: scene description -> capture v1 folder (see mrgi/reference/synth.h).
#include "mrgi/reference/synth.h"

#include <chrono>
#include <cmath>
#include <filesystem>

#include "mrgi/platform/capture.h"
#include "mrgi/reference/path_tracer.h"
#include "mrgi/reference/sensors.h"
#include "shared/mrgi_shared.h"
#include "synth_resume.h"
#include "synth_scene.h"

namespace mrgi::reference {

namespace fs = std::filesystem;

namespace {

// Box-filtered copy of an equirectangular image at width x width/2 (area average per target pixel).
ImageRGBF downsample_equirect(const ImageRGBF& src, int width) {
  const int w = std::min(width, src.width), h = std::max(1, w / 2);
  ImageRGBF out(w, h);
  for (int y = 0; y < h; ++y) {
    const int y0 = y * src.height / h, y1 = std::max(y0 + 1, (y + 1) * src.height / h);
    for (int x = 0; x < w; ++x) {
      const int x0 = x * src.width / w, x1 = std::max(x0 + 1, (x + 1) * src.width / w);
      double sum[3] = {0.0, 0.0, 0.0};
      for (int yy = y0; yy < y1; ++yy)
        for (int xx = x0; xx < x1; ++xx)
          for (int c = 0; c < 3; ++c) sum[c] += src.at(xx, yy)[c];
      const double n = double(x1 - x0) * double(y1 - y0);
      for (int c = 0; c < 3; ++c) out.at(x, y)[c] = float(sum[c] / n);
    }
  }
  return out;
}

Status copy_file(const std::string& from, const fs::path& to) {
  std::error_code ec;
  fs::create_directories(to.parent_path(), ec);
  if (ec) return fail(ErrorKind::BadInput, to.parent_path().string() + ": cannot create folder: " + ec.message());
  fs::copy_file(from, to, fs::copy_options::overwrite_existing, ec);
  if (ec) return fail(ErrorKind::BadInput, "copying '" + from + "' to '" + to.string() + "': " + ec.message());
  return ok_status();
}

RefCamera env_camera_model(const EnvCameraDesc& e, EnvCamera* info) {
  RefCamera cam;
  cam.model = RefCamera::Model::FisheyeEquidistant;
  cam.width = cam.height = e.size;
  const double half_fov = 0.5 * e.fov_deg * 3.14159265358979323846 / 180.0;
  cam.fisheye_f = 0.5 * e.size / half_fov;
  cam.fisheye_cx = cam.fisheye_cy = 0.5 * (e.size - 1);
  cam.fisheye_fov_deg = e.fov_deg;
  const glm::dquat rot = look_rotation(e.position, e.look_at, e.up);
  Pose pose;
  pose.translation = e.position;
  pose.rotation = rot;
  cam.camera_to_world = pose.matrix();
  info->model = EnvModel::FisheyeEquidistant;
  info->f = cam.fisheye_f;
  info->cx = cam.fisheye_cx;
  info->cy = cam.fisheye_cy;
  info->fov_deg = e.fov_deg;
  info->rotation = rot;
  return cam;
}

double srgb8_to_linear(uint8_t v) { return shader::srgb_decode1(float(v) / 255.0f); }

NoiseFloor noise_floor(const ImageRGB8& c_a, const ImageRGB8& g_a, const ImageRGB8& c_b, const ImageRGB8& g_b,
                       const ImageU8& mask) {
  double num[3] = {0, 0, 0}, den[3] = {0, 0, 0};  // all, real, virtual
  for (size_t i = 0; i < mask.pixel_count(); ++i) {
    const int set = mask.data[i] ? 2 : 1;
    for (int c = 0; c < 3; ++c) {
      const size_t k = 3 * i + c;
      const double da = srgb8_to_linear(g_a.data[k]) - srgb8_to_linear(c_a.data[k]);
      const double db = srgb8_to_linear(g_b.data[k]) - srgb8_to_linear(c_b.data[k]);
      for (int s : {0, set}) {
        num[s] += (db - da) * (db - da);
        den[s] += da * da;
      }
    }
  }
  auto ratio = [](double n, double d) { return d > 0.0 ? std::sqrt(n / d) : 0.0; };
  NoiseFloor f;
  f.rde_all = ratio(num[0], den[0]);
  f.rde_real = ratio(num[1], den[1]);
  f.rde_virtual = ratio(num[2], den[2]);
  f.delta_rms = mask.pixel_count() ? std::sqrt(den[0] / double(mask.pixel_count())) : 0.0;
  return f;
}

}  // namespace

Expected<SynthReport> synthesize_capture(const SceneDescription& description, const SynthOptions& options) {
  SceneDescription d = description;
  if (options.frames) {
    if (*options.frames < 1) return fail(ErrorKind::BadUsage, "--frames must be >= 1");
    d.frames = *options.frames;
  }
  if (options.spp) {
    if (*options.spp < 1) return fail(ErrorKind::BadUsage, "--spp must be >= 1");
    d.spp = *options.spp;
  }
  if (options.seed) d.seed = *options.seed;
  if (options.stop_after && *options.stop_after < 1) return fail(ErrorKind::BadUsage, "--stop-after must be >= 1");
  if (options.width || options.height) {
    const int w = options.width.value_or(d.intrinsics.width), h = options.height.value_or(d.intrinsics.height);
    if (w < 1 || h < 1 || w > 8192 || h > 8192) return fail(ErrorKind::BadUsage, "--width/--height must be in [1, 8192]");
    d.intrinsics = d.intrinsics.scaled_to(w, h);
  }
  if (options.out.empty()) return fail(ErrorKind::BadUsage, "--out must name the capture folder to create");
  std::error_code ec;
  if (fs::exists(options.out, ec))
    return fail(ErrorKind::BadUsage, options.out + ": already exists; synth does not overwrite captures");

  auto scene = SynthScene::load(d);
  if (!scene) return scene.error();

  CaptureInfo info;
  info.color = info.depth = d.intrinsics;
  info.depth_scale = d.depth.depth_scale;
  info.exposure = d.exposure;
  RefCamera env_cam;
  if (d.env_camera) {
    EnvCamera e;
    env_cam = env_camera_model(*d.env_camera, &e);
    info.env_camera = e;
  }

  // scene.json: what the runtime is told. Files it names are staged inside the capture.
  const fs::path final_dir = fs::absolute(options.out).lexically_normal();
  const fs::path staging = fs::path(final_dir.string() + ".partial");
  SceneDesc scene_json;
  struct Copy {
    std::string from;
    fs::path to;
  };
  std::vector<Copy> copies;
  for (size_t i = 0; i < d.virtual_objects.size(); ++i) {
    VirtualObjectDesc v;
    const fs::path rel = fs::path("virtual") / (std::to_string(i) + "_" + fs::path(d.virtual_objects[i].gltf).filename().string());
    v.gltf = (staging / rel).string();
    v.placement = scene->virtual_placement(i, 0.0);
    copies.push_back({d.virtual_objects[i].gltf, staging / rel});
    scene_json.virtual_objects.push_back(v);
  }
  for (const LampDesc& l : d.lights) {
    if (l.type == LampKind::Area) continue;  // scene.json v1 has no area lamps
    LightDesc ld;
    ld.type = l.type == LampKind::Point ? LightType::Point : l.type == LampKind::Spot ? LightType::Spot : LightType::Directional;
    ld.real = l.real;
    ld.position = glm::vec3(l.position);
    ld.direction = glm::vec3(l.direction);
    ld.color = glm::vec3(l.color);
    ld.intensity = float(l.intensity);
    ld.inner_angle_deg = float(l.inner_angle_deg);
    ld.outer_angle_deg = float(l.outer_angle_deg);
    scene_json.lights.push_back(ld);
  }
  ImageRGBF env_copy;
  if (d.environment.present) {
    EnvironmentDesc& e = scene_json.environment;
    e.present = true;
    e.real = true;
    e.intensity = float(d.environment.intensity);
    e.rotation = glm::quat(d.environment.rotation);
    if (d.env_camera) {
      // The env camera sees radiance already scaled by the intensity.
      e.from_env_camera = true;
      e.intensity = 1.0f;
      e.rotation = glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
    } else {
      env_copy = downsample_equirect(scene->environment_image(), d.environment.capture_width);
      e.image = (staging / "environment" / "environment.exr").string();
    }
  }

  auto identity = synth_resume_identity(d, options);
  if (!identity) return identity.error();
  const std::string resume_path = (staging / kSynthResumeFile).string();
  SynthResumeState state = *identity;
  const bool resuming = options.resume && fs::exists(staging, ec);
  auto writer = resuming ? CaptureWriter::resume(final_dir.string(), info, scene_json, options.references)
                         : CaptureWriter::create(final_dir.string(), info, scene_json, options.references);
  if (!writer) return writer.error();
  writer->set_png_effort(PngEffort::Small);  // suite captures live in the repository
  if (resuming) {
    auto saved = load_synth_resume(resume_path);
    if (!saved) return saved.error();
    if (saved->fingerprint != identity->fingerprint)
      return fail(ErrorKind::BadUsage, staging.string() + " was started from another description, input files or "
                                       "settings (fingerprint " + saved->fingerprint + " there, " +
                                       identity->fingerprint + " now; there: " + saved->settings + "; now: " +
                                       identity->settings + "); resume with the same ones, or remove it to start again");
    const size_t done = writer->frame_count();
    if (done > size_t(d.frames) || saved->frames.size() < done)
      return fail(ErrorKind::BadInput, resume_path + ": records " + std::to_string(saved->frames.size()) +
                                           " frames, the capture writer holds " + std::to_string(done) +
                                           " of " + std::to_string(d.frames) + "; remove " + staging.string() +
                                           " to start again");
    state.frames.assign(saved->frames.begin(), saved->frames.begin() + long(done));
  } else {
    MRGI_TRY(save_synth_resume(resume_path, state));
  }
  for (const Copy& c : copies) MRGI_TRY(copy_file(c.from, c.to));
  if (!env_copy.empty()) {
    fs::create_directories(staging / "environment", ec);
    MRGI_TRY(write_exr((staging / "environment" / "environment.exr").string(), env_copy));
  }

  SynthReport report;
  report.frames = d.frames;
  report.spp = d.spp;
  report.frames_resumed = int(state.frames.size());
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  for (int f = report.frames_resumed; f < d.frames; ++f) {
    if (options.stop_after && report.frames_rendered == *options.stop_after) {
      report.finished = false;
      break;
    }
    const double t = f / d.fps;
    const double frame_start = elapsed();
    auto tracer = PathTracer::create(scene->at_time(t));
    if (!tracer) return tracer.error();
    RefCamera cam;
    cam.pinhole = d.intrinsics;
    const Pose pose = camera_pose_at(d, t);
    cam.camera_to_world = pose.matrix();
    RenderSettings rs;
    rs.spp = d.spp;
    rs.max_depth = d.max_depth;
    rs.rr_depth = d.rr_depth;
    rs.seed = d.seed;
    rs.frame = uint64_t(f);
    rs.threads = options.threads;
    if (options.progress)
      rs.progress = [&](size_t done, size_t total) {
        options.progress("synth " + fs::path(d.path).stem().string(), size_t(f) * total + done,
                         size_t(d.frames) * total, elapsed());
      };
    auto render = (*tracer)->render(cam, rs);
    if (!render) return render.error();
    SynthFrameRecord record;
    record.dropped_samples = render->dropped_samples;

    InputFrame frame;
    frame.index = f;
    frame.timestamp = t;
    frame.depth_timestamp = t;
    frame.pose = pose;
    auto color = camera_frame(render->real, d.exposure, d.noise, d.seed, uint64_t(f));
    if (!color) return color.error();
    frame.color = std::move(*color);
    auto reference = camera_frame(render->combined, d.exposure, d.noise, d.seed, uint64_t(f));
    if (!reference) return reference.error();
    auto depth = depth_frame(render->depth_z, render->cos_incidence, cam.pinhole.width, cam.pinhole.height, d.depth,
                             d.seed, uint64_t(f));
    if (!depth) return depth.error();
    frame.depth = std::move(*depth);
    if (d.env_camera) {
      RenderSettings es = rs;
      es.spp = d.env_camera->spp;
      es.real_only = true;
      es.progress = nullptr;
      auto env = (*tracer)->render(env_cam, es);
      if (!env) return env.error();
      frame.env = std::move(env->real);
    }
    if (f == 0 && options.noise_floor_seed) {
      RenderSettings other = rs;
      other.seed = *options.noise_floor_seed;
      other.progress = nullptr;
      auto again = (*tracer)->render(cam, other);
      if (!again) return again.error();
      auto c_b = camera_frame(again->real, d.exposure, d.noise, other.seed, 0);
      if (!c_b) return c_b.error();
      auto g_b = camera_frame(again->combined, d.exposure, d.noise, other.seed, 0);
      if (!g_b) return g_b.error();
      record.noise_floor = noise_floor(frame.color, *reference, *c_b, *g_b, render->virtual_mask);
    }
    // The record goes first, so the records always cover the frames the writer holds.
    record.seconds = elapsed() - frame_start;
    state.frames.push_back(record);
    MRGI_TRY(save_synth_resume(resume_path, state));
    MRGI_TRY(writer->add_frame(frame, &*reference, &render->virtual_mask));
    ++report.frames_rendered;
  }
  for (const SynthFrameRecord& r : state.frames) {
    report.dropped_samples += r.dropped_samples;
    report.frame_seconds += r.seconds;
  }
  if (!state.frames.empty()) report.noise_floor = state.frames[0].noise_floor;
  if (report.finished) {
    fs::remove(resume_path, ec);
    if (ec) return fail(ErrorKind::Device, resume_path + ": cannot remove: " + ec.message());
    MRGI_TRY(writer->finish());
  }
  report.seconds = elapsed();
  return report;
}

}  // namespace mrgi::reference

// `mrgi synth`: scene description -> capture v1 folder (see mrgi/reference/synth.h).
#include "mrgi/reference/synth.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <glm/gtc/matrix_transform.hpp>

#include "mrgi/platform/capture.h"
#include "mrgi/reference/path_tracer.h"
#include "mrgi/reference/sensors.h"
#include "shared/mrgi_shared.h"
#include "environment_sampler.h"
#include "synth_from_renders.h"
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

// Whether the segment from `o` along unit `d` up to `tmax` hits a real triangle (brute force:
// a light probe's few shadow rays over a synthetic scene's few thousand triangles).
bool real_occluded(const RefScene& scene, const glm::vec3& o, const glm::vec3& d, float tmax) {
  for (const RefMesh& m : scene.meshes) {
    if (m.is_virtual) continue;
    for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
      const glm::vec3 a = m.positions[m.indices[t]], b = m.positions[m.indices[t + 1]], c = m.positions[m.indices[t + 2]];
      const glm::vec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
      const float det = glm::dot(e1, p);
      if (std::abs(det) < 1e-12f) continue;
      const float inv = 1.0f / det;
      const glm::vec3 s = o - a;
      const float u = glm::dot(s, p) * inv;
      if (u < 0.0f || u > 1.0f) continue;
      const glm::vec3 q = glm::cross(s, e1);
      const float v = glm::dot(d, q) * inv;
      if (v < 0.0f || u + v > 1.0f) continue;
      const float dist = glm::dot(e2, q) * inv;
      if (dist > 1e-4f && dist < tmax) return true;
    }
  }
  return false;
}

// A camera never sees a delta lamp (point, spot, directional): their direct light at the probe
// is added to the pixel each one's direction falls in, as radiance = irradiance / the pixel's
// solid angle, where no real surface blocks it. Virtual lamps are not part of the real scene.
void add_delta_lamps(const RefScene& scene, const glm::vec3& p, ImageRGBF& probe) {
  constexpr double kPi = 3.14159265358979323846;
  for (const RefLight& l : scene.lights) {
    if (l.is_virtual) continue;
    glm::vec3 wi, e;
    float dist = 1e30f;
    if (l.type == RefLightType::Directional) {
      wi = -glm::normalize(l.direction);
      e = l.intensity;
    } else {
      const glm::vec3 to = l.position - p;
      const float d2 = glm::dot(to, to);
      if (!(d2 > 0.0f)) continue;
      dist = std::sqrt(d2);
      wi = to / dist;
      e = l.intensity / d2;
      if (l.type == RefLightType::Spot)
        e *= shader::spot_falloff(glm::dot(-wi, glm::normalize(l.direction)), l.cos_outer, l.cos_inner);
    }
    if (glm::all(glm::equal(e, glm::vec3(0.0f))) || real_occluded(scene, p, wi, dist)) continue;
    const double u = 0.5 + std::atan2(double(wi.x), -double(wi.z)) / (2.0 * kPi);
    const double v = std::acos(std::clamp(double(wi.y), -1.0, 1.0)) / kPi;
    const int x = std::clamp(int(u * probe.width), 0, probe.width - 1), y = std::clamp(int(v * probe.height), 0, probe.height - 1);
    const double dw = std::sin((y + 0.5) / probe.height * kPi) * (kPi / probe.height) * (2.0 * kPi / probe.width);
    float* t = probe.at(x, y);
    for (int c = 0; c < 3; ++c) t[c] += float(e[c] / dw);
  }
}

// The light sources alone as the probe point sees them: the environment where no real surface
// is in the way (8 x 8 directions a pixel, so a small sun is not missed) and the delta lamps;
// surfaces themselves are black (no bounce light). What an estimate of the real lights is
// compared with.
ImageRGBF direct_probe(const RefScene& scene, const glm::vec3& p, int width, int height) {
  constexpr double kPi = 3.14159265358979323846;
  constexpr int kSub = 8;
  const EnvironmentSampler env(scene.environment);
  ImageRGBF out(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      glm::dvec3 sum(0.0);
      double weight = 0.0;
      for (int j = 0; j < kSub; ++j)
        for (int i = 0; i < kSub; ++i) {
          const double theta = (y + (j + 0.5) / kSub) / height * kPi;
          const double phi = ((x + (i + 0.5) / kSub) / width - 0.5) * 2.0 * kPi;
          const glm::vec3 d(float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)),
                            float(-std::sin(theta) * std::cos(phi)));
          const double w = std::sin(theta);
          weight += w;
          if (env.present() && !real_occluded(scene, p, d, 1e30f)) sum += w * glm::dvec3(env.radiance(d));
        }
      float* t = out.at(x, y);
      const glm::dvec3 l = weight > 0.0 ? sum / weight : glm::dvec3(0.0);
      t[0] = float(l.x), t[1] = float(l.y), t[2] = float(l.z);
    }
  add_delta_lamps(scene, p, out);
  return out;
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
  info->position = e.position;
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
  const bool from_renders = !options.from_renders.empty();
  if (from_renders && (options.noise_floor_seed || options.resume || options.stop_after || options.spp || options.seed ||
                       options.width || options.height))
    return fail(ErrorKind::BadUsage, "--from-renders takes the frames as rendered: --noise-floor-seed, --resume, "
                                     "--stop-after, --spp, --seed, --width and --height do not apply");
  std::error_code ec;
  if (fs::exists(options.out, ec))
    return fail(ErrorKind::BadUsage, options.out + ": already exists; synth does not overwrite captures");

  if (from_renders) MRGI_TRY(check_renders_present(options.from_renders, d));
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
    // A moving object: its placement at every frame's time as keyframes (the runtime
    // interpolates between them; at the frames themselves they are the path tracer's poses).
    const auto& mo = d.virtual_objects[i];
    if (mo.velocity != glm::dvec3(0.0) || mo.angular_velocity_deg != glm::dvec3(0.0))
      for (int f = 0; f < d.frames; ++f) v.motion.push_back({f / d.fps, scene->virtual_placement(i, f / d.fps)});
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
  // The real surfaces that are not diffuse, as scene.json's real material regions (the material
  // hint a runtime gets for them): each generated shape's world bounding box, 1 cm larger on
  // every side (the reconstruction's positions scatter about the surface).
  for (const RealObjectDesc& o : d.real_objects) {
    if (!o.material || o.shape == ShapeKind::Gltf) continue;
    const RefMaterial& m = *o.material;
    if (m.type != MaterialType::Glossy && m.type != MaterialType::Mirror) continue;
    glm::dvec3 half = o.shape == ShapeKind::Plane ? glm::dvec3(0.5 * o.size.x, 0.0, 0.5 * o.size.y)
                      : o.shape == ShapeKind::Box ? 0.5 * o.size
                                                  : glm::dvec3(o.radius);
    half *= o.scale;
    glm::dvec3 lo(1e30), hi(-1e30);
    for (int k = 0; k < 8; ++k) {
      const glm::dvec3 corner((k & 1) ? half.x : -half.x, (k & 2) ? half.y : -half.y, (k & 4) ? half.z : -half.z);
      const glm::dvec3 w = o.position + o.rotation * corner;
      lo = glm::min(lo, w);
      hi = glm::max(hi, w);
    }
    RealMaterialRegion r;
    r.min = glm::vec3(lo - glm::dvec3(0.01));
    r.max = glm::vec3(hi + glm::dvec3(0.01));
    r.roughness = m.type == MaterialType::Mirror ? 0.0f : m.roughness;
    r.metallic = m.type == MaterialType::Mirror ? 1.0f : m.metallic;
    scene_json.real_materials.push_back(r);
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
  report.spp = from_renders ? 0 : d.spp;  // from renders: the renderer's own (its renders.json)
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
    RefCamera cam;
    cam.pinhole = d.intrinsics;
    const Pose pose = camera_pose_at(d, t);
    cam.camera_to_world = pose.matrix();
    if (from_renders) {
      auto rendered = load_rendered_frame(options.from_renders, f, d, pose);
      if (!rendered) return rendered.error();
      InputFrame frame;
      frame.index = f;
      frame.timestamp = t;
      frame.depth_timestamp = t;
      frame.pose = pose;
      auto color = camera_frame(rendered->render.real, d.exposure, d.noise, d.seed, uint64_t(f));
      if (!color) return color.error();
      frame.color = std::move(*color);
      auto reference = camera_frame(rendered->render.combined, d.exposure, d.noise, d.seed, uint64_t(f));
      if (!reference) return reference.error();
      auto depth = depth_frame(rendered->render.depth_z, rendered->render.cos_incidence, cam.pinhole.width,
                               cam.pinhole.height, d.depth, d.seed, uint64_t(f));
      if (!depth) return depth.error();
      frame.depth = std::move(*depth);
      if (d.env_camera) frame.env = std::move(rendered->env);
      SynthFrameRecord record;
      record.seconds = elapsed() - frame_start;
      state.frames.push_back(record);
      MRGI_TRY(save_synth_resume(resume_path, state));
      MRGI_TRY(writer->add_frame(frame, &*reference, &rendered->render.virtual_mask));
      ++report.frames_rendered;
      continue;
    }
    auto tracer = PathTracer::create(scene->at_time(t));
    if (!tracer) return tracer.error();
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
  if (report.finished && d.light_probe && !from_renders && !fs::exists(staging / "light_probe" / "probe_direct.exr")) {
    // The probe: the real scene's incident radiance at the virtual objects' frame-0 centre.
    const RefScene at0 = scene->at_time(0.0);
    glm::dvec3 lo(1e30), hi(-1e30);
    for (const RefMesh& m : at0.meshes)
      if (m.is_virtual)
        for (const glm::vec3& p : m.positions) {
          lo = glm::min(lo, glm::dvec3(p));
          hi = glm::max(hi, glm::dvec3(p));
        }
    const glm::dvec3 centre = 0.5 * (lo + hi);
    auto tracer = PathTracer::create(at0);
    if (!tracer) return tracer.error();
    RefCamera probe;
    probe.model = RefCamera::Model::Equirectangular;
    probe.width = d.light_probe->width;
    probe.height = d.light_probe->width / 2;
    probe.camera_to_world = glm::translate(glm::dmat4(1.0), centre);
    RenderSettings ps;
    ps.spp = d.light_probe->spp;
    ps.max_depth = d.max_depth;
    ps.rr_depth = d.rr_depth;
    ps.seed = d.seed;
    ps.threads = options.threads;
    ps.real_only = true;
    auto img = (*tracer)->render(probe, ps);
    if (!img) return img.error();
    add_delta_lamps(at0, glm::vec3(centre), img->real);
    fs::create_directories(staging / "light_probe", ec);
    MRGI_TRY(write_exr((staging / "light_probe" / "probe.exr").string(), img->real));
    MRGI_TRY(write_exr((staging / "light_probe" / "probe_direct.exr").string(),
                       direct_probe(at0, glm::vec3(centre), probe.width, probe.height)));
    std::ofstream j(staging / "light_probe" / "probe.json");
    char text[512];
    std::snprintf(text, sizeof text,
                  "{\n \"about\": \"incident radiance of the real scene at the virtual objects' frame-0 centre, "
                  "equirectangular in world axes (u = 0.5 + atan2(x, -z) / 2pi, v = acos(y) / pi), linear radiance: "
                  "probe.exr path-traced (lamps, environment, bounce light, occlusion), probe_direct.exr the light "
                  "sources alone (environment and lamps where no real surface blocks them, surfaces black)\",\n \"position\": [%.6f, %.6f, %.6f],\n \"spp\": %d\n}\n",
                  centre.x, centre.y, centre.z, ps.spp);
    j << text;
    if (!j) return fail(ErrorKind::Device, (staging / "light_probe" / "probe.json").string() + ": cannot write");
  }
  if (report.finished) {
    fs::remove(resume_path, ec);
    if (ec) return fail(ErrorKind::Device, resume_path + ": cannot remove: " + ec.message());
    MRGI_TRY(writer->finish());
  }
  report.seconds = elapsed();
  return report;
}

}  // namespace mrgi::reference

// Embree 3 scene set-up, tiling and threads of the reference path tracer. The light transport
// itself is in path_integrator.cpp.
#include "path_integrator.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <string>
#include <thread>

namespace mrgi::reference {

namespace {

Status check_scene(const RefScene& scene) {
  if (scene.materials.empty() && !scene.meshes.empty())
    return fail(ErrorKind::BadInput, "reference scene: meshes given but no materials");
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    const RefMaterial& mat = scene.materials[m];
    if (!finite3(mat.base_color) || !finite3(mat.emission) || !std::isfinite(mat.roughness) ||
        !std::isfinite(mat.metallic) || !std::isfinite(mat.ior) || mat.ior <= 0.0f)
      return fail(ErrorKind::BadInput, "reference scene: material " + std::to_string(m) +
                                           " has a non-finite value or ior <= 0");
    if (mat.texture >= int(scene.textures.size()))
      return fail(ErrorKind::BadInput, "reference scene: material " + std::to_string(m) +
                                           " names texture " + std::to_string(mat.texture) + " which does not exist");
  }
  for (size_t i = 0; i < scene.meshes.size(); ++i) {
    const RefMesh& mesh = scene.meshes[i];
    const std::string what = "reference scene: mesh " + std::to_string(i);
    if (mesh.indices.size() % 3 != 0) return fail(ErrorKind::BadInput, what + ": index count is not a multiple of 3");
    if (mesh.material < 0 || mesh.material >= int(scene.materials.size()))
      return fail(ErrorKind::BadInput, what + ": material index out of range");
    for (uint32_t idx : mesh.indices)
      if (idx >= mesh.positions.size()) return fail(ErrorKind::BadInput, what + ": vertex index out of range");
    for (const glm::vec3& p : mesh.positions)
      if (!finite3(p)) return fail(ErrorKind::BadInput, what + ": non-finite vertex position");
    if (!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size())
      return fail(ErrorKind::BadInput, what + ": normal count differs from vertex count");
    if (!mesh.uvs.empty() && mesh.uvs.size() != mesh.positions.size())
      return fail(ErrorKind::BadInput, what + ": uv count differs from vertex count");
  }
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const RefLight& l = scene.lights[i];
    if (!finite3(l.position) || !finite3(l.direction) || !finite3(l.intensity) ||
        glm::any(glm::lessThan(l.intensity, glm::vec3(0.0f))) || !std::isfinite(l.cos_inner) ||
        !std::isfinite(l.cos_outer))
      return fail(ErrorKind::BadInput, "reference scene: lamp " + std::to_string(i) +
                                           " has a non-finite or negative value");
  }
  return ok_status();
}

RTCScene build_embree_scene(RTCDevice device, const std::vector<RefMesh>& meshes) {
  RTCScene scene = rtcNewScene(device);
  for (size_t i = 0; i < meshes.size(); ++i) {
    const RefMesh& mesh = meshes[i];
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Embree-allocated buffers carry the padding its SIMD loads need past the last vertex.
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), mesh.positions.size()));
    for (size_t k = 0; k < mesh.positions.size(); ++k) {
      v[3 * k] = mesh.positions[k].x;
      v[3 * k + 1] = mesh.positions[k].y;
      v[3 * k + 2] = mesh.positions[k].z;
    }
    auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                               3 * sizeof(uint32_t), mesh.indices.size() / 3));
    std::copy(mesh.indices.begin(), mesh.indices.end(), idx);
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(scene, geom, unsigned(i));
    rtcReleaseGeometry(geom);
  }
  rtcCommitScene(scene);
  return scene;
}

EmitterSet build_emitters(const std::vector<RefMesh>& meshes, const std::vector<RefMaterial>& materials) {
  EmitterSet set;
  double area = 0.0;
  for (size_t i = 0; i < meshes.size(); ++i) {
    const RefMesh& mesh = meshes[i];
    if (max_component(materials[mesh.material].emission) <= 0.0f) continue;
    for (size_t t = 0; t < mesh.indices.size() / 3; ++t) {
      const glm::vec3& a = mesh.positions[mesh.indices[3 * t]];
      const glm::vec3& b = mesh.positions[mesh.indices[3 * t + 1]];
      const glm::vec3& c = mesh.positions[mesh.indices[3 * t + 2]];
      const double tri_area = 0.5 * glm::length(glm::cross(b - a, c - a));
      if (tri_area <= 0.0) continue;
      area += tri_area;
      set.triangles.push_back({uint32_t(i), uint32_t(t)});
      set.cdf.push_back(float(area));
    }
  }
  for (float& c : set.cdf) c = float(c / area);
  set.total_area = float(area);
  return set;
}

}  // namespace

PathTracer::PathTracer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

PathTracer::~PathTracer() {
  if (!impl_) return;
  if (impl_->real_scene) rtcReleaseScene(impl_->real_scene);
  if (impl_->virtual_scene) rtcReleaseScene(impl_->virtual_scene);
  if (impl_->device) rtcReleaseDevice(impl_->device);
}

Expected<std::unique_ptr<PathTracer>> PathTracer::create(const RefScene& scene) {
  MRGI_TRY(check_scene(scene));
  auto impl = std::make_unique<Impl>();
  impl->materials = scene.materials;
  impl->textures = scene.textures;
  impl->lights = scene.lights;
  for (const RefLight& l : scene.lights) impl->has_virtual_lights |= l.is_virtual;
  for (const RefMesh& m : scene.meshes) (m.is_virtual ? impl->virtual_meshes : impl->real_meshes).push_back(m);
  impl->environment = EnvironmentSampler(scene.environment);
  // One worker thread is enough for the small builds here; rendering threads are ours.
  impl->device = rtcNewDevice("threads=1");
  if (!impl->device) return fail(ErrorKind::Internal, "Embree: rtcNewDevice failed");
  impl->real_scene = build_embree_scene(impl->device, impl->real_meshes);
  impl->virtual_scene = build_embree_scene(impl->device, impl->virtual_meshes);
  if (rtcGetDeviceError(impl->device) != RTC_ERROR_NONE) {
    auto tracer = std::unique_ptr<PathTracer>(new PathTracer(std::move(impl)));  // releases handles
    return fail(ErrorKind::Internal, "Embree: building the scene failed");
  }
  impl->real_emitters = build_emitters(impl->real_meshes, impl->materials);
  impl->virtual_emitters = build_emitters(impl->virtual_meshes, impl->materials);
  return std::unique_ptr<PathTracer>(new PathTracer(std::move(impl)));
}

Expected<RenderOutput> PathTracer::render(const RefCamera& camera, const RenderSettings& settings) const {
  const int w = camera.image_width(), h = camera.image_height();
  if (w <= 0 || h <= 0 || w > 16384 || h > 16384)
    return fail(ErrorKind::BadUsage, "reference render: image size must be 1..16384, got " + std::to_string(w) +
                                         "x" + std::to_string(h));
  if (settings.spp < 1) return fail(ErrorKind::BadUsage, "reference render: spp must be >= 1");
  if (settings.max_depth < 0 || settings.max_depth > 1000)
    return fail(ErrorKind::BadUsage, "reference render: max_depth must be 0..1000");
  if (camera.model == RefCamera::Model::Pinhole &&
      (!(camera.pinhole.fx > 0.0) || !(camera.pinhole.fy > 0.0)))
    return fail(ErrorKind::BadUsage, "reference render: pinhole fx and fy must be > 0");
  if (camera.model == RefCamera::Model::FisheyeEquidistant && !(camera.fisheye_f > 0.0))
    return fail(ErrorKind::BadUsage, "reference render: fisheye f must be > 0");

  RenderOutput out;
  out.real = ImageRGBF(w, h);
  if (!settings.real_only) out.combined = ImageRGBF(w, h);
  out.virtual_mask = ImageU8(w, h);
  out.depth_z.assign(size_t(w) * h, 0.0f);
  out.cos_incidence.assign(size_t(w) * h, 0.0f);

  constexpr int kTile = 16;
  const int tiles_x = (w + kTile - 1) / kTile, tiles_y = (h + kTile - 1) / kTile;
  const size_t tile_count = size_t(tiles_x) * tiles_y;
  std::atomic<size_t> next{0}, done{0}, dropped{0};
  const Integrator integrator(*impl_, camera, settings);
  auto worker = [&] {
    size_t local_dropped = 0;
    for (size_t t = next++; t < tile_count; t = next++) {
      const int x0 = int(t % tiles_x) * kTile, y0 = int(t / tiles_x) * kTile;
      for (int y = y0; y < std::min(y0 + kTile, h); ++y)
        for (int x = x0; x < std::min(x0 + kTile, w); ++x) local_dropped += integrator.render_pixel(x, y, out);
      ++done;
    }
    dropped += local_dropped;
  };
  int thread_count = settings.threads > 0 ? settings.threads : int(std::thread::hardware_concurrency());
  thread_count = std::max(1, std::min(thread_count, 256));
  std::vector<std::thread> threads;
  for (int i = 0; i < thread_count; ++i) threads.emplace_back(worker);
  if (settings.progress) {
    while (done.load() < tile_count) {
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
      settings.progress(done.load(), tile_count);
    }
  }
  for (std::thread& t : threads) t.join();

  // Light tracing (path_tracer.h): each thread takes chunks of photons and keeps its own sums.
  if (camera.model == RefCamera::Model::Pinhole && !impl_->lights.empty()) {
    const uint64_t n = settings.light_paths > 0 ? settings.light_paths : uint64_t(settings.spp) * uint64_t(w) * uint64_t(h) / 4;
    constexpr uint64_t kChunk = 4096;
    for (int part = 0; part < (settings.real_only ? 1 : 2); ++part) {
      const bool combined = part == 1;
      std::vector<std::vector<double>> sums(size_t(thread_count), std::vector<double>(size_t(w) * size_t(h) * 3, 0.0));
      for (size_t light = 0; light < impl_->lights.size(); ++light) {
        std::atomic<uint64_t> next_chunk{0};
        std::vector<std::thread> tracers;
        for (int i = 0; i < thread_count; ++i)
          tracers.emplace_back([&, i] {
            size_t local = 0;
            for (uint64_t c = next_chunk++; c * kChunk < n; c = next_chunk++)
              local += integrator.trace_light_paths(light, c * kChunk, std::min(kChunk, n - c * kChunk), n, combined, sums[size_t(i)]);
            dropped += local;
          });
        for (std::thread& t : tracers) t.join();
      }
      ImageRGBF& image = combined ? out.combined : out.real;
      for (size_t j = 0; j < image.data.size(); ++j) {
        double add = 0.0;
        for (const auto& s : sums) add += s[j];
        image.data[j] += float(add);
      }
    }
  }
  out.dropped_samples = dropped.load();
  return out;
}

}  // namespace mrgi::reference

// The ssrt TSDF volume (technique/ssrt/volume.h) on lavapipe with validation on, driven through a
// minimal frame graph: synthetic depth frames of an analytic scene (floor y = 0, box A under the
// camera, box B to the left outside the looking-down view) rendered on the CPU, fused, and read
// back: the ray-cast view against the analytic depth and normal, the auxiliary left and light
// layers against the boxes' known faces, the fuse skip, the reset on a level change and memory.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <optional>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/packing.hpp>

#include "recon/reconstruction.h"
#include "../../shaders/common/frame_constants.glsl"
#include "../../shaders/shared/mrgi_shared.h"
#include "gpu/frame_graph.h"
#include "technique/ssrt/volume.h"
#include "vulkan/vk_test_util.h"
#include "common/look_at.h"
#include "common/frame_constants_for.h"

namespace {
using namespace mrgi;
using namespace mrgi::gpu;
using mrgi::test::VulkanTest;

struct Box {
  glm::vec3 lo, hi;
};
const Box kBoxA{{-0.15f, 0.0f, -0.15f}, {0.15f, 0.3f, 0.15f}};   // under the camera
const Box kBoxB{{-0.95f, 0.0f, -0.1f}, {-0.75f, 0.3f, 0.1f}};    // left of the view
const glm::vec3 kCenter(0.0f, 0.3f, 0.0f);                        // cube [-1,1]x[-0.7,1.3]x[-1,1]

// 1 m above the floor looking straight down: image x = world x, image y = world z.
glm::dmat4 looking_down(glm::dvec3 offset = glm::dvec3(0.0)) {
  return mrgi::test::opencv_look_at(glm::dvec3(0, 1, 0) + offset, glm::dvec3(0, 0, 0) + offset, glm::dvec3(0, 0, -1));
}
// Looking at box B's +x face from the right, slightly from above.
glm::dmat4 looking_left() {
  return mrgi::test::opencv_look_at(glm::dvec3(-0.1, 0.45, 0.0), glm::dvec3(-0.85, 0.1, 0.0), glm::dvec3(0, 1, 0));
}

// Slab test: entry distance of the ray o + t d into `b` (t > 0), and the entry face's normal.
bool hit_box(glm::vec3 o, glm::vec3 d, const Box& b, float& t_hit, glm::vec3& normal) {
  float t0 = 0.0f, t1 = 1e9f;
  int axis = -1;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-12f) {
      if (o[a] < b.lo[a] || o[a] > b.hi[a]) return false;
      continue;
    }
    float ta = (b.lo[a] - o[a]) / d[a], tb = (b.hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    if (ta > t0) t0 = ta, axis = a;
    t1 = std::min(t1, tb);
  }
  if (t0 > t1 || axis < 0) return false;
  t_hit = t0;
  normal = glm::vec3(0.0f);
  normal[axis] = d[axis] > 0.0f ? -1.0f : 1.0f;
  return true;
}

// The analytic scene along a ray: distance and normal of the first hit (floor, boxes).
bool trace_scene(glm::vec3 o, glm::vec3 d, float floor_y, bool with_boxes, float& t,
                 glm::vec3& n) {
  t = 1e9f;
  if (d.y < -1e-6f && o.y > floor_y) {
    t = (floor_y - o.y) / d.y;
    n = glm::vec3(0, 1, 0);
  }
  if (with_boxes) {
    for (const Box& b : {kBoxA, kBoxB}) {
      float tb;
      glm::vec3 nb;
      if (hit_box(o, d, b, tb, nb) && tb < t) t = tb, n = nb;
    }
  }
  return t < 1e8f;
}

struct Scene {
  float floor_y = 0.0f;
  bool boxes = true;
};

// Camera-z depth and world normal per pixel of the analytic scene (0 depth: nothing).
struct Truth {
  std::vector<float> depth;
  std::vector<glm::vec3> normal;
};

struct Rig {
  uint32_t w = 160, h = 120;
  glm::vec4 k{120.0f, 120.0f, 79.5f, 59.5f};
  uint32_t max_aux = 64;
  std::unique_ptr<FrameGraph> graph;
  frame::FrameResources shared;
  std::optional<ssrt::Volume> volume;
  BufferHandle rb_depth, rb_normal, rb_aux;
  std::vector<std::string> skipped;
  std::vector<FrameTimings> timings;
  ImageU16 depth;
  frame::DepthView depth_view;  // of `depth`, what the volume's skip test reads
  uint32_t last_slot = 0;
  ssrt::VolumeFrame last_frame;

  Rig(Context& ctx, uint32_t width, uint32_t height, ssrt::VolumeSettings s) : w(width), h(height) {
    const float f = 120.0f * float(w) / 160.0f;
    k = glm::vec4(f, f, 0.5f * float(w) - 0.5f, 0.5f * float(h) - 0.5f);
    max_aux = s.max_aux_resolution;
    FrameGraphSettings fs;
    fs.max_output_width = w;
    fs.max_output_height = h;
    auto g = FrameGraph::create(ctx, fs);
    EXPECT_TRUE(g.ok()) << g.error().message;
    graph = std::move(*g);
    EXPECT_TRUE(graph->set_output_size(w, h).ok());
    auto fc = graph->create_buffer({"frame_constants", sizeof(shader::FrameConstants),
                                    MemoryUsage::Upload, true},
                                   VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    EXPECT_TRUE(fc.ok());
    auto du = graph->create_buffer(recon::camera_upload_desc("depth_upload", size_t(w) * h * 2),
                                   VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    EXPECT_TRUE(du.ok());
    auto rb = [&](const char* name, VkDeviceSize bytes) {
      auto b = graph->create_buffer({name, bytes, MemoryUsage::Readback, true},
                                    VK_BUFFER_USAGE_TRANSFER_DST_BIT);
      EXPECT_TRUE(b.ok());
      return *b;
    };
    rb_depth = rb("rb_depth", VkDeviceSize(w) * h * 4);
    rb_normal = rb("rb_normal", VkDeviceSize(w) * h * 8);
    rb_aux = rb("rb_aux", VkDeviceSize(max_aux) * max_aux * 16 * 4);
    shared.context = &ctx;
    shared.graph = graph.get();
    shared.frame_constants = *fc;
    shared.depth_upload = *du;
    shared.depth_intrinsics = Intrinsics{int(w), int(h), k.x, k.y, k.z, k.w};
    shared.depth_scale = 5000.0;
    auto v = ssrt::Volume::create(ctx, *graph, shared, s);
    EXPECT_TRUE(v.ok()) << v.error().message;
    if (v.ok()) volume.emplace(std::move(*v));
    depth = ImageU16(int(w), int(h));
  }

  glm::vec3 ray_world(const glm::dmat4& pose, uint32_t u, uint32_t v) const {
    const glm::vec3 r = shader::unproject_pinhole(glm::vec2(u, v), 1.0f, k);
    return glm::vec3(glm::mat4(pose) * glm::vec4(r, 0.0f));
  }

  // Pipelines of the volume must outlive the frames in flight.
  ~Rig() {
    if (graph) (void)graph->flush();
  }

  Truth render(const glm::dmat4& pose, const Scene& scene) {
    Truth t;
    t.depth.assign(w * h, 0.0f);
    t.normal.assign(w * h, glm::vec3(0.0f));
    const glm::vec3 o(pose[3]);
    for (uint32_t v = 0; v < h; ++v) {
      for (uint32_t u = 0; u < w; ++u) {
        const glm::vec3 r = ray_world(pose, u, v);  // camera z = 1 per |r|
        float dist;
        glm::vec3 n;
        uint16_t raw = 0;
        if (trace_scene(o, glm::normalize(r), scene.floor_y, scene.boxes, dist, n)) {
          const float z = dist / glm::length(r);
          t.depth[v * w + u] = z;
          t.normal[v * w + u] = n;
          raw = uint16_t(std::lround(z * 5000.0f));
        }
        *depth.at(int(u), int(v)) = raw;
      }
    }
    return t;
  }

  // One frame: depth of `scene` from `pose` (unless `keep_depth`), the volume's passes and the
  // readbacks. Returns false when recording failed.
  bool frame(const glm::dmat4& pose, const Scene& scene, ssrt::VolumeFrame vf,
             Truth* truth = nullptr, bool readback = true) {
    auto begun = graph->begin_frame();
    EXPECT_TRUE(begun.ok()) << begun.error().message;
    if (begun.ok() && begun->has_value()) timings.push_back(**begun);
    const Truth t = render(pose, scene);
    if (truth) *truth = t;
    std::memcpy(graph->mapped(shared.depth_upload, graph->slot()), depth.data.data(),
                depth.data.size() * 2);
    const shader::FrameConstants fc =
        test::pinhole_frame_constants(glm::mat4(pose), k, int(w), int(h), 5000.0f);
    std::memcpy(graph->mapped(shared.frame_constants, graph->slot()), &fc, sizeof(fc));
    vf.camera_to_world = pose;
    depth_view = frame::DepthView{depth.data.data(), depth.width, depth.height};
    vf.depth = &depth_view;
    last_frame = vf;
    skipped.clear();
    const Status st = volume->record(vf, skipped);
    EXPECT_TRUE(st.ok()) << st.error().message;
    if (!st.ok()) return false;
    if (readback) add_readbacks(vf.aux_resolution);
    EXPECT_TRUE(graph->compile().ok());
    last_slot = graph->slot();
    const Status sub = graph->submit();
    EXPECT_TRUE(sub.ok()) << sub.error().message;
    return sub.ok();
  }

  void add_readbacks(uint32_t aux_res) {
    struct Copy {
      ImageHandle img;
      BufferHandle buf;
      uint32_t width, height, layers;
    };
    const Copy copies[3] = {{volume->depth_volume(), rb_depth, w, h, 1},
                            {volume->normal_volume(), rb_normal, w, h, 1},
                            {volume->aux_position(), rb_aux, aux_res, aux_res, 4}};
    for (const Copy& c : copies) {
      graph->add_pass(
          "readback_" + graph->name(c.img), PassKind::Transfer,
          [c](PassBuilder& b) {
            b.read(c.img, Access::TransferSrc);
            b.write(c.buf, Access::TransferDst);
          },
          [c](VkCommandBuffer cmd, PassContext& ctx) {
            VkBufferImageCopy region{};
            region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, c.layers};
            region.imageExtent = {c.width, c.height, 1};
            vkCmdCopyImageToBuffer(cmd, ctx.image(c.img), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                   ctx.buffer(c.buf), 1, &region);
          });
      graph->mark_output(c.buf);
    }
  }

  template <class T>
  const T* read(BufferHandle b) {
    EXPECT_TRUE(graph->flush().ok());
    EXPECT_TRUE(graph->context().invalidate(graph->gpu_buffer(b, last_slot)).ok());
    return static_cast<const T*>(graph->mapped(b, last_slot));
  }
  std::vector<float> depth_volume() {
    const float* p = read<float>(rb_depth);
    return std::vector<float>(p, p + w * h);
  }
  std::vector<glm::vec4> normal_volume() {
    const uint16_t* p = read<uint16_t>(rb_normal);
    std::vector<glm::vec4> out(w * h);
    for (size_t i = 0; i < out.size(); ++i)
      for (int c = 0; c < 4; ++c) out[i][c] = glm::unpackHalf1x16(p[i * 4 + c]);
    return out;
  }
  // Layer-major, aux_res^2 texels per layer.
  std::vector<glm::vec4> aux(uint32_t aux_res) {
    const glm::vec4* p = read<glm::vec4>(rb_aux);
    return std::vector<glm::vec4>(p, p + size_t(aux_res) * aux_res * 4);
  }
  shader::SsrtAuxViews views() const {
    shader::SsrtAuxViews v;
    std::memcpy(&v, graph->mapped(volume->aux_views(), last_slot), sizeof(v));
    return v;
  }
  bool was_skipped(const std::string& pass) const {
    for (const auto& s : skipped)
      if (s.rfind(pass + ":", 0) == 0) return true;
    return false;
  }
};

ssrt::VolumeSettings settings(uint32_t max_res, uint32_t max_aux = 64) {
  ssrt::VolumeSettings s;
  s.max_resolution = max_res;
  s.max_aux_resolution = max_aux;
  return s;
}
ssrt::VolumeFrame level(uint32_t res, uint32_t aux_res = 64) {
  ssrt::VolumeFrame f;
  f.resolution = res;
  f.aux_resolution = aux_res;
  f.center = kCenter;
  return f;
}

// Pixels whose neighbourhood of `voxels` voxels (projected at the pixel's depth) lies on one
// analytic surface and inside the image: there the view must match the truth. (Within about a
// voxel of a depth edge the TSDF rounds the edge; within that of the image border the voxels
// straddle the frustum and are not all observed.)
bool interior(const Rig& r, const Truth& t, uint32_t u, uint32_t v, float voxels_m) {
  const size_t c = v * r.w + u;
  if (t.depth[c] <= 0.0f) return false;
  const int m = int(std::ceil(voxels_m * r.k.x / t.depth[c]));
  if (int(u) < m || int(v) < m || int(u) + m >= int(r.w) || int(v) + m >= int(r.h)) return false;
  for (int dv = -m; dv <= m; ++dv)
    for (int du = -m; du <= m; ++du) {
      const size_t i = (v + dv) * r.w + (u + du);
      if (t.depth[i] <= 0.0f || t.normal[i] != t.normal[c] ||
          std::abs(t.depth[i] - t.depth[c]) > 0.05f * t.depth[c])
        return false;
    }
  return true;
}

// Compares D_v / N_v with the truth away from edges (2.5 voxels); tolerance in voxels.
void expect_view_matches(Rig& r, const Truth& t, float voxel_m, float tolerance_voxels,
                         const char* what) {
  const float tolerance_m = tolerance_voxels * voxel_m;
  const std::vector<float> dv = r.depth_volume();
  const std::vector<glm::vec4> nv = r.normal_volume();
  int interior_count = 0, depth_ok = 0, normal_ok = 0, nan = 0;
  float worst = 0.0f;
  for (uint32_t v = 0; v < r.h; ++v) {
    for (uint32_t u = 0; u < r.w; ++u) {
      const size_t i = v * r.w + u;
      if (!std::isfinite(dv[i]) || !std::isfinite(nv[i].x)) ++nan;
      if (!interior(r, t, u, v, 2.5f * voxel_m)) continue;
      ++interior_count;
      const float err = std::abs(dv[i] - t.depth[i]);
      if (dv[i] > 0.0f) worst = std::max(worst, err);
      depth_ok += dv[i] > 0.0f && err <= tolerance_m;
      const float cos_angle = glm::dot(glm::vec3(nv[i]), t.normal[i]);
      normal_ok += nv[i].w == 1.0f && cos_angle >= std::cos(glm::radians(5.0f));
    }
  }
  EXPECT_EQ(nan, 0) << what;
  EXPECT_GT(interior_count, int(r.w * r.h / 4)) << what;
  EXPECT_GE(depth_ok, interior_count * 97 / 100)
      << what << ": D_v within " << tolerance_m << " m (worst " << worst << ")";
  EXPECT_GE(normal_ok, interior_count * 95 / 100) << what << ": N_v within 5 degrees";
}

TEST_F(VulkanTest, VolumeViewMatchesTheAnalyticFloorAndBoxAt256) {
  Rig r(ctx(), 160, 120, settings(256));
  ASSERT_TRUE(r.volume.has_value());
  Truth t;
  for (int f = 0; f < 3; ++f) ASSERT_TRUE(r.frame(looking_down(), Scene{}, level(256), &t));
  EXPECT_TRUE(r.volume->fused_last_frame() || r.was_skipped("ssrt_tsdf_fuse"));
  // 256^3 over 2 m: 7.8 mm voxels; within 1.5 voxels.
  expect_view_matches(r, t, 2.0f / 256.0f, 1.5f, "256^3");
}

TEST_F(VulkanTest, VolumeAuxLayersSeeTheBoxLeftOfTheViewAndTheTopFromTheLight) {
  Rig r(ctx(), 160, 120, settings(64));
  ASSERT_TRUE(r.volume.has_value());
  const uint32_t aux_res = 64;
  // Box B seen only by earlier frames (looking left), then the camera turns to look down: B is
  // outside that view (the floor's visible half-width is 0.67 m at 1 m, B starts at 0.75 m).
  for (int f = 0; f < 3; ++f) ASSERT_TRUE(r.frame(looking_left(), Scene{}, level(64, aux_res)));
  Truth t;
  ASSERT_TRUE(r.frame(looking_down(), Scene{}, level(64, aux_res), &t));
  // Nothing of box B in the current depth (it would appear in the left part of the image).
  for (uint32_t v = 0; v < r.h; ++v)
    for (uint32_t u = 0; u < r.w; ++u) {
      const glm::vec3 p = glm::vec3(looking_down()[3]) +
                          r.ray_world(looking_down(), u, v) * t.depth[v * r.w + u];
      ASSERT_GT(p.x, kBoxB.hi.x + 0.02f) << "box B must be outside the current view";
    }
  const std::vector<glm::vec4> aux = r.aux(aux_res);
  const shader::SsrtAuxViews views = r.views();
  ASSERT_EQ(views.info.x, 4);
  ASSERT_EQ(views.info.y, int(aux_res));
  const float voxel = 2.0f / 64.0f;
  auto texel = [&](int layer, glm::vec3 world, float& depth) -> const glm::vec4* {
    const glm::vec4 p = views.world_to_aux[layer] * glm::vec4(world, 1.0f);
    depth = p.z;
    if (p.x < 0 || p.x > 1 || p.y < 0 || p.y > 1 || p.z <= 0) return nullptr;
    const int x = std::min(int(p.x * aux_res), int(aux_res) - 1);
    const int y = std::min(int(p.y * aux_res), int(aux_res) - 1);
    return &aux[(size_t(layer) * aux_res + y) * aux_res + x];
  };
  // Left layer: the rays at box B's height and depth hit its +x face at x = -0.75.
  int on_face = 0, face_rays = 0;
  for (float y = 0.06f; y <= 0.24f; y += 0.03f) {
    for (float z = -0.06f; z <= 0.06f; z += 0.03f) {
      float d;
      const glm::vec4* s = texel(SSRT_AUX_LEFT, glm::vec3(-0.85f, y, z), d);
      ASSERT_NE(s, nullptr);
      ++face_rays;
      on_face += s->w > 0.0f && std::abs(s->x - kBoxB.hi.x) <= 1.5f * voxel &&
                 std::abs(s->y - y) <= voxel && std::abs(s->z - z) <= voxel;
    }
  }
  EXPECT_GE(on_face, face_rays * 9 / 10) << "left layer: box B's face";
  // The transfer's rule: a point inside/behind B is occluded in the left layer, one between the
  // camera plane and B is not.
  float d_behind, d_front;
  const glm::vec4* behind = texel(SSRT_AUX_LEFT, glm::vec3(-0.9f, 0.15f, 0.0f), d_behind);
  const glm::vec4* front = texel(SSRT_AUX_LEFT, glm::vec3(-0.6f, 0.15f, 0.0f), d_front);
  ASSERT_TRUE(behind && front);
  EXPECT_TRUE(behind->w > 0.0f && behind->w < d_behind - 0.02f);
  EXPECT_FALSE(front->w > 0.0f && front->w < d_front - 0.02f);
  // Above the boxes the left rays find nothing inside the cube.
  float d_empty;
  const glm::vec4* empty = texel(SSRT_AUX_LEFT, glm::vec3(-0.85f, 0.8f, 0.0f), d_empty);
  ASSERT_NE(empty, nullptr);
  EXPECT_EQ(empty->w, 0.0f);

  // Light layer, light overhead: the top of box A (seen by the current frame) and of box B
  // (seen by the earlier ones) at y = 0.3, the floor beside them at y = 0.
  for (const glm::vec3 top : {glm::vec3(0.0f, 0.3f, 0.0f), glm::vec3(-0.85f, 0.3f, 0.0f)}) {
    float d;
    const glm::vec4* s = texel(SSRT_AUX_LIGHT, top, d);
    ASSERT_NE(s, nullptr);
    EXPECT_GT(s->w, 0.0f);
    EXPECT_NEAR(s->y, 0.3f, 1.5f * voxel) << "box top at x " << top.x;
    EXPECT_NEAR(s->x, top.x, voxel);
    EXPECT_NEAR(s->w, d, 1.5f * voxel) << "w is the depth along the light's axis";
  }
  float d_floor;
  const glm::vec4* floor = texel(SSRT_AUX_LIGHT, glm::vec3(0.45f, 0.0f, 0.3f), d_floor);
  ASSERT_NE(floor, nullptr);
  EXPECT_NEAR(floor->y, 0.0f, 1.5f * voxel);
  // Every layer: the axes of the looking-down camera (left -x, right +x, top -z world, light
  // -y), aux_to_world inverting world_to_aux, and each stored surface projecting back onto its
  // own texel at its stored depth.
  // ssrt_transfer reads the right layer through the left one's coordinates: same image plane and
  // down axis, opposite right and forward axes, so right = (1 - u, v, -depth) of left.
  for (const glm::vec3 pt : {glm::vec3(-0.85f, 0.15f, 0.05f), glm::vec3(0.4f, -0.2f, 0.9f), glm::vec3(1.3f, 0.7f, -0.6f)}) {
    const glm::vec4 l = views.world_to_aux[SSRT_AUX_LEFT] * glm::vec4(pt, 1.0f);
    const glm::vec4 rr = views.world_to_aux[SSRT_AUX_RIGHT] * glm::vec4(pt, 1.0f);
    EXPECT_NEAR(rr.x, 1.0f - l.x, 1e-5f);
    EXPECT_NEAR(rr.y, l.y, 1e-5f);
    EXPECT_NEAR(rr.z, -l.z, 1e-5f);
  }
  const glm::vec3 axes[4] = {{-1, 0, 0}, {1, 0, 0}, {0, 0, -1}, {0, -1, 0}};
  for (int layer = 0; layer < 4; ++layer) {
    EXPECT_LT(glm::length(glm::vec3(views.direction[layer]) - axes[layer]), 1e-5f) << layer;
    const glm::mat4 round_trip = views.world_to_aux[layer] * views.aux_to_world[layer];
    for (int c = 0; c < 4; ++c)
      for (int rr = 0; rr < 4; ++rr)
        EXPECT_NEAR(round_trip[c][rr], c == rr ? 1.0f : 0.0f, 1e-4f) << layer;
    int hits = 0, consistent = 0;
    for (uint32_t y = 0; y < aux_res; ++y)
      for (uint32_t x = 0; x < aux_res; ++x) {
        const glm::vec4 s = aux[(size_t(layer) * aux_res + y) * aux_res + x];
        ASSERT_TRUE(std::isfinite(s.x) && std::isfinite(s.w));
        if (s.w <= 0.0f) continue;
        ++hits;
        const glm::vec4 p = views.world_to_aux[layer] * glm::vec4(glm::vec3(s), 1.0f);
        consistent += std::abs(p.x * aux_res - (x + 0.5f)) < 0.01f &&
                      std::abs(p.y * aux_res - (y + 0.5f)) < 0.01f && std::abs(p.z - s.w) < 1e-4f;
      }
    EXPECT_EQ(consistent, hits) << "layer " << layer;
    // (The right and top layers' rays start inside box A and B, whose inside they leave through
    // back faces, and find nothing else: no hits expected there.)
    if (layer == SSRT_AUX_LEFT || layer == SSRT_AUX_LIGHT) {
      EXPECT_GT(hits, 20) << "layer " << layer;
    }
  }
  // The current view matches too (64^3: 3.1 cm voxels).
  expect_view_matches(r, t, voxel, 1.5f, "64^3");
}

TEST_F(VulkanTest, VolumeFuseSkipsOnlyForUnchangedPoseAndDepth) {
  Rig r(ctx(), 80, 60, settings(64));
  ASSERT_TRUE(r.volume.has_value());
  ASSERT_TRUE(r.frame(looking_down(), Scene{}, level(64), nullptr, false));
  EXPECT_TRUE(r.volume->fused_last_frame());
  EXPECT_FALSE(r.was_skipped("ssrt_tsdf_fuse"));
  // Same pose and depth: fuse and both ray-casts skipped, with reasons.
  ASSERT_TRUE(r.frame(looking_down(), Scene{}, level(64), nullptr, false));
  EXPECT_FALSE(r.volume->fused_last_frame());
  EXPECT_TRUE(r.was_skipped("ssrt_tsdf_fuse"));
  EXPECT_TRUE(r.was_skipped("ssrt_tsdf_raycast"));
  EXPECT_FALSE(r.graph->compiled().runs("ssrt_tsdf_fuse"));
  // Moved by 0.5 mm (below the 1 mm tolerance): still skipped.
  ASSERT_TRUE(r.frame(looking_down(glm::dvec3(0.0005, 0, 0)), Scene{}, level(64), nullptr, false));
  EXPECT_TRUE(r.was_skipped("ssrt_tsdf_fuse"));
  // The light moved: the fuse stays skipped but the views are made again.
  ssrt::VolumeFrame lit = level(64);
  lit.direction_to_light = glm::normalize(glm::vec3(1, 1, 0));
  ASSERT_TRUE(r.frame(looking_down(), Scene{}, lit, nullptr, false));
  EXPECT_TRUE(r.was_skipped("ssrt_tsdf_fuse"));
  EXPECT_FALSE(r.was_skipped("ssrt_tsdf_aux"));
  EXPECT_TRUE(r.graph->compiled().runs("ssrt_tsdf_aux"));
  // Moved by 5 cm: fused.
  ASSERT_TRUE(r.frame(looking_down(glm::dvec3(0.05, 0, 0)), Scene{}, lit, nullptr, false));
  EXPECT_TRUE(r.volume->fused_last_frame());
  EXPECT_TRUE(r.graph->compiled().runs("ssrt_tsdf_fuse"));
  // Rotated by 1 degree about the optical axis: fused.
  glm::dmat4 turned = looking_down(glm::dvec3(0.05, 0, 0)) *
                      glm::dmat4(glm::dmat3(glm::rotate(glm::dmat4(1.0), glm::radians(1.0),
                                                        glm::dvec3(0, 0, 1))));
  ASSERT_TRUE(r.frame(turned, Scene{}, lit, nullptr, false));
  EXPECT_TRUE(r.volume->fused_last_frame());
  // Same pose, the scene changed (boxes gone): fused.
  ASSERT_TRUE(r.frame(turned, Scene{0.0f, false}, lit, nullptr, false));
  EXPECT_TRUE(r.volume->fused_last_frame());
  EXPECT_FALSE(r.was_skipped("ssrt_tsdf_fuse"));
}

TEST_F(VulkanTest, VolumeResetsOnResolutionAndCentreChange) {
  Rig r(ctx(), 80, 60, settings(128));
  ASSERT_TRUE(r.volume.has_value());
  for (int f = 0; f < 3; ++f) ASSERT_TRUE(r.frame(looking_down(), Scene{}, level(128), nullptr, false));
  EXPECT_FALSE(r.graph->compiled().runs("ssrt_tsdf_clear"));
  // The 64^3 level with a raised floor and no boxes: without the clear the first 64^3 entries
  // would hold the 128^3 layout's voxels (weights up to 3, other places) and the view would
  // show surfaces that are not there.
  const Scene raised{0.2f, false};
  Truth t;
  ASSERT_TRUE(r.frame(looking_down(), raised, level(64), &t));
  EXPECT_TRUE(r.graph->compiled().runs("ssrt_tsdf_clear"));
  expect_view_matches(r, t, 2.0f / 64.0f, 1.5f, "64^3 after the reset");
  for (int f = 0; f < 2; ++f)
    ASSERT_TRUE(r.frame(looking_down(glm::dvec3(0.01 * f, 0, 0)), raised, level(64), nullptr, false));
  EXPECT_FALSE(r.graph->compiled().runs("ssrt_tsdf_clear"));
  // A centre change resets too: the cube moved 0.25 m down, the same floor. Without the clear
  // the old voxels (weight 3) would be read 0.25 m lower: the floor at -0.05 m and empty space
  // (+1) at 0.2 m outvoting this frame's measurement there.
  ssrt::VolumeFrame moved = level(64);
  moved.center = kCenter + glm::vec3(0.0f, -0.25f, 0.0f);
  ASSERT_TRUE(r.frame(looking_down(), raised, moved, &t));
  EXPECT_TRUE(r.graph->compiled().runs("ssrt_tsdf_clear"));
  expect_view_matches(r, t, 2.0f / 64.0f, 1.5f, "64^3 after the centre moved");
  ASSERT_TRUE(r.frame(looking_down(glm::dvec3(0.02, 0, 0)), raised, moved, nullptr, false));
  EXPECT_FALSE(r.graph->compiled().runs("ssrt_tsdf_clear"));
}

TEST_F(VulkanTest, VolumeMemoryDoesNotGrowOver50Frames) {
  Rig r(ctx(), 80, 60, settings(64, 32));
  ASSERT_TRUE(r.volume.has_value());
  ASSERT_TRUE(r.frame(looking_down(), Scene{}, level(64, 32), nullptr, false));
  ASSERT_TRUE(r.graph->flush().ok());
  const uint64_t before = ctx().allocated_bytes();
  for (int f = 1; f <= 50; ++f) {
    // A moving camera (every frame fused) and a level change half-way.
    const glm::dvec3 offset(0.01 * std::sin(f * 0.3), 0.0, 0.01 * std::cos(f * 0.3));
    ASSERT_TRUE(r.frame(looking_down(offset), Scene{}, level(f < 25 ? 64 : 32, 32), nullptr,
                        f % 10 == 0));
  }
  ASSERT_TRUE(r.graph->flush().ok());
  EXPECT_EQ(ctx().allocated_bytes(), before);
}

TEST_F(VulkanTest, VolumeRefusesBadFramesAndSettings) {
  Rig r(ctx(), 80, 60, settings(64));
  ASSERT_TRUE(r.volume.has_value());
  std::vector<std::string> skipped;
  ssrt::VolumeFrame f = level(128);
  auto st = r.volume->record(f, skipped);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().kind, ErrorKind::BadUsage);
  EXPECT_NE(st.error().message.find("resolution 128"), std::string::npos) << st.error().message;
  f = level(64);
  ImageU16 wrong(10, 10);
  const frame::DepthView wrong_view{wrong.data.data(), wrong.width, wrong.height};
  f.depth = &wrong_view;
  st = r.volume->record(f, skipped);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("depth is 10x10"), std::string::npos) << st.error().message;
  f = level(64);
  f.camera_to_world[3][0] = std::nan("");
  EXPECT_FALSE(r.volume->record(f, skipped).ok());
  f = level(64);
  f.direction_to_light = glm::vec3(0.0f);
  EXPECT_FALSE(r.volume->record(f, skipped).ok());
  ssrt::VolumeSettings bad = settings(64);
  bad.truncation_voxels = 0.5f;
  auto v = ssrt::Volume::create(ctx(), *r.graph, r.shared, bad);
  ASSERT_FALSE(v.ok());
  EXPECT_NE(v.error().message.find("truncation_voxels"), std::string::npos);
}

// GPU ms of the three passes at 640 x 480 (run with --gtest_also_run_disabled_tests and
// LP_NUM_THREADS=2): a moving camera so every frame fuses and ray-casts.
TEST_F(VulkanTest, DISABLED_VolumeGpuTimes640x480) {
  for (uint32_t res : {256u, 64u}) {
    Rig r(ctx(), 640, 480, settings(res, 256));
    ASSERT_TRUE(r.volume.has_value());
    const int frames = 6;
    for (int f = 0; f < frames; ++f)
      ASSERT_TRUE(r.frame(looking_down(glm::dvec3(0.01 * f, 0, 0)), Scene{}, level(res, 256),
                          nullptr, false));
    auto rest = r.graph->flush();
    ASSERT_TRUE(rest.ok());
    for (auto& t : *rest) r.timings.push_back(t);
    std::map<std::string, std::vector<double>> ms;
    for (size_t i = 1; i < r.timings.size(); ++i)  // the first frame also clears
      for (const PassTiming& p : r.timings[i].passes) ms[p.name].push_back(p.gpu_ms);
    for (auto& [name, v] : ms) {
      std::sort(v.begin(), v.end());
      std::printf("volume %u^3 640x480 aux 256: %-20s median %.1f ms (%zu frames)\n", res,
                  name.c_str(), v[v.size() / 2], v.size());
    }
  }
}

}  // namespace

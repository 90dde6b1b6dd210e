// The reconstruction's temporal depth filter (DIR paper section 4.2: warp the previous filtered
// depth into the new view, merge, normals from the merged positions) on lavapipe with
// validation on, driven directly through recon::Reconstruction and a frame graph: a tilted
// plane with seeded Kinect-like depth noise, a static camera, then a large pose change.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include <algorithm>
#include <cstdio>
#include <optional>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/packing.hpp>

#include "../../shaders/common/frame_constants.glsl"
#include "gpu/frame_graph.h"
#include "recon/reconstruction.h"
#include "vulkan/vk_test_util.h"
#include "common/frame_constants_for.h"

namespace mrgi::test {
namespace {

using gpu::Access;
using gpu::BufferHandle;
using gpu::ImageHandle;
using gpu::PassKind;

constexpr int W = 80, H = 60;
constexpr double kDepthScale = 5000.0;

Intrinsics camera() {
  Intrinsics k;
  k.width = W;
  k.height = H;
  k.fx = k.fy = 70.0;
  k.cx = 0.5 * W - 0.5;
  k.cy = 0.5 * H - 0.5;
  return k;
}

// World: a plane n.x = d facing the camera, tilted 35 degrees about x, 2 m in front of the
// origin; optionally a box-like occluder (a plane patch 0.8 m nearer) over part of the view.
const glm::dvec3 kPlaneNormal = glm::normalize(glm::dvec3(0.0, -std::sin(0.61), -std::cos(0.61)));
constexpr double kPlaneD = -2.0;  // n.x = d at the point (0, 0, 2/cos) ...

struct Truth {
  double depth = 0.0;  // along the camera's optical axis, metres; 0 = no surface
  glm::dvec3 normal{0.0};
};

// The surface seen through pixel (u, v) of a camera at `pose` (camera-to-world).
Truth trace(const glm::dmat4& pose, int u, int v, bool with_occluder) {
  const Intrinsics k = camera();
  const glm::dvec3 ray_cam((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
  const glm::dvec3 origin(pose[3]);
  const glm::dvec3 dir = glm::dmat3(pose) * ray_cam;  // z component 1 in camera space
  Truth t;
  const double denom = glm::dot(kPlaneNormal, dir);
  if (std::abs(denom) > 1e-9) {
    const double s = (kPlaneD - glm::dot(kPlaneNormal, origin)) / denom;
    if (s > 0.0) t = {s, kPlaneNormal};
  }
  if (with_occluder) {  // world plane z = 1.2 for x in [-0.6, 0]
    const double s = (1.2 - origin.z) / dir.z;
    const glm::dvec3 p = origin + s * dir;
    if (s > 0.0 && p.x >= -0.6 && p.x <= 0.0 && (t.depth == 0.0 || s < t.depth))
      t = {s, glm::dvec3(0, 0, -1)};
  }
  return t;
}

// Kinect-like noise (Nguyen et al. 2012 axial model) plus quantisation to depth units.
InputFrame noisy_frame(const glm::dmat4& pose, bool with_pose, bool with_occluder,
                       std::mt19937& rng) {
  InputFrame f;
  f.color = ImageRGB8(W, H, 128);
  f.depth = ImageU16(W, H, 0);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const Truth t = trace(pose, u, v, with_occluder);
      if (t.depth <= 0.0) continue;
      const double sigma = 0.0012 + 0.0019 * (t.depth - 0.4) * (t.depth - 0.4);
      const double z = t.depth + std::normal_distribution<double>(0.0, sigma)(rng);
      *f.depth.at(u, v) = uint16_t(std::clamp(std::lround(z * kDepthScale), 1L, 65535L));
    }
  if (with_pose) {
    Pose p;
    p.translation = glm::dvec3(pose[3]);
    p.rotation = glm::quat_cast(glm::dmat3(pose));
    f.pose = p;
  }
  return f;
}

struct Result {
  std::vector<glm::vec3> normal;   // world
  std::vector<glm::vec2> depth;    // filtered depth (m), weight
};

class ReconFilterTest : public VulkanTest {
 protected:
  void start(const recon::ReconstructionSettings& settings) {
    gpu::FrameGraphSettings fs;
    fs.max_output_width = W;
    fs.max_output_height = H;
    fs.frames_in_flight = 1;
    auto g = gpu::FrameGraph::create(ctx(), fs);
    ASSERT_TRUE(g.ok()) << g.error().message;
    graph_ = std::move(*g);
    ASSERT_TRUE(graph_->set_output_size(W, H).ok());
    auto fc = graph_->create_buffer({"frame_constants", sizeof(shader::FrameConstants),
                                     gpu::MemoryUsage::Upload, true},
                                    VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    ASSERT_TRUE(fc.ok());
    constants_ = *fc;
    for (BufferHandle* b : {&normal_rb_, &depth_rb_}) {
      auto rb = graph_->create_buffer({b == &normal_rb_ ? "rb_normal" : "rb_depth", W * H * 8,
                                       gpu::MemoryUsage::Readback, true},
                                      VK_BUFFER_USAGE_TRANSFER_DST_BIT);
      ASSERT_TRUE(rb.ok());
      *b = *rb;
    }
    auto r = recon::Reconstruction::create(ctx(), *graph_, camera(), camera(), settings);
    ASSERT_TRUE(r.ok()) << r.error().message;
    recon_.emplace(std::move(*r));
  }

  // One frame; `pose` is what the runtime's constants would hold (the last known pose).
  Result frame(const InputFrame& input, const glm::dmat4& pose) {
    auto begun = graph_->begin_frame();
    EXPECT_TRUE(begun.ok()) << begun.error().message;
    const Intrinsics k = camera();
    const glm::vec4 kk(float(k.fx), float(k.fy), float(k.cx), float(k.cy));
    const shader::FrameConstants fc =
        mrgi::test::pinhole_frame_constants(glm::mat4(pose), kk, int(W), int(H), float(kDepthScale));
    std::memcpy(graph_->mapped(constants_, graph_->slot()), &fc, sizeof(fc));
    recon_->take_input(input, nullptr);
    recon_->copy_host_input(*graph_, input);
    recon_->record(*graph_, constants_);
    for (const auto& image_and_buffer : {std::pair{recon_->normal(), normal_rb_},
                                         std::pair{recon_->filtered_depth(), depth_rb_}}) {
      // Named copies, not a structured binding: clang 14 (the sanitizer build) cannot capture one.
      const auto img = image_and_buffer.first;
      const auto buf = image_and_buffer.second;
      graph_->add_pass(
          "readback_" + graph_->name(img), PassKind::Transfer,
          [img, buf](gpu::PassBuilder& b) {
            b.read(img, Access::TransferSrc);
            b.write(buf, Access::TransferDst);
          },
          [img, buf](VkCommandBuffer cmd, gpu::PassContext& pc) {
            VkBufferImageCopy region{};
            region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
            region.imageExtent = {W, H, 1};
            vkCmdCopyImageToBuffer(cmd, pc.image(img), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                   pc.buffer(buf), 1, &region);
          });
      graph_->mark_output(buf);
    }
    EXPECT_TRUE(graph_->compile().ok());
    const uint32_t slot = graph_->slot();
    const Status sub = graph_->submit();
    EXPECT_TRUE(sub.ok()) << sub.error().message;
    auto done = graph_->flush();
    EXPECT_TRUE(done.ok()) << done.error().message;
    Result r;
    r.normal.resize(size_t(W) * H);
    r.depth.resize(size_t(W) * H);
    EXPECT_TRUE(ctx().invalidate(graph_->gpu_buffer(normal_rb_, slot)).ok());
    EXPECT_TRUE(ctx().invalidate(graph_->gpu_buffer(depth_rb_, slot)).ok());
    const auto* n = static_cast<const uint16_t*>(graph_->mapped(normal_rb_, slot));
    const auto* d = static_cast<const float*>(graph_->mapped(depth_rb_, slot));
    for (size_t i = 0; i < r.normal.size(); ++i) {
      r.normal[i] = glm::vec3(glm::unpackHalf1x16(n[i * 4]), glm::unpackHalf1x16(n[i * 4 + 1]),
                              glm::unpackHalf1x16(n[i * 4 + 2]));
      r.depth[i] = glm::vec2(d[i * 2], d[i * 2 + 1]);
    }
    return r;
  }

  std::unique_ptr<gpu::FrameGraph> graph_;
  std::optional<recon::Reconstruction> recon_;
  BufferHandle constants_, normal_rb_, depth_rb_;
};

// Mean angle (degrees) between the reconstructed and the true normals, 3-pixel border left out.
double mean_normal_error_deg(const Result& r, const glm::dmat4& pose, bool with_occluder) {
  double sum = 0.0;
  int n = 0;
  for (int v = 3; v < H - 3; ++v)
    for (int u = 3; u < W - 3; ++u) {
      const Truth t = trace(pose, u, v, with_occluder);
      const glm::vec3 got = r.normal[size_t(v) * W + u];
      if (t.depth <= 0.0 || glm::length(got) < 0.5f) continue;
      const double c = std::clamp(glm::dot(glm::normalize(glm::dvec3(got)), t.normal), -1.0, 1.0);
      sum += std::acos(c) * 180.0 / 3.14159265358979;
      ++n;
    }
  EXPECT_GT(n, W * H / 2);
  return n > 0 ? sum / n : 180.0;
}

recon::ReconstructionSettings raw_settings() {  // reconstruction v0: no filtering at all
  recon::ReconstructionSettings s;
  s.temporal = false;
  s.median = false;
  s.normal_radius = 1;
  return s;
}

TEST_F(ReconFilterTest, StaticCameraConvergesToMuchBetterNormalsThanRawDepth) {
  const glm::dmat4 pose(1.0);
  std::vector<InputFrame> frames;
  std::mt19937 rng(12345);
  // Every third frame has no pose: the filter must treat it as not moved.
  for (int i = 0; i < 12; ++i) frames.push_back(noisy_frame(pose, i % 3 != 2, false, rng));

  start(raw_settings());
  double raw_error = 0.0;
  for (const InputFrame& f : frames) raw_error += mean_normal_error_deg(frame(f, pose), pose, false);
  raw_error /= double(frames.size());

  start({});
  std::vector<double> filtered;
  Result last;
  for (const InputFrame& f : frames) {
    last = frame(f, pose);
    filtered.push_back(mean_normal_error_deg(last, pose, false));
  }
  // The spatial step alone already helps on the first frame; the history keeps helping.
  EXPECT_LT(filtered.front(), 0.7 * raw_error);
  EXPECT_LT(filtered.back(), 0.5 * filtered.front());
  EXPECT_LT(filtered.back(), 0.25 * raw_error);
  // Converged: the weight reached the cap everywhere it could.
  int capped = 0;
  for (const glm::vec2& d : last.depth) capped += d.y >= 11.5f ? 1 : 0;
  EXPECT_GT(capped, W * H * 9 / 10);
  std::printf("normal error: raw %.2f deg, filtered frame 1 %.2f deg, frame 12 %.2f deg\n",
              raw_error, filtered.front(), filtered.back());
}

TEST_F(ReconFilterTest, LargePoseChangeFollowsTheNewFrameAndKeepsHistoryWhereItMatches) {
  std::mt19937 rng(777);
  const glm::dmat4 first(1.0);
  start({});
  for (int i = 0; i < 8; ++i) frame(noisy_frame(first, true, false, rng), first);
  // Move 0.35 m sideways and 0.3 m forward, turn 8 degrees, and let a nearer surface appear.
  glm::dmat4 moved = glm::rotate(glm::dmat4(1.0), -0.14, glm::dvec3(0, 1, 0));
  moved[3] = glm::dvec4(0.35, 0.0, 0.3, 1.0);
  const Result r = frame(noisy_frame(moved, true, true, rng), moved);
  int plane = 0, plane_kept = 0, occluder = 0, bad = 0;
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const Truth t = trace(moved, u, v, true);
      const glm::vec2 got = r.depth[size_t(v) * W + u];
      if (t.depth <= 0.0 || got.x <= 0.0f) continue;
      const double sigma = 0.0012 + 0.0019 * (t.depth - 0.4) * (t.depth - 0.4);
      if (std::abs(got.x - t.depth) > 4.0 * sigma) ++bad;  // smeared or wrongly warped
      if (t.normal.z == -1.0) {
        ++occluder;
        EXPECT_EQ(got.y, 1.0f) << "a new surface starts a new average at " << u << "," << v;
      } else {
        ++plane;
        plane_kept += got.y > 1.5f ? 1 : 0;
      }
    }
  EXPECT_GT(occluder, W * H / 10);
  EXPECT_LT(bad, W * H / 100);
  // The plane was seen before: where the warp brings it back, the history is used. A wrong
  // pose change would land it off the plane and restart the average everywhere.
  EXPECT_GT(plane_kept, plane * 7 / 10);
}

// A camera sliding sideways every frame (the suite's desk_spot moves about 5 pixels a frame at
// 640x480) over a Kinect-like sensor's quantised depth: the filtered surface must not drift and
// its error must not grow with the motion. (A warp that splatted each point with a plane through
// it and two neighbours extrapolated the staircase's steps: 5 mm rms at frame 5, 15 mm at frame
// 24, worse than the raw sensor; on desk_spot the floor came out rippled and shadowed itself in
// the real casters' shadow map.)
TEST_F(ReconFilterTest, SlidingCameraDoesNotDriftTheSurface) {
  const double kStep = 0.05;  // metres a frame: 1.75 pixels at the plane (80 px, fx 70, 2 m)
  std::mt19937 rng(4242);
  start({});
  double first_rms = 0.0, last_rms = 0.0, last_mean = 0.0, sigma_mean = 0.0;
  for (int i = 0; i < 24; ++i) {
    glm::dmat4 pose(1.0);
    pose[3] = glm::dvec4(kStep * i, 0.0, 0.0, 1.0);
    InputFrame in = noisy_frame(pose, true, false, rng);
    // Kinect-like disparity steps (the suite's sensor model: 1/8 pixel at 580 px and 7.5 cm).
    for (uint16_t& d : in.depth.data) {
      if (d == 0) continue;
      const double z = d / kDepthScale, disparity = 0.075 * 580.0 / z;
      d = uint16_t(std::lround(0.075 * 580.0 / (std::round(disparity * 8.0) / 8.0) * kDepthScale));
    }
    const Result r = frame(in, pose);
    double sum = 0.0, sum2 = 0.0, sig = 0.0;
    int n = 0;
    for (int v = 3; v < H - 3; ++v)
      for (int u = 3; u < W - 3; ++u) {
        const Truth t = trace(pose, u, v, false);
        const glm::vec2 got = r.depth[size_t(v) * W + u];
        if (t.depth <= 0.0 || got.x <= 0.0f) continue;
        const double e = double(got.x) - t.depth;
        sum += e;
        sum2 += e * e;
        sig += 0.0012 + 0.0019 * (t.depth - 0.4) * (t.depth - 0.4);
        ++n;
      }
    ASSERT_GT(n, W * H / 2);
    const double rms = std::sqrt(sum2 / n);
    if (i == 4) first_rms = rms;
    if (i == 23) {
      last_rms = rms;
      last_mean = sum / n;
      sigma_mean = sig / n;
    }
  }
  std::printf("sliding camera: rms %.3f mm at frame 5, %.3f mm at frame 24 (mean %+.3f mm, sensor sigma %.3f mm)\n",
              first_rms * 1e3, last_rms * 1e3, last_mean * 1e3, sigma_mean * 1e3);
  EXPECT_LT(std::abs(last_mean), 0.1 * sigma_mean);  // no drift
  EXPECT_LT(last_rms, 1.2 * first_rms);               // the error does not grow with motion
  EXPECT_LT(last_rms, 0.6 * sigma_mean);              // and the history still averages noise out
}

// The 3x3 same-surface median (depth_to_positions.comp, a sorting network with fillers for the
// neighbours that do not count) against a plain CPU reference: the valid same-surface
// neighbours sorted, element n / 2; the centre itself when fewer than 3 count; holes stay holes.
// Random depths on two surfaces (1.0 and 1.5 m, +-2 %) with 25 % holes exercise every count.
TEST_F(ReconFilterTest, MedianEqualsTheSortedSameSurfaceNeighbours) {
  recon::ReconstructionSettings settings;
  settings.temporal = false;
  start(settings);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  InputFrame f;
  f.color = ImageRGB8(W, H, 128);
  f.depth = ImageU16(W, H, 0);
  for (int v = 0; v < H; ++v)
    for (int x = 0; x < W; ++x) {
      if (u(rng) < 0.25) continue;
      const double z = (u(rng) < 0.5 ? 1.0 : 1.5) * (0.98 + 0.04 * u(rng));
      *f.depth.at(x, v) = uint16_t(std::lround(z * kDepthScale));
    }
  const Result r = frame(f, glm::dmat4(1.0));
  int checked = 0, by_count[10] = {};
  for (int v = 0; v < H; ++v)
    for (int x = 0; x < W; ++x) {
      const uint32_t c = *f.depth.at(x, v);
      uint32_t expect = 0;
      if (c != 0) {
        std::vector<uint32_t> same;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int qx = x + dx, qy = v + dy;
            if (qx < 0 || qy < 0 || qx >= W || qy >= H) continue;
            const uint32_t d = *f.depth.at(qx, qy);
            if (d == 0 || std::abs(double(d) - double(c)) > 0.05 * double(std::min(d, c))) continue;
            same.push_back(d);
          }
        std::sort(same.begin(), same.end());
        expect = same.size() < 3 ? c : same[same.size() / 2];
        ++by_count[same.size()];
      }
      const float got = r.depth[size_t(v) * W + x].x;
      ASSERT_NEAR(got, float(expect / kDepthScale), 1e-6f) << "pixel " << x << "," << v;
      ++checked;
    }
  EXPECT_EQ(checked, W * H);
  for (int n = 1; n <= 8; ++n) EXPECT_GT(by_count[n], 0) << n << " same-surface neighbours";
}

TEST_F(ReconFilterTest, SettingsOutOfRangeAreRefusedWithTheFieldName) {
  gpu::FrameGraphSettings fs;
  auto g = gpu::FrameGraph::create(ctx(), fs);
  ASSERT_TRUE(g.ok());
  recon::ReconstructionSettings s;
  s.max_weight = 300.0f;
  auto r = recon::Reconstruction::create(ctx(), **g, camera(), camera(), s);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("max_weight"), std::string::npos);
  s = {};
  s.normal_radius = 0;
  r = recon::Reconstruction::create(ctx(), **g, camera(), camera(), s);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("normal_radius"), std::string::npos);
}

}  // namespace
}  // namespace mrgi::test

#include "technique/ssrt/volume.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "common/frame_constants.glsl"
#include "ssrt/tsdf_volume.glsl"
#include "recon/reconstruction.h"

namespace mrgi::ssrt {
namespace {

constexpr uint32_t kMaxResolution = 1024;      // 4 GiB of voxels beyond this
constexpr uint32_t kMaxAuxResolution = 4096;
constexpr float kMaxWeightLimit = 2048.0f;     // largest integer a half float holds exactly
constexpr double kValidCountTolerance = 0.01;  // the skip's "valid-pixel count within 1 %"

bool finite(const glm::dmat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

// Rotation angle (degrees) between the rotation parts of two poses.
double rotation_deg(const glm::dmat4& a, const glm::dmat4& b) {
  const glm::dmat3 rel = glm::transpose(glm::dmat3(a)) * glm::dmat3(b);
  const double c = std::clamp((rel[0][0] + rel[1][1] + rel[2][2] - 1.0) * 0.5, -1.0, 1.0);
  return std::acos(c) * 180.0 / 3.14159265358979323846;
}

}  // namespace

Expected<Volume> Volume::create(gpu::Context& ctx, gpu::FrameGraph& graph,
                                const frame::FrameResources& shared,
                                const VolumeSettings& s) {
  const std::string where = "ssrt volume settings: ";
  if (s.max_resolution < 2 || s.max_resolution > kMaxResolution)
    return fail(ErrorKind::BadUsage, where + "max_resolution " + std::to_string(s.max_resolution) +
                                         " outside 2.." + std::to_string(kMaxResolution));
  if (s.max_aux_resolution < 1 || s.max_aux_resolution > kMaxAuxResolution)
    return fail(ErrorKind::BadUsage, where + "max_aux_resolution " +
                                         std::to_string(s.max_aux_resolution) + " outside 1.." +
                                         std::to_string(kMaxAuxResolution));
  if (!(s.size_m > 0.0f) || !std::isfinite(s.size_m))
    return fail(ErrorKind::BadUsage, where + "size_m must be positive and finite");
  if (!(s.truncation_voxels >= 1.0f) || !std::isfinite(s.truncation_voxels))
    return fail(ErrorKind::BadUsage, where + "truncation_voxels must be at least 1 voxel");
  if (!(s.max_weight >= 1.0f && s.max_weight <= kMaxWeightLimit))
    return fail(ErrorKind::BadUsage, where + "max_weight must lie in 1..2048 frames (half float)");
  if (!(s.pose_tolerance_m >= 0.0) || !(s.pose_tolerance_deg >= 0.0) ||
      !(s.depth_tolerance_m >= 0.0))
    return fail(ErrorKind::BadUsage, where + "tolerances must be non-negative numbers");
  if (!shared.depth_upload.valid() || !shared.frame_constants.valid())
    return fail(ErrorKind::BadUsage,
                "ssrt volume: shared resources lack depth_upload or frame_constants");
  MRGI_TRY(recon::check_camera_upload(graph, shared.depth_upload, "ssrt volume"));
  const Intrinsics& dk = shared.depth_intrinsics;
  if (dk.width <= 0 || dk.height <= 0 || !(dk.fx > 0.0) || !(dk.fy > 0.0) ||
      !(shared.depth_scale > 0.0))
    return fail(ErrorKind::BadUsage, "ssrt volume: depth intrinsics need a positive size and "
                                     "focal lengths, depth_scale must be positive");

  Volume v;
  v.settings_ = s;
  v.shared_ = shared;
  v.graph_ = &graph;
  // A storage buffer the fuse pass writes, read through an R32_UINT texel view (tsdf_volume.glsl
  // says why: on lavapipe the ray cast 6.5 -> 3.0 ms at the fast level on desk_spot).
  gpu::BufferDesc vd{"ssrt_tsdf_voxels",
                     VkDeviceSize(s.max_resolution) * s.max_resolution * s.max_resolution *
                         sizeof(uint32_t),
                     gpu::MemoryUsage::DeviceLocal, false, /*history=*/true};
  vd.texel_format = VK_FORMAT_R32_UINT;
  auto voxels = graph.create_buffer(vd, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                            VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  if (!voxels) return voxels.error();
  v.voxels_ = *voxels;
  auto params = graph.create_buffer(
      {"ssrt_volume_params", sizeof(shader::SsrtVolumeParams), gpu::MemoryUsage::Upload, true},
      VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  if (!params) return params.error();
  v.params_ = *params;
  auto views = graph.create_buffer(
      {"ssrt_aux_views", sizeof(shader::SsrtAuxViews), gpu::MemoryUsage::Upload, true},
      VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  if (!views) return views.error();
  v.aux_views_ = *views;

  // Persistent: a frame that skips the ray-casts keeps the previous frame's views.
  const VkImageUsageFlags usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                                  VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  gpu::ImageDesc dd;
  dd.name = "ssrt_depth_volume";
  dd.format = VK_FORMAT_R32_SFLOAT;
  dd.history = true;
  auto depth = graph.create_image(dd, usage);
  if (!depth) return depth.error();
  v.depth_volume_ = *depth;
  gpu::ImageDesc nd = dd;
  nd.name = "ssrt_normal_volume";
  nd.format = VK_FORMAT_R16G16B16A16_SFLOAT;
  // Not persistent: a history image's last write is never culled, and nothing in the frame
  // reads N_v (tsdf_normals.comp); a reader gets it on frames that ray-cast.
  nd.history = false;
  auto normal = graph.create_image(nd, usage);
  if (!normal) return normal.error();
  v.normal_volume_ = *normal;
  gpu::ImageDesc ad;
  ad.name = "ssrt_aux_position";
  ad.format = VK_FORMAT_R32G32B32A32_SFLOAT;
  ad.size_mode = gpu::SizeMode::Absolute;
  ad.width = ad.height = s.max_aux_resolution;
  ad.layers = SSRT_AUX_LAYERS;
  ad.history = true;
  auto aux = graph.create_image(ad, usage);
  if (!aux) return aux.error();
  v.aux_position_ = *aux;

  // Layouts come from the shaders (gpu/reflect.h); the passes bind by name.
  auto p = gpu::load_compute_pipeline(ctx, "ssrt/tsdf_fuse.comp", {});
  if (!p) return p.error();
  v.fuse_ = std::move(*p);
  p = gpu::load_compute_pipeline(ctx, "ssrt/tsdf_raycast.comp", {});
  if (!p) return p.error();
  v.raycast_ = std::move(*p);
  p = gpu::load_compute_pipeline(ctx, "ssrt/tsdf_normals.comp", {});
  if (!p) return p.error();
  v.normals_ = std::move(*p);
  p = gpu::load_compute_pipeline(ctx, "ssrt/tsdf_aux.comp", {});
  if (!p) return p.error();
  v.aux_ = std::move(*p);

  v.last_depth_ = ImageU16(dk.width, dk.height);
  return v;
}

Status Volume::validate(const VolumeFrame& f) const {
  const std::string where = "ssrt volume frame: ";
  if (f.resolution < 2 || f.resolution > settings_.max_resolution)
    return fail(ErrorKind::BadUsage, where + "resolution " + std::to_string(f.resolution) +
                                         " outside 2..max_resolution " +
                                         std::to_string(settings_.max_resolution));
  if (f.aux_resolution < 1 || f.aux_resolution > settings_.max_aux_resolution)
    return fail(ErrorKind::BadUsage, where + "aux_resolution " + std::to_string(f.aux_resolution) +
                                         " outside 1..max_aux_resolution " +
                                         std::to_string(settings_.max_aux_resolution));
  if (!std::isfinite(f.center.x) || !std::isfinite(f.center.y) || !std::isfinite(f.center.z))
    return fail(ErrorKind::BadUsage, where + "center is not finite");
  if (!finite(f.camera_to_world))
    return fail(ErrorKind::BadUsage, where + "camera_to_world is not finite");
  const float l = glm::length(f.direction_to_light);
  if (!std::isfinite(l) || !(l > 1e-6f))
    return fail(ErrorKind::BadUsage, where + "direction_to_light must be a finite non-zero vector");
  if (f.depth && (f.depth->width != last_depth_.width || f.depth->height != last_depth_.height ||
                  f.depth->size() != last_depth_.data.size()))
    return fail(ErrorKind::BadUsage,
                where + "depth is " + std::to_string(f.depth->width) + "x" +
                    std::to_string(f.depth->height) + ", the depth intrinsics say " +
                    std::to_string(last_depth_.width) + "x" + std::to_string(last_depth_.height));
  return ok_status();
}

bool Volume::unchanged_since_last_fuse(const VolumeFrame& f) const {
  if (!has_fused_ || !last_depth_valid_ || !f.depth) return false;
  const glm::dvec3 moved = glm::dvec3(f.camera_to_world[3]) - glm::dvec3(last_fused_pose_[3]);
  if (glm::length(moved) >= settings_.pose_tolerance_m) return false;
  if (rotation_deg(last_fused_pose_, f.camera_to_world) >= settings_.pose_tolerance_deg)
    return false;
  const uint16_t* a = last_depth_.data.data();
  const uint16_t* b = f.depth->data;
  const size_t n = last_depth_.data.size();
  size_t valid_a = 0, valid_b = 0, both = 0;
  uint64_t sum_abs = 0;  // depth units
  for (size_t i = 0; i < n; ++i) {
    const bool va = a[i] != 0, vb = b[i] != 0;
    valid_a += va;
    valid_b += vb;
    if (va && vb) {
      ++both;
      sum_abs += uint64_t(std::abs(int(a[i]) - int(b[i])));
    }
  }
  const double count_diff = std::abs(double(valid_a) - double(valid_b));
  if (count_diff > kValidCountTolerance * double(std::max<size_t>(valid_a, 1))) return false;
  if (both == 0) return valid_a == 0 && valid_b == 0;
  const double mean_m = double(sum_abs) / double(both) / shared_.depth_scale;
  return mean_m < settings_.depth_tolerance_m;
}

shader::SsrtAuxViews Volume::make_views(const VolumeFrame& f) const {
  shader::SsrtAuxViews v{};
  const glm::dmat4& c2w = f.camera_to_world;
  const glm::dvec3 cam(c2w[3]);
  const glm::dvec3 x = glm::normalize(glm::dvec3(c2w[0]));
  const glm::dvec3 y = glm::normalize(glm::dvec3(c2w[1]));
  const glm::dvec3 z = glm::normalize(glm::dvec3(c2w[2]));
  const glm::dvec3 centre(f.center);
  const double size = settings_.size_m;
  const double sqrt3 = std::sqrt(3.0);
  const glm::dvec3 light = glm::normalize(glm::dvec3(f.direction_to_light));
  // Each layer as an OpenCV-style camera (right x down = forward): forward, right, down.
  glm::dvec3 fwd[4] = {-x, x, -y, -light};
  glm::dvec3 right[4] = {z, -z, x, {}};
  const glm::dvec3 helper = std::abs(light.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
  right[3] = glm::normalize(glm::cross(fwd[3], helper));
  for (int i = 0; i < SSRT_AUX_LAYERS; ++i) {
    const glm::dvec3 down = glm::cross(fwd[i], right[i]);
    // Image plane centre: layers 0-2 on the plane through the camera centre, at the projection
    // of the cube centre; the light layer outside the cube's bounding sphere towards the light.
    const bool is_light = i == SSRT_AUX_LIGHT;
    const double side = is_light ? size * sqrt3 : size;
    const glm::dvec3 p = is_light ? centre + light * (size * sqrt3 * 0.5)
                                  : centre - fwd[i] * glm::dot(centre - cam, fwd[i]);
    glm::dmat4 w2a(0.0);  // rows u, v, depth, 1 (glm is column-major: m[col][row])
    for (int c = 0; c < 3; ++c) {
      w2a[c][0] = right[i][c] / side;
      w2a[c][1] = down[c] / side;
      w2a[c][2] = fwd[i][c];
    }
    w2a[3][0] = -glm::dot(p, right[i]) / side + 0.5;
    w2a[3][1] = -glm::dot(p, down) / side + 0.5;
    w2a[3][2] = -glm::dot(p, fwd[i]);
    w2a[3][3] = 1.0;
    glm::dmat4 a2w(1.0);
    a2w[0] = glm::dvec4(right[i] * side, 0.0);
    a2w[1] = glm::dvec4(down * side, 0.0);
    a2w[2] = glm::dvec4(fwd[i], 0.0);
    a2w[3] = glm::dvec4(p - 0.5 * side * (right[i] + down), 1.0);
    double exit_depth = 0.0;  // farthest cube corner along the axis
    for (int k = 0; k < 8; ++k) {
      const glm::dvec3 corner =
          centre + 0.5 * size * glm::dvec3(k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1);
      exit_depth = std::max(exit_depth, glm::dot(corner - p, fwd[i]));
    }
    v.world_to_aux[i] = glm::mat4(w2a);
    v.aux_to_world[i] = glm::mat4(a2w);
    v.direction[i] = glm::vec4(glm::vec3(fwd[i]), 0.0f);
    v.extent[i] = glm::vec4(float(side), float(side), float(side / f.aux_resolution),
                            float(exit_depth));
  }
  v.info = glm::ivec4(SSRT_AUX_LAYERS, int(f.aux_resolution), int(settings_.max_aux_resolution), 0);
  return v;
}

void Volume::write_params(const VolumeFrame& f) {
  shader::SsrtVolumeParams p{};
  p.camera_to_world = glm::mat4(f.camera_to_world);
  p.world_to_camera = glm::mat4(glm::inverse(f.camera_to_world));
  const float voxel = settings_.size_m / float(f.resolution);
  p.origin = glm::vec4(f.center - glm::vec3(0.5f * settings_.size_m), voxel);
  p.tsdf = glm::vec4(settings_.truncation_voxels * voxel, settings_.max_weight,
                     float(shared_.depth_scale), settings_.size_m);
  const Intrinsics& dk = shared_.depth_intrinsics;
  p.depth_k = glm::vec4(float(dk.fx), float(dk.fy), float(dk.cx), float(dk.cy));
  p.grid = glm::ivec4(int(f.resolution), dk.width, dk.height, int(f.aux_resolution));
  const uint32_t slot = graph_->slot();
  std::memcpy(graph_->mapped(params_, slot), &p, sizeof(p));
  std::memcpy(graph_->mapped(aux_views_, slot), &views_, sizeof(views_));
}

Status Volume::record(const VolumeFrame& frame, std::vector<std::string>& skipped) {
  MRGI_TRY(validate(frame));
  const bool reset = frame.resolution != resolution_ || frame.center != center_;
  const bool fuse = reset || !unchanged_since_last_fuse(frame);
  const auto* fc = static_cast<const shader::FrameConstants*>(
      graph_->mapped(shared_.frame_constants, graph_->slot()));
  ViewKey key;
  key.aux_resolution = frame.aux_resolution;
  key.direction_to_light = frame.direction_to_light;
  key.internal_k = fc->internal_k;
  key.internal_size = glm::ivec2(fc->internal_output_size.x, fc->internal_output_size.y);
  const bool views = fuse || !views_valid_ || !(key == view_key_);
  // The aux layers' views are those of the frame that ray-casts them: a skipped frame hands on
  // the views its persistent images were made with.
  if (views) views_ = make_views(frame);
  write_params(frame);
  add_passes(frame, reset, fuse, views);
  if (!fuse) skipped.push_back("ssrt_tsdf_fuse: pose and depth unchanged since the last fused frame");
  if (!views) {
    const char* why = ": volume, pose, light and sizes unchanged since the last ray-cast";
    skipped.push_back(std::string("ssrt_tsdf_raycast") + why);
    skipped.push_back(std::string("ssrt_tsdf_aux") + why);
  }
  if (fuse) {
    has_fused_ = true;
    last_fused_pose_ = frame.camera_to_world;
    last_depth_valid_ = frame.depth != nullptr;
    if (frame.depth) std::copy(frame.depth->data, frame.depth->data + frame.depth->size(), last_depth_.data.begin());
  }
  resolution_ = frame.resolution;
  center_ = frame.center;
  if (views) {
    views_valid_ = true;
    view_key_ = key;
  }
  fused_last_frame_ = fuse;
  return ok_status();
}

void Volume::add_passes(const VolumeFrame& frame, bool clear, bool fuse, bool views) {
  gpu::FrameGraph& graph = *graph_;
  const uint32_t res = frame.resolution, aux_res = frame.aux_resolution;
  if (clear) {
    graph.add_pass(
        "ssrt_tsdf_clear", gpu::PassKind::Transfer,
        [this](gpu::PassBuilder& b) { b.write(voxels_, gpu::Access::TransferDst); },
        [this, res](VkCommandBuffer cmd, gpu::PassContext& pass) {
          // 0 = packHalf2x16(tsdf 0, weight 0): never observed.
          vkCmdFillBuffer(cmd, pass.buffer(voxels_), 0,
                          VkDeviceSize(res) * res * res * sizeof(uint32_t), 0u);
        });
  }
  if (fuse) {
    graph.add_shader_pass(
        "ssrt_tsdf_fuse", gpu::PassKind::Compute, *fuse_,
        [this](gpu::ShaderPassBuilder& b) {
          b.bind("VolumeUbo", params_);
          b.bind("depth_words", shared_.depth_upload);
          b.bind("Voxels", voxels_);
        },
        [this, res](VkCommandBuffer cmd, gpu::PassContext&) { gpu::dispatch_2d(cmd, *fuse_, nullptr, 0, res, res); });
  }
  if (!views) return;
  graph.add_shader_pass(
      "ssrt_tsdf_raycast", gpu::PassKind::Compute, *raycast_,
      [this](gpu::ShaderPassBuilder& b) {
        b.bind("FrameUbo", shared_.frame_constants);
        b.bind("VolumeUbo", params_);
        b.bind("voxels", voxels_);
        b.bind("depth_volume", depth_volume_);
      },
      [this](VkCommandBuffer cmd, gpu::PassContext& pass) {
        const VkExtent2D e = pass.extent(depth_volume_);
        gpu::dispatch_2d(cmd, *raycast_, nullptr, 0, e.width, e.height);
      });
  // Culled by the graph unless something reads N_v (tsdf_normals.comp says why).
  graph.add_shader_pass(
      "ssrt_tsdf_normals", gpu::PassKind::Compute, *normals_,
      [this](gpu::ShaderPassBuilder& b) {
        b.bind("FrameUbo", shared_.frame_constants);
        b.bind("VolumeUbo", params_);
        b.bind("voxels", voxels_);
        b.bind("depth_volume", depth_volume_);
        b.bind("normal_volume", normal_volume_);
      },
      [this](VkCommandBuffer cmd, gpu::PassContext& pass) {
        const VkExtent2D e = pass.extent(normal_volume_);
        gpu::dispatch_2d(cmd, *normals_, nullptr, 0, e.width, e.height);
      });
  graph.add_shader_pass(
      "ssrt_tsdf_aux", gpu::PassKind::Compute, *aux_,
      [this](gpu::ShaderPassBuilder& b) {
        b.bind("VolumeUbo", params_);
        b.bind("AuxUbo", aux_views_);
        b.bind("voxels", voxels_);
        b.bind("aux_position", aux_position_);
      },
      [this, aux_res](VkCommandBuffer cmd, gpu::PassContext&) {
        // The layers stacked along y: rows [i aux_res, (i + 1) aux_res) are layer i.
        gpu::dispatch_2d(cmd, *aux_, nullptr, 0, aux_res, aux_res * SSRT_AUX_LAYERS);
      });
}

}  // namespace mrgi::ssrt

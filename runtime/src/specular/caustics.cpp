#include "specular/caustics.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "gi/rsm.h"
#include "gpu/shaders.h"
#include "shared/specular_math.h"
#include "specular/mesh_raster.h"
#include "specular/caustic_receiver.glsl"
#include "specular/photon.glsl"
#include "frame/scene_gpu.h"

namespace mrgi::specular {
namespace {

constexpr VkFormat kPhotonPositionFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkFormat kPhotonNormalFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kCausticFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kLitFormat = VK_FORMAT_R16G16B16A16_SFLOAT;  // the runtime's lit_rv
constexpr VkFormat kPhotonDepthFormat = VK_FORMAT_D32_SFLOAT;
// Receiver maps: float sums of many photons' irradiance (a caustic's core holds thousands).
constexpr VkFormat kReceiverFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkDeviceSize kPhotonBytes = sizeof(shader::Photon);

// photons.comp's push block.
struct PhotonPush {
  glm::mat4 view_proj;
  glm::vec4 position;   // xyz lamp; w map size
  glm::vec4 intensity;  // rgb W/sr; w 2 tan(half field of view)
  glm::vec4 axis;       // xyz spot direction; w cos inner
  glm::vec4 cone;       // x cos outer; yzw the map's axis
};
static_assert(sizeof(PhotonPush) == 128, "the guaranteed push-constant size");

glm::vec3 any_up(const glm::vec3& forward) {
  return std::abs(forward.y) > 0.9f ? glm::vec3(1.0f, 0.0f, 0.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
}

// caustic_receiver.vert's push block.
struct ReceiverPush {
  shader::CausticReceiverLamp lamp;
  glm::vec4 sizes;  // x smallest square side (texels), y largest
};
static_assert(sizeof(ReceiverPush) <= 128, "the guaranteed push-constant size");

// Lamp slot li's receiver map of `receiver` texels a side in the receiver atlas. The map's
// frame: its pole on the lamp's axis, so the octahedron's seams (where bilinear reads and squares
// break) lie 90 degrees off the cone.
shader::CausticReceiverLamp receiver_lamp(const LightDesc& lamp, size_t li, uint32_t receiver) {
  const glm::vec3 z = glm::normalize(lamp.direction);
  const glm::vec3 x = glm::normalize(glm::cross(any_up(z), z));
  const glm::vec3 y = glm::cross(z, x);
  shader::CausticReceiverLamp rl;
  rl.position = glm::vec4(lamp.position, float(receiver));
  rl.frame_x = glm::vec4(x, 0.0f);
  rl.frame_y = glm::vec4(y, 0.0f);
  rl.frame_z = glm::vec4(z, 0.0f);
  int levels = 1;
  while (levels < MRGI_CAUSTIC_RECEIVER_LEVELS && (receiver >> levels) >= 4) ++levels;
  rl.atlas = glm::ivec4(int(li * (receiver + receiver / 2)), 0, levels, 0);
  return rl;
}

}  // namespace

Expected<Caustics> Caustics::create(const frame::FrameResources& shared, uint32_t max_map_size,
                                    uint32_t max_receiver_map, const gpu::Pipeline& back_faces) {
  if (max_map_size < 16 || max_map_size > 2048)
    return fail(ErrorKind::BadUsage, "caustic map size: must be 16..2048 texels");
  if (max_receiver_map != 0 && (max_receiver_map < 16 || max_receiver_map > 2048))
    return fail(ErrorKind::BadUsage, "caustic receiver map size: must be 0 (none) or 16..2048 texels");
  static_assert(kMaxLamps == MRGI_CAUSTIC_RECEIVER_LAMPS, "one receiver map a lamp with caustics");
  Caustics c;
  c.shared_ = shared;
  c.max_map_ = max_map_size;
  c.back_faces_ = &back_faces;
  c.max_receiver_ = max_receiver_map;
  MRGI_TRY(c.create_photon_maps());
  MRGI_TRY(c.create_caustic_buffers());
  MRGI_TRY(c.create_photon_buffers());
  MRGI_TRY(c.create_photon_pipelines());
  MRGI_TRY(c.create_splat_pipelines());
  return c;
}

// The lamp's view of the objects: front and back faces' positions and normals, and depth.
Status Caustics::create_photon_maps() {
  gpu::FrameGraph& graph = *shared_.graph;
  const uint32_t max_map_size = max_map_;
  const VkImageUsageFlags colour = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT;
  auto map = [&](const char* name, VkFormat f, VkImageUsageFlags usage) -> Expected<gpu::ImageHandle> {
    gpu::ImageDesc d;
    d.name = name;
    d.format = f;
    d.size_mode = gpu::SizeMode::Absolute;
    d.width = d.height = max_map_size;
    return graph.create_image(d, usage);
  };
  auto p = map("specular photon position", kPhotonPositionFormat, colour);
  if (!p) return p.error();
  position_ = *p;
  auto n = map("specular photon normal", kPhotonNormalFormat, colour);
  if (!n) return n.error();
  normal_ = *n;
  auto bp = map("specular photon back position", kPhotonPositionFormat, colour);
  if (!bp) return bp.error();
  back_position_ = *bp;
  auto bn = map("specular photon back normal", kPhotonNormalFormat, colour);
  if (!bn) return bn.error();
  back_normal_ = *bn;
  auto d = map("specular photon depth", kPhotonDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT);
  if (!d) return d.error();
  depth_ = *d;
  return ok_status();
}

// Where the photons are splatted: the camera's caustic buffer and, with max_receiver_, the
// receiver maps' atlas and their lamps.
Status Caustics::create_caustic_buffers() {
  gpu::FrameGraph& graph = *shared_.graph;
  const uint32_t max_receiver_map = max_receiver_;
  const VkImageUsageFlags colour = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT;
  gpu::ImageDesc cd;
  cd.name = "specular caustics";
  cd.format = kCausticFormat;  // OutputRelative, following the render scale
  auto cb = graph.create_image(cd, colour);
  if (!cb) return cb.error();
  caustics_ = *cb;
  if (max_receiver_map > 0) {
    gpu::ImageDesc rd;
    rd.name = "specular caustic receivers";
    rd.format = kReceiverFormat;
    rd.size_mode = gpu::SizeMode::Absolute;
    rd.width = (max_receiver_map + max_receiver_map / 2) * uint32_t(kMaxLamps);  // with the halvings
    rd.height = max_receiver_map;
    rd.history = true;  // drawn when the photons are traced, read every frame
    auto rb = graph.create_image(rd, colour);
    if (!rb) return rb.error();
    receivers_ = *rb;
    auto lb = graph.create_buffer(
        {"specular caustic receiver lamps", sizeof(shader::CausticReceivers), gpu::MemoryUsage::Upload, true},
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    if (!lb) return lb.error();
    receiver_lamps_ = *lb;
  }
  return ok_status();
}

// Per lamp slot: its photons, their list and the splat's indirect draw.
Status Caustics::create_photon_buffers() {
  gpu::FrameGraph& graph = *shared_.graph;
  const uint32_t max_map_size = max_map_;
  for (int l = 0; l < kMaxLamps; ++l) {
    const std::string id = std::to_string(l);
    gpu::BufferDesc pd{"specular photons " + id, VkDeviceSize(max_map_size) * max_map_size * 2 * kPhotonBytes};
    pd.history = true;
    auto pb = graph.create_buffer(pd, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    if (!pb) return pb.error();
    photons_[l] = *pb;
    gpu::BufferDesc ld{"specular photon list " + id, VkDeviceSize(max_map_size) * max_map_size * 2 * 4};
    ld.history = true;
    auto lb = graph.create_buffer(ld, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    if (!lb) return lb.error();
    photon_list_[l] = *lb;
    gpu::BufferDesc dd{"specular photon draw " + id, 16};
    dd.history = true;
    auto db = graph.create_buffer(dd, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT |
                                          VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    if (!db) return db.error();
    photon_draw_[l] = *db;
  }
  return ok_status();
}

Status Caustics::create_photon_pipelines() {
  const gpu::Context& ctx = *shared_.context;
  auto pp = gpu::load_compute_pipeline(ctx, "specular/photons.comp", {});
  if (!pp) return pp.error();
  photon_pipeline_ = std::move(*pp);
  auto fpp = gpu::load_compute_pipeline(ctx, "specular/photon_footprint.comp", {});
  if (!fpp) return fpp.error();
  footprint_pipeline_ = std::move(*fpp);
  auto mesh_vs = gpu::shader_spirv("gi/rsm_mesh.vert");
  if (!mesh_vs) return mesh_vs.error();
  auto surface_fs = gpu::shader_spirv("specular/photon_surface.frag");
  if (!surface_fs) return surface_fs.error();
  gpu::GraphicsPipelineDesc pd;
  pd.name = "specular photon surfaces";
  pd.vertex_spirv = *mesh_vs;
  pd.fragment_spirv = *surface_fs;
  pd.vertex_strides = {sizeof(frame::GpuVertex)};
  pd.attributes = {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0},
                   {1, 0, VK_FORMAT_R32G32B32_SFLOAT, 12},
                   {2, 0, VK_FORMAT_R32G32_SFLOAT, 24}};
  pd.color_formats = {kPhotonPositionFormat, kPhotonNormalFormat};
  pd.depth_format = kPhotonDepthFormat;
  pd.cull_mode = VK_CULL_MODE_BACK_BIT;
  auto sp = gpu::create_graphics_pipeline(ctx, pd);
  if (!sp) return sp.error();
  surface_pipeline_ = gpu::PipelineHandle(ctx, std::move(*sp));
  MRGI_TRY(gpu::require_bindings(*surface_pipeline_, pd.name, {"Materials"}));
  return ok_status();
}

// The camera's splat and, with max_receiver_, the receiver maps' splat and their mip chain.
Status Caustics::create_splat_pipelines() {
  const gpu::Context& ctx = *shared_.context;
  auto splat_vs = gpu::shader_spirv("specular/caustic_splat.vert");
  if (!splat_vs) return splat_vs.error();
  auto splat_fs = gpu::shader_spirv("specular/caustic_splat.frag");
  if (!splat_fs) return splat_fs.error();
  gpu::GraphicsPipelineDesc sd;
  sd.name = "specular caustic splat";
  sd.vertex_spirv = *splat_vs;
  sd.fragment_spirv = *splat_fs;
  sd.color_formats = {kCausticFormat, kLitFormat};
  sd.depth_test = false;
  sd.depth_write = false;
  sd.cull_mode = VK_CULL_MODE_NONE;
  sd.additive_blend = true;
  sd.topology = VK_PRIMITIVE_TOPOLOGY_POINT_LIST;
  auto spl = gpu::create_graphics_pipeline(ctx, sd);
  if (!spl) return spl.error();
  splat_pipeline_ = gpu::PipelineHandle(ctx, std::move(*spl));
  if (max_receiver_ > 0) {
    auto rvs = gpu::shader_spirv("specular/caustic_receiver.vert");
    if (!rvs) return rvs.error();
    auto rfs = gpu::shader_spirv("specular/caustic_receiver.frag");
    if (!rfs) return rfs.error();
    gpu::GraphicsPipelineDesc rd = sd;
    rd.name = "specular caustic receivers";
    rd.vertex_spirv = *rvs;
    rd.fragment_spirv = *rfs;
    rd.color_formats = {kReceiverFormat};
    auto rp = gpu::create_graphics_pipeline(ctx, rd);
    if (!rp) return rp.error();
    receiver_pipeline_ = gpu::PipelineHandle(ctx, std::move(*rp));
    auto mp = gpu::load_compute_pipeline(ctx, "specular/caustic_receiver_mip.comp", {});
    if (!mp) return mp.error();
    receiver_mip_pipeline_ = std::move(*mp);
  }
  return ok_status();
}

// The strongest spot lamps whose cone meets the objects' sphere and that are outside it, at most
// kMaxLamps, into chosen_. Returns whether there is one.
bool Caustics::choose_lamps(const std::vector<LightDesc>& lamps, const glm::vec3& centre, float radius,
                            std::vector<std::string>& skipped) {
  std::vector<const LightDesc*>& chosen = chosen_;
  chosen.clear();
  for (const LightDesc& l : lamps) {
    if (l.type != LightType::Spot || !(l.intensity > 0.0f)) continue;
    if (glm::distance(l.position, centre) <= 1.05f * radius || !gi::lamp_reaches_sphere(l, centre, radius)) continue;
    chosen.push_back(&l);
  }
  std::sort(chosen.begin(), chosen.end(), [](const LightDesc* a, const LightDesc* b) {
    return glm::dot(a->color, glm::vec3(1.0f)) * a->intensity > glm::dot(b->color, glm::vec3(1.0f)) * b->intensity;
  });
  if (chosen.size() > size_t(kMaxLamps)) {
    skipped.push_back("specular caustics: " + std::to_string(chosen.size() - size_t(kMaxLamps)) +
                      " weaker spot lamp(s) beyond the " + std::to_string(kMaxLamps) + " with caustic maps");
    chosen.resize(size_t(kMaxLamps));
  }
  if (chosen.empty()) {
    skipped.push_back("specular caustics: no spot lamp's cone holds a reflective or refractive object");
    return false;
  }
  return true;
}

// Whether this frame traces the chosen lamps' photons (else it splats those traced for the same
// lamps, objects and map size at most refresh.period - 1 frames ago; a due trace waits while
// impostors are redrawn this frame, to spread the fast level's work over frames).
bool Caustics::photons_due(uint32_t size, uint32_t receiver, const std::vector<size_t>& objects,
                           const glm::vec3& centre, float radius, const Refresh& refresh,
                           std::vector<std::string>& skipped) {
  ++frame_;
  // What the photons depend on, compared exactly (doubles hold the revision and the indices).
  std::vector<double>& key = key_;
  key.assign({double(size), double(refresh.glass_reflection_stride), double(refresh.revision), double(receiver),
              centre.x, centre.y, centre.z, radius});
  for (size_t o : objects) key.push_back(double(o));
  for (const LightDesc* l : chosen_) {
    const double k[] = {l->position.x,
                        l->position.y,
                        l->position.z,
                        l->direction.x,
                        l->direction.y,
                        l->direction.z,
                        l->color.r * l->intensity,
                        l->color.g * l->intensity,
                        l->color.b * l->intensity,
                        l->inner_angle_deg,
                        l->outer_angle_deg};
    key.insert(key.end(), std::begin(k), std::end(k));
  }
  const int64_t age = frame_ - traced_frame_;
  const bool trace = key != traced_key_ || age >= refresh.period + 1 || (age >= refresh.period && !refresh.busy);
  if (trace) {
    traced_key_.swap(key);
    traced_frame_ = frame_;
  } else {
    skipped.push_back("specular photons: traced " + std::to_string(age) +
                      " frame(s) ago for the same lamps and objects (refresh period " + std::to_string(refresh.period) +
                      ")");
  }
  return trace;
}

// Lamp slot li's photon passes: the objects' front (`front`) and refractive back (`back`) faces
// from the lamp, a photon per texel traced to the impostors, and their footprints.
void Caustics::add_photon_passes(gpu::FrameGraph& graph, const Impostors& imp, size_t li, const LightDesc& lamp,
                                 const glm::mat4& view_proj, const glm::vec3& axis, float half, uint32_t size,
                                 const std::vector<size_t>& front, const std::vector<size_t>& back) {
  const frame::SceneGpu& sg = *shared_.scene_gpu;
  const std::string id = std::to_string(li);
  const gpu::BufferHandle draw = photon_draw_[li], photons = photons_[li], list = photon_list_[li];
  MeshRaster r;
  r.name = "specular photon surfaces " + id;
  r.pipeline = &*surface_pipeline_;
  r.colour = {position_, normal_};
  r.depth = depth_;
  r.extent = {size, size};
  r.push.view_proj = view_proj;
  r.push.light = glm::vec4(lamp.position, 1.0f);
  r.draws = front;
  // Half a texel of the map: its focal length is size / (2 tan(half)).
  r.lod = frame::LodView{lamp.position, float(size) / (2.0f * std::tan(half)), 0.5f};
  add_mesh_raster(graph, sg, r);
  if (!back.empty()) {
    r.name = "specular photon back faces " + id;
    r.pipeline = back_faces_;
    r.colour = {back_position_, back_normal_};
    r.draws = back;
    add_mesh_raster(graph, sg, r);
  }
  const glm::vec3 dir = glm::normalize(lamp.direction);
  const PhotonPush push{view_proj, glm::vec4(lamp.position, float(size)),
                        glm::vec4(lamp.color * lamp.intensity, 2.0f * std::tan(half)),
                        glm::vec4(dir, std::cos(glm::radians(lamp.inner_angle_deg))),
                        glm::vec4(std::cos(glm::radians(lamp.outer_angle_deg)), axis)};
  graph.add_pass(
      "specular photons reset " + id, gpu::PassKind::Transfer,
      [draw](gpu::PassBuilder& b) { b.write(draw, gpu::Access::TransferDst); },
      [draw](VkCommandBuffer cmd, gpu::PassContext& p) { vkCmdFillBuffer(cmd, p.buffer(draw), 0, 16, 0); });
  const gpu::Pipeline* pp = &*photon_pipeline_;
  const bool has_back = !back.empty();
  graph.add_shader_pass(
      "specular photons " + id, gpu::PassKind::Compute, *photon_pipeline_,
      [this, imp, has_back, photons, list, draw](gpu::ShaderPassBuilder& b) {
        b.bind("SpecularUbo", imp.constants);
        b.bind("Materials", shared_.scene_gpu->materials);
        b.bind("photon_position", position_);
        b.bind("photon_normal", normal_);
        // Without a refractive object the back faces are never read: the front ones stand in.
        b.bind("back_position", has_back ? back_position_ : position_);
        b.bind("back_normal", has_back ? back_normal_ : normal_);
        b.bind("impostor_position", imp.position);
        b.bind("impostor_normal", imp.normal);
        b.bind("impostor_albedo", imp.albedo);
        b.bind("Photons", photons);
        b.bind("PhotonList", list);
        b.bind_over("PhotonDraw", draw);
      },
      [pp, push, size](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::push_and_dispatch(cmd, *pp, &push, sizeof push, {(size + 7) / 8, (size + 7) / 8, 1});
      });
  const gpu::Pipeline* fp = &*footprint_pipeline_;
  const glm::ivec4 map(int(size), 0, 0, 0);
  graph.add_shader_pass(
      "specular photon footprints " + id, gpu::PassKind::Compute, *footprint_pipeline_,
      [photons](gpu::ShaderPassBuilder& b) { b.bind_over("Photons", photons); },
      [fp, map, size](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::push_and_dispatch(cmd, *fp, &map, sizeof map, {(size + 7) / 8, (size + 7) / 8, 1});
      });
}

bool Caustics::trace(gpu::FrameGraph& graph, const Impostors& imp, const std::vector<LightDesc>& lamps,
                      const std::vector<size_t>& objects, const glm::vec3& centre, float radius, uint32_t map_size,
                      const Refresh& refresh, std::vector<std::string>& skipped) {
  const frame::SceneGpu& sg = *shared_.scene_gpu;
  const uint32_t size = std::min(map_size, max_map_);
  recorded_.lamps.clear();
  recorded_.receivers = {};
  recorded_.receiver_lamps = {};
  splat_push_.clear();
  shader::CausticReceivers receiver_set{};
  if (!choose_lamps(lamps, centre, radius, skipped)) return false;
  const std::vector<const LightDesc*>& chosen = chosen_;
  const float largest_point = shared_.context->max_point_size();
  if (largest_point < 4.0f) {
    skipped.push_back("specular caustics: the device draws no points over " + std::to_string(largest_point) +
                      " pixels (largePoints), and the caustic splat's photons are points");
    return false;
  }
  const uint32_t receiver = max_receiver_ > 0 ? std::min(refresh.receiver_map, max_receiver_) : 0u;
  const bool trace = photons_due(size, receiver, objects, centre, radius, refresh, skipped);
  // The ranges the photon maps draw: only on a frame that traces (no allocation on the others).
  std::vector<size_t> front, back;
  if (trace) {
    front = specular_draws(sg, objects, (1 << shader::SPECULAR_REFLECTIVE) | (1 << shader::SPECULAR_REFRACTIVE));
    back = specular_draws(sg, objects, 1 << shader::SPECULAR_REFRACTIVE);
  }
  // Squares between 1.5 pixels and a fortieth of the image's width (caustic_splat.vert sizes each
  // by its photon's spacing; larger ones cost more in overdraw than the smoothness they add).
  const VkExtent2D internal = graph.extent(shared_.lit_rv);
  const float quad_min_px = 1.5f, quad_max_px = std::min(std::max(4.0f, float(internal.width) / 40.0f), largest_point);
  for (size_t li = 0; li < chosen.size(); ++li) {
    const LightDesc& lamp = *chosen[li];
    const glm::vec3 to = centre - lamp.position;
    const float dist = glm::length(to);
    const glm::vec3 axis = to / dist;
    const float half = std::asin(std::min(radius / dist, 0.97f));
    // glm's perspective is OpenGL's (y up); flipped to Vulkan's y down like the camera's
    // (FrameConstants::world_to_clip), so the photon maps' front and back faces are the ones the
    // culling of their pipelines means (unflipped, the winding mirrors and "back faces" were the
    // lamp-facing ones: the refracted photons left from the wrong side and spread over the table).
    const glm::mat4 flip_y = glm::scale(glm::mat4(1.0f), glm::vec3(1.0f, -1.0f, 1.0f));
    const glm::mat4 view_proj = flip_y * glm::perspective(2.0f * half, 1.0f, 0.01f, dist + radius) *
                                glm::lookAt(lamp.position, centre, any_up(axis));
    recorded_.lamps.push_back({lamp.position, view_proj, size, photons_[li]});
    if (trace) add_photon_passes(graph, imp, li, lamp, view_proj, axis, half, size, front, back);
    splat_push_.push_back(glm::vec4(quad_min_px, 0.0f, quad_max_px, 0.0f));
    if (receiver > 0) {
      const shader::CausticReceiverLamp rl = receiver_lamp(lamp, li, receiver);
      receiver_set.lamps[li] = rl;
      receiver_set.count.x = int(li) + 1;
      if (trace) add_receiver_splat(graph, li, rl, largest_point);
    }
  }
  if (receiver > 0) {
    *static_cast<shader::CausticReceivers*>(graph.mapped(receiver_lamps_, graph.slot())) = receiver_set;
    recorded_.receivers = receivers_;
    recorded_.receiver_lamps = receiver_lamps_;
  }
  return true;
}

void Caustics::add_receiver_splat(gpu::FrameGraph& graph, size_t li, const shader::CausticReceiverLamp& lamp,
                                  float largest_point) {
  const uint32_t side = uint32_t(lamp.position.w);
  // Squares of one texel up to a sixteenth of the map (the octahedron's 2 units: 1/8 of a
  // hemisphere's width), so the widest spread photons stay smooth without flooding the map.
  const ReceiverPush push{lamp, glm::vec4(1.0f, std::min(float(side) / 16.0f, largest_point), 0.0f, 0.0f)};
  const gpu::Pipeline* pipe = &*receiver_pipeline_;
  const gpu::BufferHandle draw = photon_draw_[li], photons = photons_[li], list = photon_list_[li];
  const bool first = li == 0;
  const std::string id = std::to_string(li);
  graph.add_shader_pass(
      "specular caustic receivers " + id, gpu::PassKind::Graphics, *receiver_pipeline_,
      [this, first, photons, list, draw](gpu::ShaderPassBuilder& b) {
        b.bind("Photons", photons);
        b.bind("PhotonList", list);
        b.uses().read(draw, gpu::Access::IndirectRead);
        // Each lamp's map is its own part of the atlas: the second keeps the first's.
        b.uses().write(receivers_, first ? gpu::Access::ColorAttachmentWrite : gpu::Access::ColorAttachmentReadWrite);
      },
      [this, pipe, push, draw, side, li](VkCommandBuffer cmd, gpu::PassContext& p) {
        const gpu::Context& ctx = p.context();
        VkRenderingAttachmentInfo colour{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
        colour.imageView = p.view(receivers_);
        colour.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
        colour.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;  // the render area: this lamp's map
        colour.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        colour.clearValue.color = {{0.0f, 0.0f, 0.0f, 0.0f}};
        const VkRect2D area{{int32_t(li * (side + side / 2)), 0}, {side, side}};
        VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
        ri.renderArea = area;
        ri.layerCount = 1;
        ri.colorAttachmentCount = 1;
        ri.pColorAttachments = &colour;
        ctx.fn().cmd_begin_rendering(cmd, &ri);
        const VkViewport vp{float(area.offset.x), 0.0f, float(side), float(side), 0.0f, 1.0f};
        vkCmdSetViewport(cmd, 0, 1, &vp);
        vkCmdSetScissor(cmd, 0, 1, &area);
        vkCmdPushConstants(cmd, pipe->layout, pipe->stages, 0, sizeof push, &push);
        vkCmdDrawIndirect(cmd, p.buffer(draw), 0, 1, 16);
        ctx.fn().cmd_end_rendering(cmd);
      });
  // The halvings the readers take where their pixels are wider than mip 0's texels.
  const gpu::Pipeline* mip = &*receiver_mip_pipeline_;
  const glm::ivec2 origin(lamp.atlas.x, lamp.atlas.y);
  for (int k = 1; k < lamp.atlas.z; ++k) {
    const glm::ivec2 from = shader::caustic_receiver_origin(origin, int(side), k - 1);
    const glm::ivec2 to = shader::caustic_receiver_origin(origin, int(side), k);
    const uint32_t level_side = side >> k;
    const glm::ivec4 push_mip[2] = {glm::ivec4(from, to), glm::ivec4(int(level_side), 0, 0, 0)};
    graph.add_shader_pass(
        "specular caustic receiver mip " + id + "." + std::to_string(k), gpu::PassKind::Compute, *receiver_mip_pipeline_,
        [this](gpu::ShaderPassBuilder& b) { b.bind_over("caustic_receivers", receivers_); },
        [mip, push_mip, level_side](VkCommandBuffer cmd, gpu::PassContext&) {
          gpu::push_and_dispatch(cmd, *mip, push_mip, sizeof push_mip, {(level_side + 7) / 8, (level_side + 7) / 8, 1});
        });
  }
}

void Caustics::splat(gpu::FrameGraph& graph) {
  for (size_t li = 0; li < recorded_.lamps.size(); ++li) {
    const bool first = li == 0;
    const gpu::Pipeline* splat = &*splat_pipeline_;
    const glm::vec4 splat_push = splat_push_[li];
    const gpu::BufferHandle draw = photon_draw_[li], photons = photons_[li], list = photon_list_[li];
    graph.add_shader_pass(
        "specular caustic splat " + std::to_string(li), gpu::PassKind::Graphics, *splat_pipeline_,
        [this, first, photons, list, draw](gpu::ShaderPassBuilder& b) {
          b.bind("FrameUbo", shared_.frame_constants);
          b.bind("Photons", photons);
          b.bind("PhotonList", list);
          b.uses().read(draw, gpu::Access::IndirectRead);
          b.bind("real_position", shared_.real_position);
          b.bind("real_albedo", shared_.real_albedo);
          b.bind("virtual_position", shared_.virtual_position);
          b.bind("virtual_albedo", shared_.virtual_albedo);
          b.uses().write(caustics_, first ? gpu::Access::ColorAttachmentWrite : gpu::Access::ColorAttachmentReadWrite);
          b.uses().write(shared_.lit_rv, gpu::Access::ColorAttachmentReadWrite);
        },
        [this, splat, splat_push, first, draw](VkCommandBuffer cmd, gpu::PassContext& p) {
          const gpu::Context& ctx = p.context();
          const VkExtent2D e = p.extent(caustics_);
          VkRenderingAttachmentInfo colour[2];
          const gpu::ImageHandle targets[2] = {caustics_, shared_.lit_rv};
          for (int i = 0; i < 2; ++i) {
            colour[i] = {VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
            colour[i].imageView = p.view(targets[i]);
            colour[i].imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
            colour[i].loadOp = first && i == 0 ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
            colour[i].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
            colour[i].clearValue.color = {{0.0f, 0.0f, 0.0f, 0.0f}};
          }
          VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
          ri.renderArea = {{0, 0}, e};
          ri.layerCount = 1;
          ri.colorAttachmentCount = 2;
          ri.pColorAttachments = colour;
          ctx.fn().cmd_begin_rendering(cmd, &ri);
          const VkViewport vp{0.0f, 0.0f, float(e.width), float(e.height), 0.0f, 1.0f};
          const VkRect2D sc{{0, 0}, e};
          vkCmdSetViewport(cmd, 0, 1, &vp);
          vkCmdSetScissor(cmd, 0, 1, &sc);
          vkCmdPushConstants(cmd, splat->layout, splat->stages, 0, sizeof splat_push, &splat_push);
          vkCmdDrawIndirect(cmd, p.buffer(draw), 0, 1, 16);
          ctx.fn().cmd_end_rendering(cmd);
        });
  }
}

}  // namespace mrgi::specular

// Internal to the specular stage (specular.cpp, specular_init.cpp): its formats, the objects and
// impostor sets of a frame, and the stage's state (SpecularStage::Impl). Not part of the
// library's interface.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "specular/caustics.h"
#include "specular/specular.h"
#include "specular/specular_params.glsl"
#include "frame/frame_resources.h"
#include "frame/screen_bounds.h"
#include "shading/direct_light.h"

namespace mrgi::specular {
namespace specular_detail {

constexpr VkFormat kPositionFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkFormat kImpostorNormalFormat = VK_FORMAT_R8G8B8A8_SNORM;
constexpr VkFormat kImpostorAlbedoFormat = VK_FORMAT_R8G8B8A8_UNORM;
constexpr VkFormat kBackNormalFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

struct ObjectInView {
  size_t object = 0;
  glm::vec3 lo{0.0f}, hi{0.0f};
  float distance = 0.0f;
  bool refractive = false, reflective = false;
  frame::ScreenBounds screen;  // its box projected into this frame's camera
};

// trace_list.comp's lists, in its order: the pass over each and trace.comp's specialisation.
struct TraceList {
  const char* pass;
  bool refractive, reflect;
};
constexpr int kTraceLists = 3;
constexpr TraceList kTraceList[kTraceLists] = {{"specular trace glass", true, true},
                                               {"specular trace mirrors", false, true},
                                               {"specular trace glass unreflected", true, false}};

struct ImpostorSet {
  glm::vec3 centre{0.0f};
  float radius = 0.0f;
  std::vector<size_t> objects;  // not drawn into their own set
};


}  // namespace specular_detail

struct SpecularStage::Impl {
  frame::FrameResources shared;
  SpecularSettings settings;
  gpu::ImageHandle impostor_position, impostor_normal, impostor_albedo, impostor_depth;
  gpu::ImageHandle back_position, back_normal, back_depth;
  gpu::ImageHandle no_shadow, no_caustics, no_receivers;
  gpu::BufferHandle constants, own_lights, no_receiver_lamps;
  // Per set: the real grid's triangles of each cube face (impostor_cells.comp) and the six
  // indexed indirect draws; capacity: indices a face can hold (every triangle of the finest grid).
  std::vector<gpu::BufferHandle> face_indices, face_draws;
  uint32_t face_capacity = 0;
  gpu::BufferHandle env_grid;  // the light stage's environment grid, copied each frame
  int env_width = 0;           // its width in cells
  gpu::PipelineHandle cells_pipeline, grid_pipeline, mesh_pipeline, back_pipeline, list_pipeline;
  gpu::PipelineHandle trace_pipelines[specular_detail::kTraceLists];  // trace.comp per kTraceList
  // trace_list.comp's output: dispatch arguments per kind (glass, mirrors), counts, pixels.
  gpu::BufferHandle trace_args, trace_counts, trace_pixels;
  uint32_t list_capacity = 0;  // pixels each kind's list holds
  std::optional<Caustics> caustics;  // null with SpecularSettings::caustics off
  bool caustics_recorded = false;    // this frame's prepare() splatted caustics
  bool active = false;               // prepare() found something to do this frame
  glm::ivec4 region{0};              // the trace list's dispatch: first pixel, size
  bool glass_in_view = false, mirrors_in_view = false;
  float glass_reflection_fresnel = 0.0f;  // this frame's level's (SpecularLevel)
  frame::CausticPhotons photons; // this frame's, for the technique
  VkExtent2D grid_points{0, 0};
  uint32_t grid_stride = 1;
  glm::mat4 world_to_clip{1.0f};  // this frame's camera (the back faces' draw)
  glm::vec3 camera_world{0.0f};   // and its centre and focal length (internal pixels)
  float internal_focal_px = 0.0f;
  // What each set's block of the atlas holds: drawn at frame `frame` around `centre` for
  // `objects` at face size `face` (a set is redrawn when any of them changed or it is
  // refresh_period frames old).
  struct DrawnSet {
    int64_t frame = -1000000;
    glm::vec3 centre{0.0f};
    std::vector<size_t> objects;
    uint32_t face = 0;
    uint64_t revision = 0;
  };
  std::vector<DrawnSet> drawn;
  int64_t frame = 0;
  // prepare()'s scratch, kept between frames (no allocation a frame once grown).
  std::vector<specular_detail::ObjectInView> in_view;
  std::vector<specular_detail::ImpostorSet> sets;
  std::vector<bool> redraw;
  std::vector<size_t> objects;

  // What a trace pass binds besides the stage's own images: the technique's lights and shadow
  // maps (or the stage's unshadowed ones), the caustics it reads, the trace lists.
  struct TraceInputs {
    gpu::BufferHandle light_set;
    gpu::ImageHandle shadow_primary, shadow_virtual;
    gpu::ImageHandle caustic_buffer, receiver_maps;
    gpu::BufferHandle receiver_lamps;
    VkSampler compare = VK_NULL_HANDLE, nearest = VK_NULL_HANDLE;
  };

  // init(), in its order (specular_init.cpp).
  Status init();
  Status create_impostor_atlases();
  Status create_back_face_images();
  Status create_placeholders();
  Status create_face_buffers();
  Status create_frame_buffers();
  Status create_compute_pipelines();
  Status create_trace_lists();
  Status create_raster_pipelines();

  // prepare()'s steps.
  void find_objects_in_view(const frame::SceneGpu& sg, const shader::FrameConstants& fc);
  glm::ivec4 trace_region(const shader::FrameConstants& fc) const;
  void group_into_sets(int set_count);
  void write_constants(shader::SpecularConstants& c, const SpecularLevel& level, uint32_t face, int set_count,
                       const glm::ivec2& size);
  int write_environment(shader::SpecularConstants& c);
  void choose_redraws(const frame::SceneGpu& sg, const SpecularLevel& level, uint32_t face, int set_count);
  bool draw_impostor_sets(const frame::SceneGpu& sg, const SpecularLevel& level, uint32_t face,
                          std::vector<std::string>& skipped);
  bool add_caustics(const frame::SceneGpu& sg, const SpecularLevel& level, bool any_redrawn,
                    std::vector<std::string>& skipped);
  void set_grid(gpu::FrameGraph& graph, uint32_t face);
  void add_impostors(gpu::FrameGraph& graph, const specular_detail::ImpostorSet& set, int index,
                     const glm::ivec2& origin, uint32_t face, bool first);
  void add_impostor_cells(gpu::FrameGraph& graph, const specular_detail::ImpostorSet& set, const std::string& id,
                          gpu::BufferHandle indices, gpu::BufferHandle draws);
  void begin_impostor_rendering(VkCommandBuffer cmd, gpu::PassContext& p, const glm::ivec2& origin, uint32_t face,
                                gpu::Access depth_access) const;
  void add_back_faces(gpu::FrameGraph& graph, const std::vector<specular_detail::ObjectInView>& objects,
                      const glm::ivec4& region);

  // finish()'s steps.
  TraceInputs trace_light(const shading::DirectLightOutput* direct,
                          shader::SpecularConstants& c, std::vector<std::string>& skipped);
  void add_trace_list_passes();
  void add_trace_pass(int li, const TraceInputs& in);
};


}  // namespace mrgi::specular

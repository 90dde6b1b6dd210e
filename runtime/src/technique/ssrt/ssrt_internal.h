// Internal to the ssrt technique (ssrt.cpp, ssrt_init.cpp): its constants, push-constant
// blocks and the technique class. Not part of the library's interface.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "common/frame_constants.glsl"
#include "gpu/pipelines.h"
#include "gpu/shaders.h"
#include "shared/transfer_math.h"
#include "frame/scene_gpu.h"
#include "technique/ssrt/depth_filter_gpu.h"
#include "light/light_stage.h"
#include "light/sh_estimator.h"
#include "technique/ssrt/sample_directions.h"
#include "technique/ssrt/volume.h"

#include "technique/ssrt/ssrt.h"
#include "technique/knobs.h"
#include "technique/laddered.h"

namespace mrgi::technique::ssrt_detail {

// The ladder's knobs (technique/knobs.h), one entry per field of SsrtLevel.
inline const KnobField<SsrtLevel> kSsrtKnobs[] = {
    {"subsample", "pixels per cell side (transfer computed once per cell)", &SsrtLevel::subsample, true},
    {"directions", "visibility directions per pixel (per 2x2 jitter set)", &SsrtLevel::directions, true},
    {"sh_bands", "SH bands of transfer and estimated light", &SsrtLevel::sh_bands},
    {"internal_scale", "fraction of the output width and height", &SsrtLevel::internal_scale},
    {"volume_resolution", "TSDF voxels per side of the 2 m workspace cube", &SsrtLevel::volume_resolution, true},
    {"aux_resolution", "texels per side of each auxiliary orthographic buffer", &SsrtLevel::aux_resolution, true},
    {"final_filter", "1 = the third median pass (eq. 5) on, 0 = off", &SsrtLevel::final_filter},
    {"geometry_step", "internal pixels per texel side of the volume ray cast, depth filters and their G-buffer",
     &SsrtLevel::geometry_step, true},
    {"occluder_step",
     "internal pixels per texel side of the occluder G-buffer the transfer's samples read (virtual surface, "
     "albedos; occluders.comp)",
     &SsrtLevel::occluder_step, true},
    {"mesh_error_px", "projected error of the virtual meshes' level of detail, internal pixels (0 = full detail)",
     &SsrtLevel::mesh_error_px},
};

constexpr uint32_t kCoarseLayers = 7;
constexpr uint32_t kReduceEntries = 192;       // per partial sum, see light_reduce.comp
constexpr uint32_t kStripCells = 32;           // cells of a row per light_reduce invocation
constexpr uint32_t kSampleSeed = 20140901;     // sample sets are a pure function of N and this

// Settings shared by every level (units in the names).
constexpr float kRadiusM = 0.5f;             // SSDO sampling radius
constexpr float kRangeM = 2.0f * kRadiusM;   // occluders farther from the receiver do not count
constexpr float kNormalOffsetM = 0.01f;      // start of the samples above the surface
constexpr float kMinSenderDistM = 0.05f;     // 1/d^2 clamp of the form factor
constexpr float kDepthBias = 0.01f;          // occluder must be 1 % closer than the sample
constexpr float kSaturation = 0.98f;         // camera values at/above are clipped: not used
constexpr float kIndirectTolerance = 1e-3f;  // eq. 14
// Fast levels: a tile whose footprint's solutions can change no pixel's composite by more than
// this fraction keeps the camera frame: at most 0.88 of an 8-bit level, so no pixel moves by
// more than one level (transfer_math.h ssrt_tile_invisible). The suite's fast level, third frame
// of the 5 scenes with a virtual object: 15380 -> 10870 tiles shaded of 24000, frames identical.
constexpr float kTileTolerance = 1.0f / 128.0f;
constexpr float kGaussRadiusPx = 8.0f;       // paper OursFast
// An auxiliary-buffer surface occludes a sample only if it lies this many of the layer's texels
// in front of it (the aux layers are ray-cast from a TSDF with voxels about one texel wide).
constexpr float kAuxBiasTexels = 1.5f;
// Without a virtual object the volume is centred this far in front of the first camera pose.
constexpr double kVolumeAheadM = 1.0;

struct TransferPush {
  glm::ivec4 grid;
  glm::ivec4 config;
  glm::vec4 sampling;
  glm::vec4 bounce;
  glm::ivec4 influence;
  glm::vec4 aux;  // x bias in texels of the aux layer, y 1 = test the aux layers, z solid angle
  glm::ivec4 region;  // cells [x0, x1) x [y0, y1) of one dispatch
};
struct ReducePush {
  glm::ivec4 grid;
  glm::ivec4 size;
};
struct FinalPush {
  glm::ivec4 counts;
};
struct BlurPush {
  glm::ivec4 grid;
  glm::vec4 filt;
};
struct TilesPush {
  glm::ivec4 grid;
  glm::ivec4 counts;
  glm::ivec4 virt;
  glm::vec4 tolerance;
};
struct ShadePush {
  glm::ivec4 grid;
  glm::ivec4 size;
  glm::ivec4 influence;
  glm::vec4 opts;
};

class Ssrt final : public Laddered<SsrtLevel> {
 public:
  Ssrt(const frame::FrameResources& shared, std::vector<SsrtLevel> levels)
      : Laddered("ssrt", ladder_of(levels, ssrt_levels(), kSsrtKnobs), std::move(levels)),
        shared_(shared) {}
  Status init();
  Status record(const frame::FrameInfo& info, std::vector<std::string>& skipped) override;
  // The paper's own geometry stage (Sec. 4) replaces the runtime's reconstruction: the
  // transfer and the shading read the filtered G-buffer, the camera colour is read from the
  // upload where it is used (cell centres, shaded tiles), and the virtual objects' depth test
  // reads the filtered G-buffer too (G_r, Fig. 2: the paper's occlusion geometry). recon's two
  // full-resolution passes cost 13-14 ms of desk_spot's fast frame on lavapipe.
  Needs needs() const override { return {false, true}; }
  Status record_geometry(const frame::FrameInfo& info, std::vector<std::string>& skipped) override;
  std::optional<frame::RealGeometry> occlusion_geometry() const override {
    return frame::RealGeometry{geo_position_, geo_normal_, geometry_step_};
  }
  const LightEstimate& estimate() const { return estimator().estimate(); }
  const LightEstimate* light_estimate() const override { return &estimate(); }
  // Once, before the first estimate: the first frame is lit by its own estimate instead of the
  // prior (a uniform grey guess that made the first frames_in_flight frames' RDE about 1).
  bool estimate_pending() const override { return !primed_ && !estimator().estimate().valid; }
  void frames_completed() override;
  ComposeTiles compose_tiles() const override { return compose_tiles_; }

 private:
  // init()'s steps, in its order (ssrt_init.cpp).
  Status create_geometry_stage();
  Status create_sample_directions();
  Status create_light_buffers();
  Status create_solution_images();
  Status create_transfer_pipelines();
  Status create_blur_pipelines();
  Status create_shade_pipelines();
  Status create_shade_tile_buffers();
  // record()'s passes after the geometry stage.
  void add_occluders_pass();
  void add_transfer_pass();
  void add_light_reduce_passes();
  void add_upsample_blur_pass();
  void add_tiled_shade_passes(std::vector<std::string>& skipped);
  // Solves the sums the frame that last used `slot` read back (it must have completed).
  void consume_readback(uint32_t slot, std::vector<std::string>& notes);
  // The paper's geometry stage (Sec. 4): fuse the volume, ray-cast G_v and the aux layers, run
  // the depth filter chain into the G-buffer the transfer reads.
  Status record_real_geometry(const frame::FrameInfo& info, const SsrtLevel& level,
                              std::vector<std::string>& skipped);
  void write_light();
  // Whether the virtual objects' influence region (bounds grown by the sampling radius) is in
  // view; `cells` gets its conservative screen rectangle in cells [x0, x1) x [y0, y1).
  bool influence_in_view(glm::ivec4& cells) const;
  bool project_virtual_bounds(float grow_m, glm::vec2& pmin, glm::vec2& pmax, bool& behind) const;
  glm::ivec4 virtual_pixels() const;
  glm::ivec4 virtual_cells() const;
  // TiledCompose: Tiled, with the composite written to the runtime's output (shade.comp
  // kCompose; frame::FrameResources::composed_output).
  enum class ShadeMode { Full, PassThrough, Tiled, TiledCompose };
  void add_shade_pass(const char* name, ShadeMode mode, bool run_transfer);
  glm::ivec4 influence_pixels() const {
    const int st = int(step_);
    const int grow = step_ > 1 ? int(kGaussRadiusPx) + 2 * st : 0;
    return glm::ivec4(influence_cells_.x * st - grow, influence_cells_.y * st - grow,
                      influence_cells_.z * st + grow, influence_cells_.w * st + grow);
  }

  frame::FrameResources shared_;
  // The light stage's estimator, which this technique's sums feed.
  const light::LightEstimator& estimator() const { return shared_.light_stage->estimator(); }
  std::optional<ssrt::Volume> volume_;
  std::optional<ssrt::DepthFilterGpu> filter_;
  // Writes this frame's geometry constants: the frame constants with the internal intrinsics
  // and size replaced by the geometry stage's (geometry_step_ internal pixels per texel), and
  // sets the geometry images' extent divisor to match.
  Status write_geometry_constants();

  // The real G-buffer the transfer uses: the filter chain's (paper Sec. 4), not recon's.
  gpu::ImageHandle geo_position_, geo_normal_;
  // The packed occluder G-buffer (occluders.comp: occ_a, occ_b) at the occluder step.
  gpu::ImageHandle occ_a_, occ_b_;
  // The frame constants the geometry stage (volume ray cast, depth filters) reads: a copy of
  // the runtime's with internal_k / internal_output_size at the geometry resolution, so the same
  // shaders run at any geometry step. Images whose extent follows it: geo_images_.
  gpu::BufferHandle geo_constants_;
  std::vector<gpu::ImageHandle> geo_images_;
  std::optional<glm::vec3> volume_center_;
  uint64_t centred_for_layout_ = 0;  // the SceneGpu::layout_revision the cube was placed for
  std::vector<uint32_t> sample_base_;  // per level: first sample of its sets
  std::vector<float> chi_;             // per level
  gpu::BufferHandle samples_, light_, partials_, result_;
  gpu::ImageHandle coarse_;
  gpu::ImageHandle upsampled_;  // RGBA32UI per cell, shaders/ssrt/upsampled.glsl
  gpu::PipelineHandle occluders_, transfer_, transfer_real_, transfer_real_only_, reduce_,
      reduce_final_, blur_, shade_, shade_pass_, shade_tiled_, shade_tiled_compose_, shade_tiles_;
  // Fast levels' shade tiles (shade_tiles.comp): indirect dispatch arguments and tile indices.
  gpu::BufferHandle tile_args_, tile_list_;
  gpu::BufferHandle no_compose_;
  // ssrt_upsample_blur with its window radius in cells as a constant, per radius the ladder uses
  // (blur_ takes it from the push constants).
  std::vector<std::pair<int, gpu::PipelineHandle>> blur_by_radius_;
  // The blur window's radius in cells at `step` pixels per cell (upsample_blur.comp).
  static int blur_radius_cells(int step) { return int(std::ceil(kGaussRadiusPx / float(step))); }  // shade.comp's output and mask for the variants without kCompose
  ComposeTiles compose_tiles_;  // this frame's (set by record)
  std::vector<int64_t> pending_;       // per frame slot: frame whose sums its readback holds
  std::vector<int> pending_bands_;     // per frame slot: SH bands of that frame's transfer
  bool primed_ = false;                // a priming run was asked for (only ever once)
  std::vector<std::string> deferred_notes_;  // from frames_completed, reported by the next record
  // This frame's knobs (set by record before the passes are added).
  uint32_t step_ = 1, directions_ = 64, bands_ = 4, geometry_step_ = 1, occluder_step_ = 1;
  int level_ = 0;
  // The frame record_geometry() last recorded (record() then adds the rest of it).
  int64_t geometry_frame_ = -1;
  bool geometry_frame_valid_ = false;
  glm::uvec2 grid_{1, 1};
  glm::ivec4 influence_cells_{0, 0, 0, 0};
  VkExtent2D used_{1, 1};
};

}  // namespace mrgi::technique::ssrt_detail

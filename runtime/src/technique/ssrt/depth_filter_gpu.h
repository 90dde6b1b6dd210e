// The ssrt depth filter chain on the GPU (paper Sec. 4, eq. 1-5) and the real G-buffer it feeds.
// Same rules as the CPU reference depth_filter.h (the tests compare them texel for texel); the
// shaders are shaders/ssrt/depth_{merge,bilateral,final,gbuffer}.comp.
//   ssrt_depth_input      D_c, I_c (grey, see grey_level) and the D_c-agrees-with-D_v bit per
//                         pixel from this frame's colour/depth uploads and D_v
//   ssrt_depth_merge      D'  (eq. 1-3); also D' packed with I_c for the next pass
//   ssrt_depth_bilateral  D'' (eq. 4), joint bilateral median over Omega_I
//   ssrt_depth_final      D''' (eq. 5), plain median; left out when final_pass is false
//   ssrt_gbuffer          final depth -> world positions + camera-facing normals
// Every image is at the internal resolution (OutputRelative, follows the render scale) and is
// allocated once in create(). The D_c / I_c of a pixel are gathered from the raw uploads along
// its ray (nearest depth / colour sample), like recon/depth_to_positions.comp, so unregistered
// depth and render scales below 1 are handled; with registered depth at full resolution the
// gather is the identity.
//
// GPU limits (create() returns BadUsage naming the field otherwise): at most 5 sub-sampled taps
// per side for D' and D'' (the paper's 5 x 5; e.g. merge_window 6 would read 7 x 7 taps), a
// tap reach of at most 16 pixels (merge_window / bilateral_window <= 33 with 5 taps), and a
// D''' window of at most 5 x 5 (final_window <= 5).
// Every pass fetches its taps straight from the images (8 x 8 workgroups, no shared memory):
// on lavapipe a barrier turns each SIMD chunk of a workgroup into a coroutine, which cost
// 3-8x more than the fetches it saved (measured: D''' 36 -> 4 ms at 640 x 480); sampled
// texelFetch was 2-3x slower than imageLoad, SSBO reads slower too.
// Cost at 640 x 480 on lavapipe (LP_NUM_THREADS=2, synthetic frame with 10 % scattered holes,
// as multiples of the floor pass measured alongside): input 2.6-3.0, merge 4.8-5.0, bilateral
// 3.6-3.7, final 2.5-3.0, gbuffer 5.4-6.0; the chain ~20 x floor (~28 ms at 1.41 ms floor).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "mrgi/expected.h"
#include "technique/ssrt/depth_filter.h"
#include "technique/technique.h"

namespace mrgi::ssrt {

// I_c of an sRGB8 colour, 0..255: Rec. 601 luma on the encoded bytes in 8-bit fixed point
// (weights 77, 150, 29 sum to 256, so grey stays grey and white stays 255). Integer on both the
// GPU and the CPU, so the reference is fed exactly the shader's values.
constexpr uint32_t grey_level(uint32_t r, uint32_t g, uint32_t b) {
  return (77u * r + 150u * g + 29u * b + 128u) >> 8;
}

class DepthFilterGpu {
 public:
  static Expected<DepthFilterGpu> create(gpu::Context& ctx, gpu::FrameGraph& graph,
                                         const frame::FrameResources& shared,
                                         const DepthFilterSettings& settings = {});
  // Adds ssrt_depth_merge, ssrt_depth_bilateral, ssrt_depth_final (when final_pass is false it
  // is left out and "ssrt_depth_final: <reason>" is appended to skipped) and ssrt_gbuffer.
  // depth_volume: R32F D_v (metres along camera z, 0 = no surface) at the internal resolution,
  // or a null handle when there is no volume (then every D_v is "missing").
  // texel_pixels: internal pixels per side of one texel of the chain's images (the frame
  // constants the chain reads are at that resolution): the windows, given in pixels of the
  // paper's 640x480, shrink by it (k / texel_pixels, at least 1) so they cover the same part of
  // the scene; a 20 px D' window read as 20 coarse texels smeared depth edges over 80 px.
  Status record(gpu::ImageHandle depth_volume, bool final_pass, std::vector<std::string>& skipped,
                uint32_t texel_pixels = 1);

  gpu::ImageHandle position() const { return position_; }  // RGBA32F xyz world, w depth m; 0 = invalid
  // RGBA16F xyz world unit normal facing the camera; w 1 where measured, 0 where the pixel has
  // no same-surface neighbour along an axis (then xyz faces the camera) or no depth (all 0).
  gpu::ImageHandle normal() const { return normal_; }
  // D', D'', D''' (R32F metres, 0 = missing).
  gpu::ImageHandle merged() const { return merged_; }
  gpu::ImageHandle bilateral() const { return bilateral_; }
  gpu::ImageHandle final_depth() const { return final_; }
  // RG32F: x D_c (metres, 0 = missing), y I_c (grey 0..255) + 256 where D_c agrees with D_v.
  gpu::ImageHandle input() const { return input_; }
  // RG32F: x D', y I_c (what the bilateral pass reads).
  gpu::ImageHandle merged_intensity() const { return merged_intensity_; }
  const DepthFilterSettings& settings() const { return settings_; }

  struct WindowPush {
    glm::ivec4 window;      // reach px, stride px, taps per side, has volume
    glm::vec4 thresholds;   // lambda_I grey levels, lambda_D metres
  };

 private:
  gpu::FrameGraph* graph_ = nullptr;
  gpu::BufferHandle frame_constants_, color_upload_, depth_upload_;
  gpu::ImageHandle input_, merged_, merged_intensity_, bilateral_, final_, position_, normal_;
  gpu::ImageHandle no_volume_;   // 1 x 1 placeholder bound when there is no D_v (never read)
  gpu::ImageHandle volume_;      // this frame's D_v (or no_volume_)
  gpu::ImageHandle gbuffer_source_;  // this frame's final depth (D''' or D'')
  gpu::PipelineHandle input_pipe_, merge_, bilateral_pipe_, final_pipe_, gbuffer_;
  DepthFilterSettings settings_;
  // Push constants, filled at create / record (kept here so the callbacks allocate nothing).
  WindowPush merge_push_{}, bilateral_push_{};
  glm::ivec4 final_push_{1, 0, 0, 0};
  glm::ivec4 gbuffer_push_{2, 0, 0, 0};  // x normal tangent radius, texels
};

}  // namespace mrgi::ssrt

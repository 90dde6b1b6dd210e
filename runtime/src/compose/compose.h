// Compose (docs/DESIGN.md "One frame, as data"): tone-maps L_rv and L_r with the camera's response and
// adds their difference onto the camera frame per caustics-DIR eq. 1-2 (shaders/compose/
// compose.comp says how and why in linear space), at the output resolution (where the internal
// resolution is lower, the mask is the output-resolution coverage and the solutions are
// up-sampled from the texels on each pixel's side of it). Writes the RGBA8 sRGB frame with
// the virtual-pixel mask in its alpha straight into this slot's readback buffer. A tiled frame at the
// camera's size writes only the listed tiles there, with a copy of the tile list: read() takes
// the camera frame from the upload on the host and lays the tiles over it (0.3 ms of host time
// against 2.4 ms for a full-frame camera copy pass on lavapipe at 640x480). A technique may write
// the composite of its tiles itself (ComposeInputs::tiles_composed, same formula: mrgi_shared.h
// compose_encoded); compose then adds no pass, only the tile-list readback.
#pragma once
#include <algorithm>
#include <vector>

#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "mrgi/image.h"

namespace mrgi::compose {

// Guards of the differential composite (mrgi_shared.h differential_compose), in linear camera
// units (exposure-scaled radiance, 1 = sensor saturation).
struct ComposeSettings {
  float eps = 1e-3f;       // below this modelled real light, alpha blends to 1 (absolute delta)
  float alpha_max = 10.0f; // alpha = CI / TM(L_r) clamped to [0, alpha_max]
  // For a technique that lists no tiles of its own (Technique::compose_tiles): compose lists the
  // 8 x 8 output tiles whose composite can move a pixel by more than ComposeInputs::
  // tile_tolerance 8-bit levels from the camera's (shaders/compose/tile_classify.comp,
  // mrgi_shared.h compose_tile_invisible), and composites only those; the camera frame
  // elsewhere. Off: every pixel composited (the A/B reference).
  bool classify_tiles = true;
};

struct ComposeInputs {
  gpu::BufferHandle frame_constants;
  gpu::BufferHandle color_upload;
  gpu::ImageHandle lit_rv, lit_r, virtual_position;
  // Nothing virtual affects this frame (runtime/influence.h): the output is the camera frame and
  // the solutions, not computed this frame, are not looked at.
  bool camera_only = false;
  // The technique's Technique::compose_tiles() (valid handles): outside the listed 8 x 8 tiles
  // the output is the camera frame (tile indices of the output, ty * ceil(w / 8) + tx). Without
  // them compose lists its own (ComposeSettings::classify_tiles). Compose then runs the composite
  // over the tiles only, from solutions at the output size or resampled, and takes the camera
  // frame elsewhere (on the host at the camera's size, else a camera copy pass first).
  gpu::BufferHandle tile_args, tile_list;
  // Compose's own classification (ComposeSettings::classify_tiles): the 8-bit levels a tile's
  // composite may move a pixel by and the tile still keep the camera frame, for any camera value
  // (the level's QualityLevel::compose_tolerance); outputs then differ from composing every pixel
  // by at most that, rounded to the nearest level (0.5: one level).
  float tile_tolerance = 0.5f;
  // The technique wrote the composite of those tiles into output() itself
  // (Technique::ComposeTiles::composed): compose adds no pass of its own, only the tile-list
  // readback, and lays the tiles over the camera frame on the host. Honoured only for a frame
  // at the camera's size whose solutions have the output's size (fusable()) that comes back to
  // the host (not device_output, where compose composes those tiles itself).
  bool tiles_composed = false;
  // The virtual objects' coverage at the output resolution (recon::VirtualGBuffer::
  // output_coverage), required where the solutions are smaller than the output: the mask and
  // silhouettes at the output's pixels, and the side of it each pixel up-samples from.
  gpu::ImageHandle virtual_coverage;
  // The output pixels that raster drew and cleared this frame (VirtualGBuffer::
  // output_coverage_area): the coverage is 0 outside it.
  VkRect2D coverage_area{{0, 0}, {0, 0}};
  // The output stays on the device (an app's image): the camera frame around the tiles is
  // written by the camera pass, not laid on the host.
  bool device_output = false;
  // With device_output at the camera's size on a CPU device: the host already wrote the camera
  // frame into this slot's output words (cheaper there than a pass over every pixel): no camera
  // pass; the tiles are composed over it, and a frame nothing virtual affects adds no pass.
  bool camera_prefilled = false;
};

// `count` camera colour words (recon/reconstruction.h kColorWordBytes: R | G << 8 | B << 16, top
// byte ignored) as RGBA8 pixels with alpha 255.
void camera_words_to_rgba8(const uint32_t* words, size_t count, uint8_t* rgba);

// `image` at w x h, reusing its storage when it already has that size (Runtime::recycle: no
// fresh pages for the OS to zero each frame); every value zero, or, with `zeroed` false, left as
// it was where reused (the caller writes every value).
template <class T, int C>
void reuse_or_allocate(Image<T, C>& image, int w, int h, bool zeroed = true) {
  if (image.width == w && image.height == h && image.data.size() == size_t(w) * h * C) {
    if (zeroed) std::fill(image.data.begin(), image.data.end(), T{});
    return;
  }
  image = Image<T, C>(w, h);
}

class Compose {
 public:
  // same_size_as_camera: the output has the colour camera's size (the camera pixel is read
  // as it is instead of resampled); fixed for the Compose's life.
  static Expected<Compose> create(gpu::Context& context, gpu::FrameGraph& graph, uint32_t width,
                                  uint32_t height, bool same_size_as_camera,
                                  const ComposeSettings& settings = {});
  // Adds the pass "compose" (tiled at the camera's size: and "compose_tile_readback"; tiled at
  // another size: and "compose_camera" before it; with its own classification: "compose_tiles_reset",
  // "compose_tiles" and "compose_tiles_split" before, "compose_real_tiles" after) and marks the
  // readback buffers as outputs.
  Status record(gpu::FrameGraph& graph, const ComposeInputs& inputs);
  // Copies slot `slot`'s results (after its frame completed) into `image` and `mask`
  // (resized to the output size; non-zero mask = virtual pixel).
  Status read(const gpu::FrameGraph& graph, uint32_t slot, ImageRGBA8& image,
              Image<uint8_t, 1>& mask) const;
  // Where a technique composes its own tiles: the readback buffer (RGBA8 words, the virtual
  // mask in alpha: mrgi_shared.h pack_output_word), row-major at the output size, and the
  // guards (mrgi_shared.h compose_encoded). fusable(): the output has the camera's size, the
  // only case in which tiles_composed is honoured.
  gpu::BufferHandle output() const { return output_; }
  const ComposeSettings& settings() const { return settings_; }
  bool fusable() const { return same_size_as_camera_; }

 private:
  void dispatch(VkCommandBuffer cmd, gpu::PassContext& pass, const gpu::Pipeline& pipeline, bool tiled_pass,
                VkDeviceSize args_offset = 0, int first_entry = 0);

  ComposeSettings settings_;
  uint32_t width_ = 0, height_ = 0;
  ComposeInputs in_;
  gpu::BufferHandle output_;
  void record_classify(gpu::FrameGraph& graph);

  // Composite (solutions resampled), composite at the solutions' own size, camera frame only,
  // and the composite over listed tiles from solutions at the output's size or resampled (each
  // also for tiles no virtual surface reaches: no mask or coverage read).
  gpu::PipelineHandle pipeline_, same_internal_pipeline_, camera_pipeline_, tiled_pipeline_,
      tiled_scaled_pipeline_, tiled_real_pipeline_, tiled_scaled_real_pipeline_;
  // The tile classifier (ComposeSettings::classify_tiles): its pipelines (flags, then the two
  // lists), its state (both lists' dispatch arguments, then one flag per output tile) and its
  // lists (shaders/compose/tile_lists.glsl).
  gpu::PipelineHandle classify_pipeline_, split_pipeline_;
  gpu::BufferHandle classify_state_, classify_list_;
  gpu::BufferHandle no_tiles_;  // bound as the tile list when there is none (never read)
  gpu::ImageHandle no_coverage_;  // 1x1, bound as virtual_coverage at the output's size (never read)
  bool tiled_ = false;          // this frame: camera copy + composite over the listed tiles
  bool split_ = false;          // this frame: compose's own two lists (else a technique's one)
  bool same_size_as_camera_ = false;
  uint32_t max_tiles_ = 0;
  VkDeviceSize list_bytes_ = 0;  // this frame's tile-list copy (at most the list's size)
  // Per slot: both lists' args (32 bytes; the second only when split) then the tile indices of
  // that slot's tiled frame (compose/tile_lists.glsl).
  gpu::BufferHandle tile_readback_;
  std::vector<uint8_t> slot_host_camera_;  // per slot: the camera frame is laid on the host
  std::vector<uint8_t> slot_split_;        // per slot: the readback holds two lists
};

}  // namespace mrgi::compose

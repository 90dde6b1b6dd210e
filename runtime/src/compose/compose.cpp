#include "compose/compose.h"

#include <algorithm>
#include <bit>
#include <cstring>

#include <glm/glm.hpp>

#include "gpu/shaders.h"

namespace mrgi::compose {
namespace {

struct ComposePush {
  glm::vec4 compose;
  glm::ivec4 coverage_area;  // x0, y0, x1, y1 (compose.comp ParamsConstants)
  glm::ivec4 tiles{0};       // x: the list's first entry for this dispatch
};

// compose/tile_lists.glsl: the state's words (two dispatch commands, then a flag per tile).
constexpr VkDeviceSize kArgsVirtualBytes = 0, kArgsRealBytes = 16, kStateHeaderBytes = 32;

// Both lists' dispatch commands to (0, 1, 1) and every tile flag to 0; fills over disjoint
// ranges only (overlapping ones in one pass are a write-after-write hazard).
void reset_tile_state(VkCommandBuffer cmd, VkBuffer state) {
  for (VkDeviceSize args : {kArgsVirtualBytes, kArgsRealBytes}) {
    vkCmdFillBuffer(cmd, state, args, 4, 0u);      // x groups
    vkCmdFillBuffer(cmd, state, args + 4, 8, 1u);  // y, z
    vkCmdFillBuffer(cmd, state, args + 12, 4, 0u); // pad
  }
  vkCmdFillBuffer(cmd, state, kStateHeaderBytes, VK_WHOLE_SIZE, 0u);
}

glm::ivec4 area_corners(const VkRect2D& r) {
  return {r.offset.x, r.offset.y, r.offset.x + int(r.extent.width), r.offset.y + int(r.extent.height)};
}

}  // namespace

Expected<Compose> Compose::create(gpu::Context& context, gpu::FrameGraph& graph, uint32_t width,
                                  uint32_t height, bool same_size_as_camera,
                                  const ComposeSettings& settings) {
  Compose c;
  c.settings_ = settings;
  c.width_ = width;
  c.height_ = height;
  c.same_size_as_camera_ = same_size_as_camera;
  c.max_tiles_ = ((width + 7) / 8) * ((height + 7) / 8);
  // Both dispatch commands, then both lists (compose/tile_lists.glsl).
  auto tiles = graph.create_buffer({"compose_tile_readback", kStateHeaderBytes + 2 * VkDeviceSize(c.max_tiles_) * 4,
                                    gpu::MemoryUsage::Readback, true},
                                   VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  if (!tiles) return tiles.error();
  c.tile_readback_ = *tiles;
  c.slot_host_camera_.assign(graph.frames_in_flight(), 0);
  c.slot_split_.assign(graph.frames_in_flight(), 0);
  const VkDeviceSize bytes = VkDeviceSize(width) * height * 4;
  // Transfer source: copied into an app's image (AppOutputImage) instead of read back. Whole
  // groups of 16 pixels: an app's colour image is written into it as the camera words under the
  // composite, 16 pixels at a time (shaders/recon/app_color_words.comp).
  gpu::BufferDesc od{"output_rgba8", (bytes + 63) / 64 * 64, gpu::MemoryUsage::Readback, true};
  auto out = graph.create_buffer(od, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  if (!out) return out.error();
  c.output_ = *out;
  auto spv = gpu::shader_spirv("compose/compose.comp");
  if (!spv) return spv.error();
  // compose.comp: kSameSize, kCameraOnly, kSameInternal, kTiled, kRealTiles; each path compiled
  // out of the others'.
  const struct {
    const char* name;
    uint32_t camera_only, same_internal, tiled, real_tiles;
    gpu::PipelineHandle* handle;
  } variants[] = {{"compose", 0, 0, 0, 0, &c.pipeline_},
                  {"compose_same_internal", 0, 1, 0, 0, &c.same_internal_pipeline_},
                  {"compose_tiled", 0, 1, 1, 0, &c.tiled_pipeline_},
                  {"compose_tiled_scaled", 0, 0, 1, 0, &c.tiled_scaled_pipeline_},
                  {"compose_tiled_real", 0, 1, 1, 1, &c.tiled_real_pipeline_},
                  {"compose_tiled_scaled_real", 0, 0, 1, 1, &c.tiled_scaled_real_pipeline_},
                  {"compose_camera_only", 1, 0, 0, 0, &c.camera_pipeline_}};
  auto no_tiles = graph.create_buffer({"compose_no_tiles", 16}, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (!no_tiles) return no_tiles.error();
  c.no_tiles_ = *no_tiles;
  gpu::ImageDesc none;
  none.name = "compose_no_coverage";
  none.format = VK_FORMAT_R32_SFLOAT;
  none.size_mode = gpu::SizeMode::Absolute;
  none.width = none.height = 1;
  auto no_coverage = graph.create_image(none, VK_IMAGE_USAGE_STORAGE_BIT);
  if (!no_coverage) return no_coverage.error();
  c.no_coverage_ = *no_coverage;
  for (const auto& v : variants) {
    // Bindings and push constants from the shader (the passes bind by name).
    gpu::ComputePipelineDesc d{v.name, *spv, {}, 0,
                               {same_size_as_camera ? 1u : 0u, v.camera_only, v.same_internal,
                                v.tiled, v.real_tiles}};
    auto p = gpu::create_compute_pipeline(context, d);
    if (!p) return p.error();
    *v.handle = gpu::PipelineHandle(context, std::move(*p));
  }
  if (settings.classify_tiles) {
    auto classify = gpu::load_compute_pipeline(context, "compose/tile_classify.comp", {});
    if (!classify) return classify.error();
    c.classify_pipeline_ = std::move(*classify);
    auto split = gpu::load_compute_pipeline(context, "compose/tile_split.comp", {});
    if (!split) return split.error();
    c.split_pipeline_ = std::move(*split);
    auto state = graph.create_buffer({"compose_tile_state", kStateHeaderBytes + VkDeviceSize(c.max_tiles_) * 4},
                                     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT |
                                         VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    if (!state) return state.error();
    c.classify_state_ = *state;
    auto list = graph.create_buffer({"compose_tile_list", 2 * VkDeviceSize(c.max_tiles_) * 4},
                                    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    if (!list) return list.error();
    c.classify_list_ = *list;
  }
  return c;
}

// The tiles of a frame whose technique listed none: reset, tile_classify.comp over the
// solutions' used extent, then tile_split.comp over the output's tiles.
void Compose::record_classify(gpu::FrameGraph& graph) {
  graph.add_pass(
      "compose_tiles_reset", gpu::PassKind::Transfer,
      [this](gpu::PassBuilder& b) { b.write(classify_state_, gpu::Access::TransferDst); },
      [this](VkCommandBuffer cmd, gpu::PassContext& pass) {
        reset_tile_state(cmd, pass.buffer(classify_state_));
      });
  const gpu::Pipeline* pipe = &*classify_pipeline_;
  graph.add_shader_pass(
      "compose_tiles", gpu::PassKind::Compute, *classify_pipeline_,
      [this](gpu::ShaderPassBuilder& b) {
        b.bind("FrameUbo", in_.frame_constants);
        b.bind("lit_rv", in_.lit_rv);
        b.bind("lit_r", in_.lit_r);
        b.bind("virtual_position", in_.virtual_position);
        b.bind("virtual_coverage", in_.virtual_coverage.valid() ? in_.virtual_coverage : no_coverage_);
        b.bind("TileState", classify_state_);
      },
      [this, pipe](VkCommandBuffer cmd, gpu::PassContext& pass) {
        const VkExtent2D used = pass.extent(in_.lit_r);
        struct {
          glm::vec4 compose;
          glm::ivec4 coverage_area;
        } push{{settings_.eps, settings_.alpha_max, in_.tile_tolerance, 0.0f},
               area_corners(in_.coverage_area)};
        gpu::push_and_dispatch(cmd, *pipe, &push, sizeof push, {(used.width + 7) / 8, (used.height + 7) / 8, 1});
      });
  const gpu::Pipeline* split = &*split_pipeline_;
  graph.add_shader_pass(
      "compose_tiles_split", gpu::PassKind::Compute, *split_pipeline_,
      [this](gpu::ShaderPassBuilder& b) {
        b.bind("FrameUbo", in_.frame_constants);
        b.bind("TileState", classify_state_);
        b.bind("TileList", classify_list_);
      },
      [this, split](VkCommandBuffer cmd, gpu::PassContext&) {
        gpu::push_and_dispatch(cmd, *split, nullptr, 0, {(max_tiles_ + 63) / 64, 1, 1});
      });
  in_.tile_args = classify_state_;
  in_.tile_list = classify_list_;
  in_.tiles_composed = false;
}

Status Compose::record(gpu::FrameGraph& graph, const ComposeInputs& inputs) {
  in_ = inputs;
  const bool listed = in_.tile_args.valid() && in_.tile_list.valid();
  // Compose's own classification lists real-only tiles apart (compose/tile_lists.glsl); a
  // technique's list is one list.
  split_ = !in_.camera_only && !listed && classify_state_.valid();
  if (split_) record_classify(graph);
  slot_split_[graph.slot()] = split_ ? 1 : 0;
  tiled_ = !in_.camera_only && in_.tile_args.valid() && in_.tile_list.valid();
  const bool host_camera = tiled_ && same_size_as_camera_ && !in_.device_output;
  slot_host_camera_[graph.slot()] = host_camera ? 1 : 0;
  const bool composed = host_camera && in_.tiles_composed;
  // Every variant declares the same bindings (compose.comp's paths are compiled out of each
  // other, not their declarations): the pass binds them all.
  auto bind_inputs = [this](gpu::ShaderPassBuilder& b) {
    b.bind("FrameUbo", in_.frame_constants);
    b.bind("color_words", in_.color_upload);
    b.bind("lit_rv", in_.lit_rv);
    b.bind("lit_r", in_.lit_r);
    b.bind("virtual_position", in_.virtual_position);
    b.bind("virtual_coverage", in_.virtual_coverage.valid() ? in_.virtual_coverage : no_coverage_);
  };
  if (in_.camera_prefilled && in_.camera_only) {
    graph.mark_output(output_);  // the camera frame the host wrote is the output
    return ok_status();
  }
  if (tiled_ && !host_camera && !in_.camera_prefilled) {
    // The camera frame everywhere, then the composite over the technique's tiles.
    const gpu::Pipeline* pipe = &*camera_pipeline_;
    graph.add_shader_pass(
        "compose_camera", gpu::PassKind::Compute, *pipe,
        [this, bind_inputs](gpu::ShaderPassBuilder& b) {
          bind_inputs(b);
          b.bind("Tiles", no_tiles_);
          b.bind("Output", output_);
        },
        [this, pipe](VkCommandBuffer cmd, gpu::PassContext& pass) { dispatch(cmd, pass, *pipe, false); });
  }
  if (!composed) {
    const VkExtent2D used = graph.extent(in_.lit_r);
    const bool same_internal = used.width == width_ && used.height == height_;
    if (!same_internal && !in_.camera_only && !in_.virtual_coverage.valid()) {
      // The runtime passes the coverage at every reduced scale: without it the mask would be
      // read from a 1x1 placeholder. Composite from the internal mask is not a fallback here.
      return fail(ErrorKind::Internal,
                  "compose: the solutions are " + std::to_string(used.width) + "x" + std::to_string(used.height) +
                      ", the output " + std::to_string(width_) + "x" + std::to_string(height_) +
                      ": the output-resolution coverage (ComposeInputs::virtual_coverage) is required");
    }
    const gpu::Pipeline* pipe = tiled_                         ? (same_internal ? &*tiled_pipeline_ : &*tiled_scaled_pipeline_)
                                : in_.camera_only              ? &*camera_pipeline_
                                : same_internal                ? &*same_internal_pipeline_
                                                               : &*pipeline_;
    // Over the camera pass's output (tiles only): declared read-write so that pass is kept.
    const bool over = tiled_ && !host_camera;
    graph.add_shader_pass(
        "compose", gpu::PassKind::Compute, *pipe,
        [this, bind_inputs, over](gpu::ShaderPassBuilder& b) {
          bind_inputs(b);
          if (tiled_) {
            b.bind("Tiles", in_.tile_list);
            b.uses().read(in_.tile_args, gpu::Access::IndirectRead);
          } else {
            b.bind("Tiles", no_tiles_);
          }
          if (over) {
            b.bind_over("Output", output_);
          } else {
            b.bind("Output", output_);
          }
        },
        [this, pipe](VkCommandBuffer cmd, gpu::PassContext& pass) { dispatch(cmd, pass, *pipe, tiled_); });
    if (split_) {
      // The real-only tiles, over the pass above (disjoint tiles of the same output).
      const gpu::Pipeline* real = same_internal ? &*tiled_real_pipeline_ : &*tiled_scaled_real_pipeline_;
      graph.add_shader_pass(
          "compose_real_tiles", gpu::PassKind::Compute, *real,
          [this, bind_inputs](gpu::ShaderPassBuilder& b) {
            bind_inputs(b);
            b.bind("Tiles", in_.tile_list);
            b.uses().read(in_.tile_args, gpu::Access::IndirectRead);
            b.bind_over("Output", output_);
          },
          [this, real](VkCommandBuffer cmd, gpu::PassContext& pass) {
            dispatch(cmd, pass, *real, true, kArgsRealBytes, int(max_tiles_));
          });
    }
  }
  graph.mark_output(output_);
  if (!host_camera) return ok_status();
  // A technique's list may be smaller than this output's tile count (it lists only its used
  // extent's tiles); the count in args never exceeds what it holds.
  list_bytes_ = std::min<VkDeviceSize>(VkDeviceSize(max_tiles_) * (split_ ? 8 : 4),
                                       graph.gpu_buffer(in_.tile_list, graph.slot()).size);
  graph.add_pass(
      "compose_tile_readback", gpu::PassKind::Transfer,
      [this](gpu::PassBuilder& b) {
        b.read(in_.tile_args, gpu::Access::TransferSrc);
        b.read(in_.tile_list, gpu::Access::TransferSrc);
        b.write(tile_readback_, gpu::Access::TransferDst);
      },
      [this](VkCommandBuffer cmd, gpu::PassContext& pass) {
        const VkBufferCopy args{0, 0, split_ ? kStateHeaderBytes : 16};
        vkCmdCopyBuffer(cmd, pass.buffer(in_.tile_args), pass.buffer(tile_readback_), 1, &args);
        const VkBufferCopy list{0, kStateHeaderBytes, list_bytes_};
        vkCmdCopyBuffer(cmd, pass.buffer(in_.tile_list), pass.buffer(tile_readback_), 1, &list);
      });
  graph.mark_output(tile_readback_);
  return ok_status();
}

// tiled_pass: the composite over the listed tiles (their count in tile_args at args_offset, the
// first at list entry first_entry); otherwise every pixel (the camera copy of a tiled frame, or
// the whole compose of an untiled one).
void Compose::dispatch(VkCommandBuffer cmd, gpu::PassContext& pass, const gpu::Pipeline& pipeline, bool tiled_pass,
                       VkDeviceSize args_offset, int first_entry) {
  ComposePush pc;
  pc.compose = glm::vec4(settings_.eps, settings_.alpha_max, 0.0f, 0.0f);
  pc.coverage_area = area_corners(in_.coverage_area);
  pc.tiles.x = first_entry;
  if (tiled_pass) {
    gpu::dispatch_indirect(cmd, pipeline, &pc, sizeof(pc), pass.buffer(in_.tile_args), args_offset);
  } else {
    gpu::dispatch_2d(cmd, pipeline, &pc, sizeof(pc), width_, height_);
  }
}

void camera_words_to_rgba8(const uint32_t* words, size_t count, uint8_t* rgba) {
  static_assert(std::endian::native == std::endian::little, "RGBA8 words are R | G << 8 | B << 16");
  for (size_t i = 0; i < count; ++i) {
    const uint32_t v = words[i] | 0xff000000u;
    std::memcpy(rgba + 4 * i, &v, 4);
  }
}

namespace {
// `count` words of the readback buffer (mrgi_shared.h pack_output_word: packUnorm4x8, r in the
// low byte, so on a little-endian host the bytes are RGBA; the mask in alpha, 0 or 255) into
// RGBA8 pixels with alpha 255 and the mask.
void unpack_output_words(const uint32_t* words, uint8_t* rgba, uint8_t* mask, size_t count) {
  static_assert(std::endian::native == std::endian::little, "RGBA8 words are R | G << 8 | B << 16");
  for (size_t i = 0; i < count; ++i) {
    const uint32_t v = words[i];
    mask[i] = (v >> 24) >= 128u ? 255 : 0;
    const uint32_t opaque = v | 0xff000000u;
    std::memcpy(rgba + 4 * i, &opaque, 4);
  }
}
}  // namespace

Status Compose::read(const gpu::FrameGraph& graph, uint32_t slot, ImageRGBA8& image,
                     Image<uint8_t, 1>& mask) const {
  const gpu::GpuBuffer& ob = graph.gpu_buffer(output_, slot);
  MRGI_TRY(graph.context().invalidate(ob));
  reuse_or_allocate(image, int(width_), int(height_), false);  // every pixel written below
  // Every mask byte is written below on a whole-frame readback; a tiled one writes only its tiles.
  reuse_or_allocate(mask, int(width_), int(height_), slot_host_camera_[slot] != 0);
  const auto* out = static_cast<const uint32_t*>(graph.mapped(output_, slot));
  if (!slot_host_camera_[slot]) {
    unpack_output_words(out, image.data.data(), mask.data.data(), mask.data.size());
    return ok_status();
  }
  // The camera frame (this slot's upload: colour words at the output size), then the composed tiles.
  const gpu::GpuBuffer& tb = graph.gpu_buffer(tile_readback_, slot);
  MRGI_TRY(graph.context().invalidate(tb));
  uint8_t* px = image.data.data();
  camera_words_to_rgba8(static_cast<const uint32_t*>(graph.mapped(in_.color_upload, slot)), size_t(width_) * height_, px);
  const auto* words = static_cast<const uint32_t*>(graph.mapped(tile_readback_, slot));
  const uint32_t* list = words + kStateHeaderBytes / 4;
  const uint32_t count = std::min(words[0], max_tiles_);  // (the list copy bounds it too)
  // The real-only tiles of compose's own classification, from entry max_tiles_.
  const uint32_t real_count = slot_split_[slot] ? std::min(words[kArgsRealBytes / 4], max_tiles_) : 0;
  const uint32_t tiles_x = (width_ + 7) / 8;
  for (uint32_t k = 0; k < count + real_count; ++k) {
    const uint32_t t = k < count ? list[k] : list[max_tiles_ + (k - count)];
    const uint32_t x0 = (t % tiles_x) * 8, y0 = (t / tiles_x) * 8;
    if (x0 >= width_ || y0 >= height_) continue;  // never written by the GPU either
    const uint32_t w = std::min(8u, width_ - x0);
    for (uint32_t y = y0; y < std::min(y0 + 8, height_); ++y) {
      const size_t i = size_t(y) * width_ + x0;
      unpack_output_words(out + i, px + 4 * i, mask.data.data() + i, w);
    }
  }
  return ok_status();
}

}  // namespace mrgi::compose

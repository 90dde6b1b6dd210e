// The frame graph's per-resource and per-slot records, shared by its .cpp files (private).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "gpu/frame_graph.h"

namespace mrgi::gpu {

// A frame that has not finished after this long is treated as a hung device. Generous because
// the CPU rasteriser (lavapipe, 2 threads) runs the best quality levels at seconds per frame.
inline constexpr uint64_t kFrameTimeoutS = 120;
inline constexpr uint64_t kFrameTimeoutNs = kFrameTimeoutS * 1000ull * 1000 * 1000;

struct FrameGraph::ImageEntry {
  ImageDesc desc;
  GpuImage gpu;
  bool owned = true;
  uint32_t divisor = 1;  // set_extent_divisor: used extent = ceil(relative extent / divisor)
  ResourceState state;                    // level 0's (every level's when there is one)
  std::vector<ResourceState> mip_states;  // every level's, when there are more
  void set_all_levels(const ResourceState& s) {
    state = s;
    if (gpu.mip_levels > 1) mip_states.assign(gpu.mip_levels, s);
  }
};

struct FrameGraph::BufferEntry {
  BufferDesc desc;
  std::vector<GpuBuffer> copies;       // one, or one per frame slot
  std::vector<ResourceState> states;   // per copy
  bool owned = true;
};

struct FrameGraph::Slot {
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  VkQueryPool queries = VK_NULL_HANDLE;
  bool submitted = false;
  int64_t frame_index = -1;
  std::vector<std::string> pass_names;
  std::vector<std::string> culled;
  bool profiled = false;             // this slot's frame ran in profiling mode
  std::vector<double> host_ms;       // profiling mode: per pass, submit to fence
  std::vector<double> cpu_ms;        // profiling mode: per pass, process CPU time meanwhile
};

}  // namespace mrgi::gpu

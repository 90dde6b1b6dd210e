// One raster pass of some of the virtual objects' ranges into cleared targets, for the specular
// stage's views of its objects (the camera's back faces, a lamp's photon G-buffers): drawn with
// gi/rsm_mesh.vert, whose push block (gi/rsm.cpp RsmPush) carries the view and, per draw, the
// range's material (misc.y).
#pragma once
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gi/rsm.h"
#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "frame/scene_gpu.h"

namespace mrgi::specular {

struct MeshRaster {
  std::string name;
  const gpu::Pipeline* pipeline = nullptr;  // rsm_mesh.vert + a fragment shader, binding Materials
  std::vector<gpu::ImageHandle> colour;     // cleared to 0
  gpu::ImageHandle depth;                   // cleared to 1
  VkExtent2D extent{0, 0};                  // {0, 0}: the first colour target's used extent
  std::optional<VkRect2D> area;             // set: drawn and cleared there only (the rest keeps old contents)
  gi::RsmPush push;  // misc.y is set per range
  std::vector<size_t> draws;                // indices into scene.virtual_objects.draws
  // Set: each range at the coarsest level of detail within lod.max_error_px of this view
  // (frame::MeshSet::select_lod); lavapipe sets up every triangle on one thread, and the
  // glass_mirror sphere's 2,200 took half of the camera's back-face pass at half resolution.
  std::optional<frame::LodView> lod;
};

void add_mesh_raster(gpu::FrameGraph& graph, const frame::SceneGpu& scene, const MeshRaster& raster);

// The ranges of the given objects whose material is of one of `kinds` (bits 1 << specular_kind).
std::vector<size_t> specular_draws(const frame::SceneGpu& scene, const std::vector<size_t>& objects, int kinds);

}  // namespace mrgi::specular

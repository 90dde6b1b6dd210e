// One raster pass of some of the virtual objects' ranges into cleared targets, for the specular
// stage's views of its objects (the camera's back faces, a lamp's photon G-buffers): drawn with
// gi/rsm_mesh.vert, whose push block (gi/rsm.cpp RsmPush) carries the view and, per draw, the
// range's material (misc.y).
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "technique/scene_gpu.h"

namespace mrgi::specular {

// gi/rsm_mesh.vert's push block.
struct MeshDrawPush {
  glm::mat4 view_proj{1.0f};
  glm::vec4 light{0.0f};  // xyz: the viewpoint (fragment shaders face normals towards it)
  glm::vec4 colour{0.0f};
  glm::vec4 axis{0.0f};
  glm::ivec4 misc{1, -1, 0, 0};  // y: the draw's material (set per range)
};
static_assert(sizeof(MeshDrawPush) == 128, "the guaranteed push-constant size");

struct MeshRaster {
  std::string name;
  const gpu::Pipeline* pipeline = nullptr;  // rsm_mesh.vert + a fragment shader, binding Materials
  std::vector<gpu::ImageHandle> colour;     // cleared to 0
  gpu::ImageHandle depth;                   // cleared to 1
  VkExtent2D extent{0, 0};                  // {0, 0}: the first colour target's used extent
  MeshDrawPush push;
  std::vector<size_t> draws;                // indices into scene.virtual_objects.draws
};

void add_mesh_raster(gpu::FrameGraph& graph, const technique::SceneGpu& scene, const MeshRaster& raster);

// The ranges of the given objects whose material is of one of `kinds` (bits 1 << specular_kind).
std::vector<size_t> specular_draws(const technique::SceneGpu& scene, const std::vector<size_t>& objects, int kinds);

}  // namespace mrgi::specular

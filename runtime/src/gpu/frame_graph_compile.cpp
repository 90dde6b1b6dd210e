// The pure half of the frame graph: culling and barrier derivation over declared passes. No
// Vulkan calls, so tests check it without a device.
#include <algorithm>

#include "gpu/frame_graph.h"

namespace mrgi::gpu {
namespace {

constexpr VkAccessFlags2 kWriteAccessBits =
    VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT |
    VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT |
    VK_ACCESS_2_HOST_WRITE_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT | VK_ACCESS_2_SHADER_WRITE_BIT;

bool is_shader_access(Access a) {
  return a == Access::Sampled || a == Access::StorageRead || a == Access::StorageWrite ||
         a == Access::StorageReadWrite || a == Access::UniformRead;
}
bool is_attachment_access(Access a) {
  return a == Access::ColorAttachmentWrite || a == Access::ColorAttachmentReadWrite ||
         a == Access::DepthAttachmentWrite || a == Access::DepthAttachmentRead ||
         a == Access::DepthAttachmentReadWrite;
}
bool image_only(Access a) { return is_attachment_access(a) || a == Access::Sampled; }
bool buffer_only(Access a) {
  return a == Access::VertexBuffer || a == Access::IndexBuffer || a == Access::UniformRead ||
         a == Access::IndirectRead;
}
bool write_only(Access a) { return is_write(a) && !is_read(a); }

}  // namespace

bool is_write(Access a) {
  switch (a) {
    case Access::StorageWrite:
    case Access::StorageReadWrite:
    case Access::ColorAttachmentWrite:
    case Access::ColorAttachmentReadWrite:
    case Access::DepthAttachmentWrite:
    case Access::DepthAttachmentReadWrite:
    case Access::TransferDst: return true;
    default: return false;
  }
}

// Reads the contents a previous pass left (so that pass must run).
bool is_read(Access a) {
  switch (a) {
    case Access::StorageWrite:
    case Access::ColorAttachmentWrite:
    case Access::DepthAttachmentWrite:
    case Access::TransferDst: return false;
    default: return true;
  }
}

const char* to_string(Access a) {
  switch (a) {
    case Access::Sampled: return "sampled";
    case Access::StorageRead: return "storage-read";
    case Access::StorageWrite: return "storage-write";
    case Access::StorageReadWrite: return "storage-read-write";
    case Access::ColorAttachmentWrite: return "color-attachment-write";
    case Access::ColorAttachmentReadWrite: return "color-attachment-read-write";
    case Access::DepthAttachmentWrite: return "depth-attachment-write";
    case Access::DepthAttachmentRead: return "depth-attachment-read";
    case Access::DepthAttachmentReadWrite: return "depth-attachment-read-write";
    case Access::TransferSrc: return "transfer-src";
    case Access::TransferDst: return "transfer-dst";
    case Access::VertexBuffer: return "vertex-buffer";
    case Access::IndexBuffer: return "index-buffer";
    case Access::UniformRead: return "uniform";
    case Access::IndirectRead: return "indirect";
  }
  return "?";
}

const char* to_string(PassKind k) {
  switch (k) {
    case PassKind::Compute: return "compute";
    case PassKind::Graphics: return "graphics";
    case PassKind::Transfer: return "transfer";
  }
  return "?";
}

AccessInfo access_info(PassKind kind, Access access, bool is_image, bool depth_format) {
  const VkPipelineStageFlags2 shader =
      kind == PassKind::Compute ? VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT
                                : VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;
  const VkPipelineStageFlags2 tests =
      VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
  AccessInfo r;
  switch (access) {
    case Access::Sampled:
      r = {shader, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
      break;
    case Access::StorageRead:
      r = {shader, VK_ACCESS_2_SHADER_STORAGE_READ_BIT, VK_IMAGE_LAYOUT_GENERAL};
      break;
    case Access::StorageWrite:
      r = {shader, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_IMAGE_LAYOUT_GENERAL};
      break;
    case Access::StorageReadWrite:
      r = {shader, VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
           VK_IMAGE_LAYOUT_GENERAL};
      break;
    case Access::ColorAttachmentWrite:
      r = {VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
           VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
      break;
    case Access::ColorAttachmentReadWrite:
      r = {VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
           VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
           VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
      break;
    case Access::DepthAttachmentWrite:
    case Access::DepthAttachmentReadWrite:
      r = {tests, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
           VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
      break;
    case Access::DepthAttachmentRead:
      r = {tests, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT, VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL};
      break;
    case Access::TransferSrc:
      r = {VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
      break;
    case Access::TransferDst:
      r = {VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL};
      break;
    case Access::VertexBuffer:
      r = {VK_PIPELINE_STAGE_2_VERTEX_ATTRIBUTE_INPUT_BIT, VK_ACCESS_2_VERTEX_ATTRIBUTE_READ_BIT,
           VK_IMAGE_LAYOUT_UNDEFINED};
      break;
    case Access::IndexBuffer:
      r = {VK_PIPELINE_STAGE_2_INDEX_INPUT_BIT, VK_ACCESS_2_INDEX_READ_BIT, VK_IMAGE_LAYOUT_UNDEFINED};
      break;
    case Access::UniformRead:
      r = {shader, VK_ACCESS_2_UNIFORM_READ_BIT, VK_IMAGE_LAYOUT_UNDEFINED};
      break;
    case Access::IndirectRead:
      r = {VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT, VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT, VK_IMAGE_LAYOUT_UNDEFINED};
      break;
  }
  if (!is_image) r.layout = VK_IMAGE_LAYOUT_UNDEFINED;
  (void)depth_format;  // SHADER_READ_ONLY_OPTIMAL is valid for sampled depth images too
  return r;
}

std::vector<Barrier> CompiledGraph::barriers_for(const std::string& resource_name) const {
  std::vector<Barrier> out;
  for (const auto& p : passes)
    for (const auto& b : p.barriers)
      if (b.resource_name == resource_name) out.push_back(b);
  for (const auto& b : final_barriers)
    if (b.resource_name == resource_name) out.push_back(b);
  return out;
}

bool CompiledGraph::runs(const std::string& pass_name) const {
  return std::any_of(passes.begin(), passes.end(), [&](const CompiledPass& p) { return p.name == pass_name; });
}

Expected<CompiledGraph> compile_graph(std::span<const PassDecl> passes,
                                      std::span<const ResourceInfo> resources) {
  const size_t np = passes.size(), nr = resources.size();
  // 1. Validate the declarations.
  for (size_t p = 0; p < np; ++p) {
    const PassDecl& pass = passes[p];
    const std::string where = "pass '" + pass.name + "'";
    for (size_t u = 0; u < pass.uses.size(); ++u) {
      const ResourceUse& use = pass.uses[u];
      if (use.resource.id >= nr)
        return fail(ErrorKind::BadUsage, where + ": resource id " + std::to_string(use.resource.id) + " is not declared");
      const ResourceInfo& res = resources[use.resource.id];
      const std::string what = where + ", resource '" + res.name + "' (" + to_string(use.access) + ")";
      if (res.is_image != use.resource.is_image)
        return fail(ErrorKind::BadUsage, what + ": handle kind does not match the resource");
      if (res.is_image && buffer_only(use.access))
        return fail(ErrorKind::BadUsage, what + ": a buffer access on an image");
      if (!res.is_image && image_only(use.access))
        return fail(ErrorKind::BadUsage, what + ": an image access on a buffer");
      if (pass.kind != PassKind::Graphics &&
          (is_attachment_access(use.access) || use.access == Access::VertexBuffer || use.access == Access::IndexBuffer))
        return fail(ErrorKind::BadUsage, what + ": only graphics passes use attachments and vertex/index buffers");
      if (pass.kind == PassKind::Transfer && is_shader_access(use.access))
        return fail(ErrorKind::BadUsage, what + ": a transfer pass runs no shaders");
      for (size_t v = 0; v < u; ++v)
        if (pass.uses[v].resource == use.resource)
          return fail(ErrorKind::BadUsage, what + ": the resource is declared twice in one pass (declare one "
                                                  "combined access, e.g. storage-read-write)");
    }
  }

  // 2. Culling. Each write makes a new version of a resource; a pass that reads a version needs
  // the pass that wrote it. The passes that must run are those with side effects and the last
  // writers of outputs (marked or history), plus everything they need, transitively. This is
  // Filament's reference-counted culling phrased as reachability.
  std::vector<std::vector<uint32_t>> needs(np);
  std::vector<int> last_writer(nr, -1);
  for (size_t p = 0; p < np; ++p) {
    for (const ResourceUse& use : passes[p].uses)
      if (is_read(use.access) && last_writer[use.resource.id] >= 0)
        needs[p].push_back(uint32_t(last_writer[use.resource.id]));
    for (const ResourceUse& use : passes[p].uses)
      if (is_write(use.access)) last_writer[use.resource.id] = int(p);
  }
  std::vector<char> alive(np, 0);
  std::vector<uint32_t> stack;
  for (size_t p = 0; p < np; ++p)
    if (passes[p].side_effect) stack.push_back(uint32_t(p));
  for (size_t r = 0; r < nr; ++r)
    if ((resources[r].is_output || resources[r].history) && last_writer[r] >= 0)
      stack.push_back(uint32_t(last_writer[r]));
  while (!stack.empty()) {
    const uint32_t p = stack.back();
    stack.pop_back();
    if (alive[p]) continue;
    alive[p] = 1;
    for (uint32_t q : needs[p]) stack.push_back(q);
  }

  // 3. Barriers for the passes that run, in order, from each resource's state.
  CompiledGraph g;
  std::vector<ResourceState> st(nr);
  for (size_t r = 0; r < nr; ++r) st[r] = resources[r].initial;
  std::vector<char> touched(nr, 0);
  for (size_t p = 0; p < np; ++p) {
    if (!alive[p]) {
      g.culled.push_back(passes[p].name);
      continue;
    }
    CompiledPass cp;
    cp.pass_index = uint32_t(p);
    cp.name = passes[p].name;
    for (const ResourceUse& use : passes[p].uses) {
      const uint32_t r = use.resource.id;
      const ResourceInfo& res = resources[r];
      const AccessInfo ai = access_info(passes[p].kind, use.access, res.is_image, false);
      ResourceState& s = st[r];
      const bool layout_change = res.is_image && s.layout != ai.layout;
      const bool writes = is_write(use.access);
      Barrier b;
      b.resource = use.resource;
      b.resource_name = res.name;
      b.dst_stages = ai.stages;
      b.dst_access = ai.access;
      b.old_layout = res.is_image ? s.layout : VK_IMAGE_LAYOUT_UNDEFINED;
      b.new_layout = ai.layout;
      if (writes || layout_change) {
        // Write-after-write, write-after-read and layout transitions wait for the last write and
        // every read since.
        b.src_stages = s.write_stages | s.read_stages;
        b.src_access = s.write_access;
        // A first, write-only touch of a non-history image this frame discards the old contents.
        if (res.is_image && !touched[r] && !res.history && write_only(use.access))
          b.old_layout = VK_IMAGE_LAYOUT_UNDEFINED;
        if (b.src_stages != 0 || layout_change) cp.barriers.push_back(b);
        if (writes) {
          s.write_stages = ai.stages;
          s.write_access = ai.access & kWriteAccessBits;
          s.read_stages = 0;
          s.visible_stages = 0;
          s.visible_access = 0;
        } else {
          // The transition is the last "write"; this read saw it through the barrier.
          s.write_stages = ai.stages;
          s.write_access = 0;
          s.read_stages = ai.stages;
          s.visible_stages = ai.stages;
          s.visible_access = ai.access;
        }
        s.layout = res.is_image ? ai.layout : VK_IMAGE_LAYOUT_UNDEFINED;
      } else {
        // Read-after-write: one barrier per new consumer stage/access; reads after reads need none.
        const bool covered = (ai.stages & ~s.visible_stages) == 0 && (ai.access & ~s.visible_access) == 0;
        if (s.write_stages != 0 && !covered) {
          b.src_stages = s.write_stages;
          b.src_access = s.write_access;
          cp.barriers.push_back(b);
          s.visible_stages |= ai.stages;
          s.visible_access |= ai.access;
        }
        s.read_stages |= ai.stages;
      }
      touched[r] = 1;
    }
    g.passes.push_back(std::move(cp));
  }
  // Readback buffers written this frame are made visible to the host (read after the fence).
  for (size_t r = 0; r < nr; ++r) {
    if (!resources[r].host_read || !touched[r] || st[r].write_access == 0) continue;
    Barrier b;
    b.resource = ResourceRef{resources[r].is_image, uint32_t(r)};
    b.resource_name = resources[r].name;
    b.src_stages = st[r].write_stages;
    b.src_access = st[r].write_access;
    b.dst_stages = VK_PIPELINE_STAGE_2_HOST_BIT;
    b.dst_access = VK_ACCESS_2_HOST_READ_BIT;
    b.old_layout = b.new_layout = st[r].layout;
    g.final_barriers.push_back(b);
    st[r] = ResourceState{};
    st[r].layout = b.new_layout;
  }
  g.final_states = std::move(st);
  return g;
}

}  // namespace mrgi::gpu

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

// Subresources: one per mip level of each resource, flattened (first_sub[r] + level).
struct Subresources {
  std::vector<uint32_t> first_sub;

  explicit Subresources(std::span<const ResourceInfo> resources) : first_sub(resources.size() + 1, 0) {
    for (size_t r = 0; r < resources.size(); ++r) {
      const uint32_t levels = resources[r].is_image ? std::max(1u, resources[r].mip_levels) : 1u;
      first_sub[r + 1] = first_sub[r] + levels;
    }
  }
  size_t count() const { return first_sub.back(); }
  uint32_t levels_of(uint32_t r) const { return first_sub[r + 1] - first_sub[r]; }
  // The levels a use covers: [base, base + count).
  std::pair<uint32_t, uint32_t> range_of(const ResourceUse& use) const {
    const uint32_t levels = levels_of(use.resource.id);
    const uint32_t count = use.mip_count == 0 ? (use.base_mip < levels ? levels - use.base_mip : 0) : use.mip_count;
    return {use.base_mip, count};
  }
};

// The declarations' errors: unknown resources, accesses the resource or the pass kind cannot
// have, mip levels outside the resource, a resource's levels declared twice in one pass.
Status validate_passes(std::span<const PassDecl> passes, std::span<const ResourceInfo> resources,
                       const Subresources& subs) {
  const size_t np = passes.size(), nr = resources.size();
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
      const auto [base, count] = subs.range_of(use);
      if (count == 0 || base + count > subs.levels_of(use.resource.id))
        return fail(ErrorKind::BadUsage, what + ": mip levels " + std::to_string(base) + ".." +
                                             std::to_string(base + count) + " outside the resource's " +
                                             std::to_string(subs.levels_of(use.resource.id)));
      for (size_t v = 0; v < u; ++v) {
        if (!(pass.uses[v].resource == use.resource)) continue;
        const auto [vb, vc] = subs.range_of(pass.uses[v]);
        if (vb < base + count && base < vb + vc)
          return fail(ErrorKind::BadUsage, what + ": the resource is declared twice in one pass (declare one "
                                                  "combined access, e.g. storage-read-write, or disjoint mip levels)");
      }
    }
  }
  return ok_status();
}

// Culling: per pass, whether it runs. Each write makes a new version of a subresource; a pass
// that reads a version needs the pass that wrote it. The passes that must run are those with
// side effects and the last writers of outputs (marked or history, every level), plus everything
// they need, transitively. This is Filament's reference-counted culling phrased as reachability.
std::vector<char> live_passes(std::span<const PassDecl> passes, std::span<const ResourceInfo> resources,
                              const Subresources& subs) {
  const size_t np = passes.size(), nr = resources.size(), ns = subs.count();
  const std::vector<uint32_t>& first_sub = subs.first_sub;
  std::vector<std::vector<uint32_t>> needs(np);
  std::vector<int> last_writer(ns, -1);
  for (size_t p = 0; p < np; ++p) {
    for (const ResourceUse& use : passes[p].uses) {
      if (!is_read(use.access)) continue;
      const auto [base, count] = subs.range_of(use);
      for (uint32_t m = base; m < base + count; ++m)
        if (const int w = last_writer[first_sub[use.resource.id] + m]; w >= 0) needs[p].push_back(uint32_t(w));
    }
    for (const ResourceUse& use : passes[p].uses) {
      if (!is_write(use.access)) continue;
      const auto [base, count] = subs.range_of(use);
      for (uint32_t m = base; m < base + count; ++m) last_writer[first_sub[use.resource.id] + m] = int(p);
    }
  }
  std::vector<char> alive(np, 0);
  std::vector<uint32_t> stack;
  for (size_t p = 0; p < np; ++p)
    if (passes[p].side_effect) stack.push_back(uint32_t(p));
  for (size_t r = 0; r < nr; ++r)
    if (resources[r].is_output || resources[r].history)
      for (uint32_t k = first_sub[r]; k < first_sub[r + 1]; ++k)
        if (last_writer[k] >= 0) stack.push_back(uint32_t(last_writer[k]));
  while (!stack.empty()) {
    const uint32_t p = stack.back();
    stack.pop_back();
    if (alive[p]) continue;
    alive[p] = 1;
    for (uint32_t q : needs[p]) stack.push_back(q);
  }
  return alive;
}

bool same_barrier(const Barrier& a, const Barrier& b) {
  return a.src_stages == b.src_stages && a.src_access == b.src_access && a.dst_stages == b.dst_stages &&
         a.dst_access == b.dst_access && a.old_layout == b.old_layout && a.new_layout == b.new_layout;
}

// One subresource of `res` used with `access` (ai: its stages, access and layout): the source
// side of its barrier into `b` (whose destination side and layouts are filled), and its state
// `s` after the use. `touched`: an earlier pass used it this frame. Returns whether the barrier
// is needed.
bool use_subresource(ResourceState& s, Barrier& b, const ResourceInfo& res, Access access, const AccessInfo& ai,
                     bool touched) {
  const bool writes = is_write(access);
  const bool layout_change = res.is_image && s.layout != ai.layout;
  bool emit = false;
  if (writes || layout_change) {
    // Write-after-write, write-after-read and layout transitions wait for the last write
    // and every read since.
    b.src_stages = s.write_stages | s.read_stages;
    b.src_access = s.write_access;
    // A first, write-only touch of a non-history image this frame discards the old contents.
    if (res.is_image && !touched && !res.history && write_only(access))
      b.old_layout = VK_IMAGE_LAYOUT_UNDEFINED;
    emit = b.src_stages != 0 || layout_change;
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
      emit = true;
      s.visible_stages |= ai.stages;
      s.visible_access |= ai.access;
    }
    s.read_stages |= ai.stages;
  }
  return emit;
}

// The barriers `pass` needs, in the order of its uses, from the subresources' states `st` (left
// as the pass leaves them); neighbouring levels that need the same barrier share one.
void add_pass_barriers(CompiledPass& cp, const PassDecl& pass, std::span<const ResourceInfo> resources,
                       const Subresources& subs, std::vector<ResourceState>& st, std::vector<char>& touched) {
  for (const ResourceUse& use : pass.uses) {
    const uint32_t r = use.resource.id;
    const ResourceInfo& res = resources[r];
    const AccessInfo ai = access_info(pass.kind, use.access, res.is_image, false);
    const auto [base, count] = subs.range_of(use);
    const size_t merge_from = cp.barriers.size();
    for (uint32_t m = base; m < base + count; ++m) {
      const uint32_t k = subs.first_sub[r] + m;
      ResourceState& s = st[k];
      Barrier b;
      b.resource = use.resource;
      b.resource_name = res.name;
      b.base_mip = m;
      b.mip_count = 1;
      b.dst_stages = ai.stages;
      b.dst_access = ai.access;
      b.old_layout = res.is_image ? s.layout : VK_IMAGE_LAYOUT_UNDEFINED;
      b.new_layout = ai.layout;
      const bool emit = use_subresource(s, b, res, use.access, ai, touched[k] != 0);
      touched[k] = 1;
      if (!emit) continue;
      if (cp.barriers.size() > merge_from) {
        Barrier& last = cp.barriers.back();
        if (last.base_mip + last.mip_count == m && same_barrier(last, b)) {
          ++last.mip_count;
          continue;
        }
      }
      cp.barriers.push_back(std::move(b));
    }
  }
}

// Readback buffers written this frame are made visible to the host (read after the fence).
void add_host_read_barriers(CompiledGraph& g, std::span<const ResourceInfo> resources, const Subresources& subs,
                            std::vector<ResourceState>& st, const std::vector<char>& touched) {
  const std::vector<uint32_t>& first_sub = subs.first_sub;
  for (size_t r = 0; r < resources.size(); ++r) {
    const uint32_t k = first_sub[r];
    if (!resources[r].host_read || !touched[k] || st[k].write_access == 0) continue;
    Barrier b;
    b.resource = ResourceRef{resources[r].is_image, uint32_t(r)};
    b.resource_name = resources[r].name;
    b.src_stages = st[k].write_stages;
    b.src_access = st[k].write_access;
    b.dst_stages = VK_PIPELINE_STAGE_2_HOST_BIT;
    b.dst_access = VK_ACCESS_2_HOST_READ_BIT;
    b.old_layout = b.new_layout = st[k].layout;
    b.mip_count = subs.levels_of(uint32_t(r));
    g.final_barriers.push_back(b);
    for (uint32_t m = k; m < first_sub[r + 1]; ++m) {
      st[m] = ResourceState{};
      st[m].layout = b.new_layout;
    }
  }
}

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
  const Subresources subs(resources);
  const std::vector<uint32_t>& first_sub = subs.first_sub;
  const size_t ns = subs.count();

  // 1. Validate the declarations.
  MRGI_TRY(validate_passes(passes, resources, subs));

  // 2. Culling (live_passes).
  const std::vector<char> alive = live_passes(passes, resources, subs);

  // 3. Barriers for the passes that run, in order, from each subresource's state; neighbouring
  // levels that need the same barrier share one.
  CompiledGraph g;
  std::vector<ResourceState> st(ns);
  for (size_t r = 0; r < nr; ++r)
    for (uint32_t m = 0; m < subs.levels_of(uint32_t(r)); ++m)
      st[first_sub[r] + m] = m < resources[r].initial_mips.size() ? resources[r].initial_mips[m] : resources[r].initial;
  std::vector<char> touched(ns, 0);
  for (size_t p = 0; p < np; ++p) {
    if (!alive[p]) {
      g.culled.push_back(passes[p].name);
      continue;
    }
    CompiledPass cp;
    cp.pass_index = uint32_t(p);
    cp.name = passes[p].name;
    add_pass_barriers(cp, passes[p], resources, subs, st, touched);
    g.passes.push_back(std::move(cp));
  }
  add_host_read_barriers(g, resources, subs, st, touched);
  g.final_states.resize(nr);
  g.final_mip_states.resize(nr);
  for (size_t r = 0; r < nr; ++r) {
    g.final_states[r] = st[first_sub[r]];
    if (subs.levels_of(uint32_t(r)) > 1)
      g.final_mip_states[r].assign(st.begin() + first_sub[r], st.begin() + first_sub[r + 1]);
  }
  return g;
}

}  // namespace mrgi::gpu

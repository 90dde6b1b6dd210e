#include "mrgi/perf/lpv_costs.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <optional>

#include <glm/gtc/packing.hpp>

#include "gi/light_propagation.h"
#include "gpu/context.h"
#include "gpu/floor_pass.h"
#include "gpu/frame_graph.h"
#include "mrgi/perf/stats.h"

namespace mrgi::perf {
namespace {

// The paper's figures (ms, NVIDIA GTX 470): Table 3, V^Delta propagation by volume size and steps;
// Table 2, full injection by RSM size (V^rho, V^Delta delta, V^Delta direct).
const std::map<std::pair<uint32_t, uint32_t>, double> kPaperTable3 = {
    {{16, 16}, 0.712},  {{16, 32}, 1.815},  {{32, 16}, 2.342},  {{32, 32}, 4.552},  {{32, 64}, 8.857},
    {{64, 16}, 11.148}, {{64, 32}, 22.021}, {{64, 64}, 43.23}};
const std::map<uint32_t, std::array<double, 3>> kPaperTable2 = {
    {256, {0.091, 0.184, 0.18}}, {512, {0.462, 0.862, 0.895}}, {1024, {2.108, 4.667, 4.494}},
    {2048, {10.74, 21.35, 20.215}}};

// A map of size x size texels: a floor of VPLs across the volume's middle (every texel valid,
// facing up), lit from above, and a second map 0.1 m higher (the "other" map of direct mode).
struct Maps {
  gi::RsmImages rsm, raised;
};

Expected<Maps> make_maps(gpu::FrameGraph& graph, uint32_t size, float volume_side) {
  auto image = [&](const std::string& name, VkFormat f) -> Expected<gpu::ImageHandle> {
    gpu::ImageDesc d;
    d.name = name;
    d.format = f;
    d.size_mode = gpu::SizeMode::Absolute;
    d.width = d.height = size;
    return graph.create_image(d, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
  };
  const std::string n = "lpv costs " + std::to_string(size);
  auto pos = image(n + " position", VK_FORMAT_R32G32B32A32_SFLOAT);
  if (!pos) return pos.error();
  auto raised = image(n + " raised position", VK_FORMAT_R32G32B32A32_SFLOAT);
  if (!raised) return raised.error();
  auto nor = image(n + " normal", VK_FORMAT_R16G16B16A16_SFLOAT);
  if (!nor) return nor.error();
  auto flux = image(n + " flux", VK_FORMAT_R32G32B32A32_SFLOAT);
  if (!flux) return flux.error();
  std::vector<float> p(size_t(size) * size * 4), q(p.size()), f(p.size());
  std::vector<uint16_t> nn(p.size());
  for (uint32_t y = 0; y < size; ++y)
    for (uint32_t x = 0; x < size; ++x) {
      const size_t i = (size_t(y) * size + x) * 4;
      const float u = (float(x) + 0.5f) / float(size) * volume_side, v = (float(y) + 0.5f) / float(size) * volume_side;
      const float h = 0.5f * volume_side;
      p[i] = u, p[i + 1] = h, p[i + 2] = v, p[i + 3] = 1.0f;
      q[i] = u, q[i + 1] = h + 0.1f, q[i + 2] = v, q[i + 3] = 1.0f;
      nn[i] = 0, nn[i + 1] = uint16_t(glm::packHalf1x16(1.0f)), nn[i + 2] = 0, nn[i + 3] = 0;
      f[i] = f[i + 1] = f[i + 2] = 1e-4f, f[i + 3] = 2e-4f;
    }
  MRGI_TRY(graph.upload_image(*pos, p.data(), p.size() * 4));
  MRGI_TRY(graph.upload_image(*raised, q.data(), q.size() * 4));
  MRGI_TRY(graph.upload_image(*nor, nn.data(), nn.size() * 2));
  MRGI_TRY(graph.upload_image(*flux, f.data(), f.size() * 4));
  Maps m;
  m.rsm = {*pos, *nor, *flux, size, size};
  m.raised = m.rsm;
  m.raised.position = *raised;
  return m;
}

}  // namespace

Expected<LpvCosts> measure_lpv_costs(const LpvCostSettings& s,
                                     const std::function<void(const std::string&, size_t, size_t)>& progress) {
  if (s.volume_sizes.empty() || s.steps.empty() || s.repeats < 1)
    return fail(ErrorKind::BadUsage, "lpv-costs: volume sizes, steps and repeats >= 1 needed");
  const uint32_t top = *std::max_element(s.volume_sizes.begin(), s.volume_sizes.end());
  for (uint32_t v : s.volume_sizes)
    if (v < 2 || top % v != 0)
      return fail(ErrorKind::BadUsage, "lpv-costs: volume size " + std::to_string(v) + " must be >= 2 and divide " +
                                           std::to_string(top));
  for (uint32_t r : s.rsm_sizes)
    if (r < 16 || r > 4096) return fail(ErrorKind::BadUsage, "lpv-costs: RSM size " + std::to_string(r) + " outside 16..4096");
  auto ctx_or = gpu::Context::create(s.device);
  if (!ctx_or) return ctx_or.error();
  gpu::Context& ctx = **ctx_or;
  LpvCosts out;
  out.device = ctx.info().name;
  out.driver = ctx.info().driver;
  if (const char* t = std::getenv("LP_NUM_THREADS")) out.lp_num_threads = std::atoi(t);
  auto floor = gpu::measure_floor_pass(ctx, 640, 480, uint32_t(std::max(s.repeats, 5)));
  if (!floor) return floor.error();
  out.floor_median_ms = floor->median_ms;

  gpu::FrameGraphSettings fs;
  fs.max_output_width = fs.max_output_height = 16;
  fs.frames_in_flight = 1;
  fs.max_passes = 8;
  auto graph_or = gpu::FrameGraph::create(ctx, fs);
  if (!graph_or) return graph_or.error();
  gpu::FrameGraph& graph = **graph_or;
  MRGI_TRY(graph.set_profiling(true));
  gi::LpvSettings ls;
  ls.name = "lpv costs";
  ls.resolution = top;
  auto lpv_or = gi::LightPropagationVolume::create(graph, ls);
  if (!lpv_or) return lpv_or.error();
  gi::LightPropagationVolume& lpv = *lpv_or;
  const float side = 2.0f;  // metres; the cell size follows the used size
  const gi::LpvLight sun{glm::vec3(0.0f, -1.0f, 0.0f), false, glm::vec3(1.0f)};
  std::map<uint32_t, Maps> maps;
  std::vector<uint32_t> rsm_sizes = s.rsm_sizes;
  if (std::find(rsm_sizes.begin(), rsm_sizes.end(), 512u) == rsm_sizes.end()) rsm_sizes.push_back(512);
  for (uint32_t r : rsm_sizes) {
    auto m = make_maps(graph, r, side);
    if (!m) return m.error();
    maps.emplace(r, *m);
  }
  // Runs one frame of `add` (repeats + 1 times, the first a warm-up) and returns the median of
  // each named pass.
  auto time_frames = [&](const std::function<void()>& add, const std::vector<std::string>& names)
      -> Expected<std::vector<double>> {
    std::map<std::string, std::vector<double>> ms;
    for (int i = 0; i < s.repeats + 1; ++i) {
      auto done = graph.begin_frame();
      if (!done) return done.error();
      add();
      MRGI_TRY(graph.submit());
      auto flushed = graph.flush();
      if (!flushed) return flushed.error();
      if (i == 0) continue;
      for (const gpu::FrameTimings& t : *flushed)
        for (const PassTiming& p : t.passes) ms[p.name].push_back(p.gpu_ms);
    }
    std::vector<double> medians;
    for (const std::string& n : names) {
      if (ms[n].empty()) return fail(ErrorKind::Internal, "lpv-costs: no timing of pass '" + n + "'");
      medians.push_back(median(ms[n]));
    }
    return medians;
  };
  const size_t total = s.volume_sizes.size() * s.steps.size() + s.rsm_sizes.size();
  size_t done = 0;
  for (uint32_t v : s.volume_sizes) {
    MRGI_TRY(lpv.set_cells(graph, v));
    lpv.set_grid({glm::vec3(0.0f), side / float(v)});
    for (uint32_t st : s.steps) {
      if (progress) progress(std::to_string(v) + "^3 x " + std::to_string(st), done++, total);
      auto t = time_frames(
          [&] {
            lpv.add_clear(graph);
            lpv.add_inject(graph, "rho", maps.at(512).rsm, sun, gi::InjectKind::Indirect, 1.0f);
            lpv.add_propagate(graph, st);
            graph.mark_output(lpv.accumulated(0));
          },
          {"lpv costs propagate"});
      if (!t) return t.error();
      out.propagation.push_back({v, st, (*t)[0]});
    }
  }
  MRGI_TRY(lpv.set_cells(graph, std::min<uint32_t>(top, 32)));
  lpv.set_grid({glm::vec3(0.0f), side / float(std::min<uint32_t>(top, 32))});
  for (uint32_t r : s.rsm_sizes) {
    if (progress) progress("RSM " + std::to_string(r) + "^2", done++, total);
    const Maps& m = maps.at(r);
    auto t = time_frames(
        [&] {
          lpv.add_clear(graph);
          lpv.add_inject(graph, "rho", m.rsm, sun, gi::InjectKind::Indirect, 1.0f);
          lpv.add_inject(graph, "mu", m.rsm, sun, gi::InjectKind::Indirect, -1.0f);
          lpv.add_inject(graph, "direct", m.rsm, sun, gi::InjectKind::Direct, -1.0f, &m.raised);
          lpv.add_propagate(graph, 0);
          graph.mark_output(lpv.accumulated(0));
        },
        {"lpv costs inject rho", "lpv costs inject mu", "lpv costs inject direct"});
    if (!t) return t.error();
    // Table 2's "V^Delta delta" injects both maps (+rho, -mu): the sum of the two passes.
    out.injection.push_back({r, (*t)[0], (*t)[0] + (*t)[1], (*t)[2]});
  }
  if (progress) progress("done", total, total);
  return out;
}

std::string lpv_costs_markdown(const LpvCosts& c) {
  std::string md;
  char line[512];
  std::snprintf(line, sizeof line,
                "# Light propagation volume costs\n\nDevice %s (%s), LP_NUM_THREADS %d, floor pass %.3f ms. "
                "Each entry the median of the profiled pass (`mrgi lpv-costs`); the paper's figures are "
                "NVIDIA GTX 470 (DLPV paper, Tables 2 and 3). *shape*: the entry over the table's own "
                "entry at the reference (32^3 x 32 steps; RSM 512^2), ours / the paper's: 1 = the cost "
                "grows the same way.\n\n",
                c.device.c_str(), c.driver.c_str(), c.lp_num_threads, c.floor_median_ms);
  md += line;
  md += "## Propagation (Table 3): volume size x steps, ms\n\n| volume | steps | mrgi ms | floors | paper ms | mrgi shape | paper shape | shape ratio |\n|---|---:|---:|---:|---:|---:|---:|---:|\n";
  double ref = 0.0;
  for (const auto& p : c.propagation)
    if (p.size == 32 && p.steps == 32) ref = p.ms;
  const double paper_ref = kPaperTable3.at({32, 32});
  for (const auto& p : c.propagation) {
    const auto it = kPaperTable3.find({p.size, p.steps});
    const double ours = ref > 0.0 ? p.ms / ref : 0.0;
    if (it != kPaperTable3.end() && ref > 0.0) {
      const double theirs = it->second / paper_ref;
      std::snprintf(line, sizeof line, "| %u^3 | %u | %.2f | %.1f | %.3f | %.3f | %.3f | %.2f |\n", p.size, p.steps, p.ms,
                    p.ms / c.floor_median_ms, it->second, ours, theirs, theirs > 0.0 ? ours / theirs : 0.0);
    } else {
      char paper[32] = "-", shape[32] = "-";
      if (it != kPaperTable3.end()) std::snprintf(paper, sizeof paper, "%.3f", it->second);
      if (ref > 0.0) std::snprintf(shape, sizeof shape, "%.3f", ours);
      std::snprintf(line, sizeof line, "| %u^3 | %u | %.2f | %.1f | %s | %s | - | - |\n", p.size, p.steps, p.ms,
                    p.ms / c.floor_median_ms, paper, shape);
    }
    md += line;
  }
  md += "\n## Injection (Table 2): every RSM texel a VPL, ms\n\n| RSM | V^rho | V^Delta delta (+rho, -mu) | V^Delta direct | paper V^rho / delta / direct | shape ratio (V^rho) |\n|---|---:|---:|---:|---:|---:|\n";
  double iref = 0.0;
  for (const auto& i : c.injection)
    if (i.rsm == 512) iref = i.rho_ms;
  for (const auto& i : c.injection) {
    const auto it = kPaperTable2.find(i.rsm);
    if (it != kPaperTable2.end() && iref > 0.0) {
      const double shape = (i.rho_ms / iref) / (it->second[0] / kPaperTable2.at(512)[0]);
      std::snprintf(line, sizeof line, "| %u^2 | %.2f | %.2f | %.2f | %.3f / %.3f / %.3f | %.2f |\n", i.rsm, i.rho_ms,
                    i.delta_ms, i.direct_ms, it->second[0], it->second[1], it->second[2], shape);
    } else {
      std::snprintf(line, sizeof line, "| %u^2 | %.2f | %.2f | %.2f | - | - |\n", i.rsm, i.rho_ms, i.delta_ms, i.direct_ms);
    }
    md += line;
  }
  return md;
}

}  // namespace mrgi::perf

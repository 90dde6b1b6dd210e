// The frame graph's submission: a frame's command buffer with the app's semaphores, and
// profiling mode (each pass submitted alone and host-timed), flush. Resources, slots and
// recording are in frame_graph.cpp.
#include <algorithm>
#include <chrono>
#include <string>

#include "gpu/frame_graph.h"
#include "gpu/frame_graph_entries.h"
#include "gpu/vk_check.h"

namespace mrgi::gpu {

Status FrameGraph::set_profiling(bool on) {
  if (on && profile_cmds_.empty())
    return fail(ErrorKind::BadUsage, "set_profiling: the frame graph was created without "
                                     "FrameGraphSettings::allow_profiling");
  if (in_frame_) return fail(ErrorKind::BadUsage, "set_profiling: between frames only");
  profiling_ = on;
  return ok_status();
}

Expected<double> FrameGraph::submit_and_wait(VkCommandBuffer cmd, const std::string* pass) {
  VkDevice dev = context_.device();
  VkCommandBufferSubmitInfo cbi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
  cbi.commandBuffer = cmd;
  VkSubmitInfo2 si{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  si.commandBufferInfoCount = 1;
  si.pCommandBufferInfos = &cbi;
  const auto t0 = std::chrono::steady_clock::now();
  VK_CHECK(context_.queue_submit2(si, profile_fence_));
  const VkResult w = vkWaitForFences(dev, 1, &profile_fence_, VK_TRUE, kFrameTimeoutNs);
  auto t1 = std::chrono::steady_clock::now();
  if (w == VK_TIMEOUT)
    return fail(ErrorKind::Timeout, (pass ? "pass '" + *pass + "'" : std::string("an empty submission")) +
                                        " did not finish within " + std::to_string(kFrameTimeoutS) +
                                        " s (profiling mode)");
  VK_CHECK(w);
  VK_CHECK(vkResetFences(dev, 1, &profile_fence_));
  const auto planted = pass ? std::find_if(plants_.begin(), plants_.end(), [&](const auto& p) { return p.first == *pass; })
                            : plants_.end();
  if (planted != plants_.end()) {  // test hook: see frame_graph.h
    const auto until = t0 + (t1 - t0) * planted->second;
    while (std::chrono::steady_clock::now() < until) {
    }
    t1 = std::chrono::steady_clock::now();
  }
  return std::chrono::duration<double, std::milli>(t1 - t0).count();
}

Status FrameGraph::measure_submission_overhead() {
  VkCommandBuffer cmd = profile_cmds_[0];
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  constexpr int kSamples = 7;
  std::vector<double> ms;
  for (int i = 0; i < kSamples; ++i) {
    VK_CHECK(vkResetCommandBuffer(cmd, 0));
    VK_CHECK(vkBeginCommandBuffer(cmd, &bi));
    VK_CHECK(vkEndCommandBuffer(cmd));
    auto t = submit_and_wait(cmd, nullptr);
    if (!t) return t.error();
    ms.push_back(*t);
  }
  // The fastest of the empty submissions: load on the machine only lengthens one, and an
  // overhead taken while another process held the cores (the median was, once) exceeded a short
  // pass's whole time, so every sample of it clamped to 0 ms (the floor pass's median with it).
  submission_overhead_ms_ = *std::min_element(ms.begin(), ms.end());
  return ok_status();
}

Status FrameGraph::add_submit_wait(VkSemaphore wait, VkPipelineStageFlags2 stage) {
  if (wait == VK_NULL_HANDLE) return ok_status();
  if (submit_wait_count_ == kMaxSubmitWaits)
    return fail(ErrorKind::BadUsage, "add_submit_wait: at most " + std::to_string(kMaxSubmitWaits) +
                                         " wait semaphores a frame");
  VkSemaphoreSubmitInfo& w = submit_waits_[submit_wait_count_++];
  w = VkSemaphoreSubmitInfo{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
  w.semaphore = wait;
  w.stageMask = stage;
  return ok_status();
}

void FrameGraph::add_submit_semaphores(VkSubmitInfo2& si, VkSemaphoreSubmitInfo& signal) {
  if (submit_wait_count_ > 0) {
    si.waitSemaphoreInfoCount = submit_wait_count_;
    si.pWaitSemaphoreInfos = submit_waits_.data();
  }
  if (submit_signal_) {
    signal.semaphore = submit_signal_;
    signal.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    si.signalSemaphoreInfoCount = 1;
    si.pSignalSemaphoreInfos = &signal;
  }
  submit_wait_count_ = 0;
  submit_signal_ = VK_NULL_HANDLE;
}

Status FrameGraph::submit_profiled() {
  const uint32_t n = uint32_t(compiled_.passes.size());
  if (n > profile_cmds_.size())
    return fail(ErrorKind::BadUsage, std::to_string(n) + " passes, more than the " +
                                         std::to_string(profile_cmds_.size()) + " profiling command buffers");
  // The frame that used this slot before has completed (begin_frame waited), but the other
  // slots' frames may still run: wait for them, so the first pass's time is its own.
  MRGI_TRY(wait_submitted());
  if (submit_wait_count_ > 0) {
    // The passes are submitted one by one: the frame's wait semaphores are waited for first, by
    // an empty submission the host waits on, so every pass runs after them.
    VkSubmitInfo2 si{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    for (uint32_t i = 0; i < submit_wait_count_; ++i) submit_waits_[i].stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    si.waitSemaphoreInfoCount = submit_wait_count_;
    si.pWaitSemaphoreInfos = submit_waits_.data();
    VK_CHECK(context_.queue_submit2(si, profile_fence_));
    const VkResult w = vkWaitForFences(context_.device(), 1, &profile_fence_, VK_TRUE, kFrameTimeoutNs);
    if (w == VK_TIMEOUT)
      return fail(ErrorKind::Timeout, "the frame's wait semaphore was not signalled within " +
                                          std::to_string(kFrameTimeoutS) + " s (profiling mode)");
    VK_CHECK(w);
    VK_CHECK(vkResetFences(context_.device(), 1, &profile_fence_));
    submit_wait_count_ = 0;
  }
  Slot& slot = slots_[slot_];
  slot.host_ms.assign(n, 0.0);
  slot.cpu_ms.assign(n, 0.0);
  PassContext ctx(*this);
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  for (uint32_t i = 0; i < n; ++i) {
    const CompiledPass& p = compiled_.passes[i];
    VkCommandBuffer cmd = profile_cmds_[i];
    VK_CHECK(vkResetCommandBuffer(cmd, 0));
    VK_CHECK(vkBeginCommandBuffer(cmd, &bi));
    record_barriers(cmd, p.barriers);
    run_pass(cmd, p.pass_index, ctx);
    if (i + 1 == n) record_barriers(cmd, compiled_.final_barriers);
    VK_CHECK(vkEndCommandBuffer(cmd));
    // Recording is not timed: the pass's time is what the queue spends on it.
    const double cpu0 = process_cpu_ms();
    auto ms = submit_and_wait(cmd, &p.name);
    if (!ms) return ms.error();
    slot.host_ms[i] = std::max(0.0, *ms - submission_overhead_ms_);
    slot.cpu_ms[i] = process_cpu_ms() - cpu0;
  }
  finish_execute(true);
  // The slot's fence marks the frame done, as in normal mode (an empty submission signals it,
  // and the frame's semaphores: the passes' submissions before it have all completed).
  VkSubmitInfo2 si{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  VkSemaphoreSubmitInfo signal{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
  add_submit_semaphores(si, signal);
  VK_CHECK(context_.queue_submit2(si, slot.fence));
  slot.submitted = true;
  in_frame_ = false;
  return ok_status();
}

Status FrameGraph::submit() {
  if (!in_frame_) return fail(ErrorKind::BadUsage, "submit: call begin_frame first");
  if (!compiled_valid_) MRGI_TRY(compile());
  if (profiling_) return submit_profiled();
  Slot& slot = slots_[slot_];
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(slot.cmd, &bi));
  MRGI_TRY(execute(slot.cmd));
  VK_CHECK(vkEndCommandBuffer(slot.cmd));
  VkCommandBufferSubmitInfo cbi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
  cbi.commandBuffer = slot.cmd;
  VkSubmitInfo2 si{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  si.commandBufferInfoCount = 1;
  si.pCommandBufferInfos = &cbi;
  VkSemaphoreSubmitInfo signal{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
  add_submit_semaphores(si, signal);
  VK_CHECK(context_.queue_submit2(si, slot.fence));
  slot.submitted = true;
  in_frame_ = false;
  return ok_status();
}

Expected<std::vector<FrameTimings>> FrameGraph::flush() {
  if (in_frame_) return fail(ErrorKind::BadUsage, "flush: the current frame was not submitted");
  std::vector<FrameTimings> out;
  const uint32_t n = uint32_t(slots_.size());
  // Oldest first: the slot after the current one is the oldest in flight.
  for (uint32_t k = 1; k <= n; ++k) {
    const uint32_t index = (slot_ + k) % n;
    auto t = collect(index);
    if (!t) return t.error();
    if (*t) out.push_back(std::move(**t));
  }
  return out;
}

}  // namespace mrgi::gpu

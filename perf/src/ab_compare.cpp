// `mrgi bench --compare BASE`: the two workers, the interleaved measurements, the judgement
// (mrgi/perf/ab_compare.h).
#include "mrgi/perf/ab_compare.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>

#include <nlohmann/json.hpp>

#include "mrgi/perf/bench.h"
#include "mrgi/perf/stats.h"
#include "mrgi/runtime.h"

namespace mrgi::perf {
namespace {

using nlohmann::json;

// A worker process (`BINARY bench --serve`) with a pipe each way.
class Worker {
 public:
  static Expected<std::unique_ptr<Worker>> start(const std::string& binary, const std::string& device,
                                                 const std::string& role) {
    int to_child[2], from_child[2];
    if (pipe2(to_child, O_CLOEXEC) != 0) return fail(ErrorKind::Internal, "pipe: " + std::string(strerror(errno)));
    if (pipe2(from_child, O_CLOEXEC) != 0) {
      close(to_child[0]);
      close(to_child[1]);
      return fail(ErrorKind::Internal, "pipe: " + std::string(strerror(errno)));
    }
    std::vector<std::string> args = {binary, "bench", "--serve"};
    if (!device.empty()) args.insert(args.end(), {"--device", device});
    const pid_t pid = fork();
    if (pid < 0) return fail(ErrorKind::Internal, "fork: " + std::string(strerror(errno)));
    if (pid == 0) {
      dup2(to_child[0], STDIN_FILENO);
      dup2(from_child[1], STDOUT_FILENO);
      std::vector<char*> argv;
      for (std::string& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      execv(binary.c_str(), argv.data());
      std::fprintf(stderr, "mrgi bench --compare: cannot run %s: %s\n", binary.c_str(), strerror(errno));
      _exit(127);
    }
    close(to_child[0]);
    close(from_child[1]);
    auto w = std::unique_ptr<Worker>(new Worker());
    w->pid_ = pid;
    w->role_ = role;
    w->binary_ = binary;
    w->in_ = fdopen(to_child[1], "w");
    w->out_ = fdopen(from_child[0], "r");
    auto hello = w->read_answer();
    if (!hello.ok() || hello->value("protocol", 0) != 1)
      return fail(ErrorKind::BadInput, role + " " + binary +
                                           ": did not answer as an mrgi bench worker (`bench --serve`, protocol 1)" +
                                           (hello.ok() ? "" : ": " + hello.error().message));
    w->source_ = hello->value("source", "");
    return w;
  }
  ~Worker() {
    if (in_) {
      std::fputs("{\"op\":\"quit\"}\n", in_);
      std::fclose(in_);
    }
    if (out_) std::fclose(out_);
    if (pid_ > 0) {
      int status = 0;
      for (int i = 0; i < 100 && waitpid(pid_, &status, WNOHANG) == 0; ++i) usleep(50000);
      if (waitpid(pid_, &status, WNOHANG) == 0) {
        kill(pid_, SIGKILL);
        waitpid(pid_, &status, 0);
      }
    }
  }
  Expected<json> ask(const json& request) {
    const std::string line = request.dump() + "\n";
    if (std::fputs(line.c_str(), in_) < 0 || std::fflush(in_) != 0)
      return fail(ErrorKind::Internal, role_ + " " + binary_ + ": the worker stopped reading");
    auto a = read_answer();
    if (!a.ok()) return a.error();
    if (!a->value("ok", false))
      return fail(ErrorKind::BadInput, role_ + " " + binary_ + ": " + a->value("error", std::string("failed")));
    return a;
  }
  const std::string& source() const { return source_; }

 private:
  Worker() = default;
  Expected<json> read_answer() {
    std::string line;
    for (int c; (c = std::fgetc(out_)) != EOF && c != '\n';) line.push_back(char(c));
    if (line.empty()) return fail(ErrorKind::Internal, role_ + " " + binary_ + ": the worker ended without an answer");
    try {
      return json::parse(line);
    } catch (const std::exception& e) {
      return fail(ErrorKind::Internal, role_ + " " + binary_ + ": unreadable answer '" + line.substr(0, 200) + "'");
    }
  }
  pid_t pid_ = -1;
  std::string role_, binary_, source_;
  FILE* in_ = nullptr;
  FILE* out_ = nullptr;
};

std::string git_head(const std::string& dir) {
  if (dir.empty()) return "";
  FILE* p = popen(("git -C '" + dir + "' rev-parse HEAD 2>/dev/null").c_str(), "r");
  if (!p) return "";
  char buf[128] = {0};
  std::string s = std::fgets(buf, sizeof buf, p) ? buf : "";
  pclose(p);
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s;
}

}  // namespace

double pass_over_rest(const std::map<std::string, double>& passes, const std::string& pass) {
  double own = std::nan(""), rest = 0.0;
  for (const auto& [name, ms] : passes) {
    if (name == pass) own = ms;
    else if (std::isfinite(ms)) rest += ms;
  }
  return rest > 0.0 ? own / rest : std::nan("");
}

namespace {

// One entry's answers from both builds, pair by pair.
struct EntrySamples {
  std::string level_name;
  std::vector<json> answers[2];
  // The field (or the pass's entry in the object `field`) of every answer of one side, NaN where
  // an answer lacks it (a pass a frame skipped): judge_pairs leaves such pairs out.
  std::vector<double> series(int side, const std::string& field, const std::string& pass = "") const {
    std::vector<double> v;
    for (const json& a : answers[side]) {
      const json* at = pass.empty() ? (a.contains(field) ? &a[field] : nullptr)
                                    : (a.contains(field) && a[field].contains(pass) ? &a[field][pass] : nullptr);
      v.push_back(at && at->is_number() ? at->get<double>() : std::nan(""));
    }
    return v;
  }
  // kSchedulerMetric of every answer of one side (NaN where an answer lacks the counts).
  std::vector<double> frames_per_frame_within_budget(int side) const {
    std::vector<double> v;
    for (const json& a : answers[side]) {
      const bool has = a.contains("budget_frames") && a.contains("within_budget_frames");
      v.push_back(has ? (a["budget_frames"].get<double>() + 2.0) / (a["within_budget_frames"].get<double>() + 1.0)
                      : std::nan(""));
    }
    return v;
  }
  // A pass's fastest profiled frame over the rest of the measurement's passes (each by its
  // fastest frame) for every answer of one side, NaN where the pass is missing: the machine
  // speeding up or slowing down between measurements moves a pass and the rest of its frame
  // alike, so the ratio keeps a change of this pass and drops the drift (a small pass's raw time
  // spread 15-25 % between measurements of one build; a slowdown of another pass lowers this
  // ratio, never raises it, so it raises no alarm here).
  std::vector<double> pass_relative(int side, const std::string& pass) const {
    std::vector<double> v;
    std::map<std::string, double> passes;
    for (const json& a : answers[side]) {
      passes.clear();
      if (a.contains("passes_min") && a["passes_min"].is_object())
        for (auto& [name, ms] : a["passes_min"].items())
          if (ms.is_number()) passes[name] = ms.get<double>();
      v.push_back(pass_over_rest(passes, pass));
    }
    return v;
  }
};

// An entry's judged quantities: sustained ms, CPU ms, and each pass taking at least
// pass_min_share of the base's profiled frame, as its fastest profiled frame of each
// measurement (load only adds time) over the rest of that measurement's passes (pass_relative).
void add_quantities(const AbEntry& entry, const EntrySamples& es, const AbSettings& s, std::vector<AbQuantity>& out) {
  auto add = [&](const std::string& metric, const std::vector<double>& b, const std::vector<double>& c) {
    AbQuantity q{entry.scene, entry.technique, es.level_name, metric, b, c, {}};
    q.judgement = judge_pairs(entry.scene + "/" + entry.technique + "/" + es.level_name + " " + metric, b, c, s.rule);
    out.push_back(std::move(q));
  };
  if (entry.level == "auto") {
    // The scheduler holds the frame time by trading quality: its time says nothing; its share
    // of frames within the budget does (kSchedulerMetric).
    add(kSchedulerMetric, es.frames_per_frame_within_budget(0), es.frames_per_frame_within_budget(1));
    return;
  }
  add("sustained_ms", es.series(0, "sustained_ms"), es.series(1, "sustained_ms"));
  add("cpu_ms", es.series(0, "cpu_ms"), es.series(1, "cpu_ms"));
  std::vector<double> frame = es.series(0, "profiled_ms");
  drop_unresolved_times(frame);
  std::set<std::string> names;
  for (const json& a : es.answers[0])
    if (a.contains("passes"))
      for (auto& [name, ms] : a["passes"].items()) names.insert(name);
  for (const std::string& name : names) {
    std::vector<double> kept = es.series(0, "passes_min", name);
    drop_unresolved_times(kept);
    if (kept.empty() || !(median(kept) >= s.pass_min_share * median(frame))) continue;
    add("pass:" + name, es.pass_relative(0, name), es.pass_relative(1, name));
  }
}

}  // namespace

std::vector<AbQuantity> pool_pass_quantities(const std::vector<AbQuantity>& quantities, const AbRule& rule) {
  std::map<std::string, AbQuantity> pooled;
  std::map<std::string, int> entries;
  for (const AbQuantity& q : quantities) {
    if (q.metric.rfind("pass:", 0) != 0 || q.scene == "every entry") continue;
    AbQuantity& p = pooled[q.metric];
    p.scene = "every entry";
    p.technique = "";
    p.level_name = "";
    p.metric = q.metric;
    p.base.insert(p.base.end(), q.base.begin(), q.base.end());
    p.candidate.insert(p.candidate.end(), q.candidate.begin(), q.candidate.end());
    ++entries[q.metric];
  }
  std::vector<AbQuantity> out;
  for (auto& [metric, p] : pooled) {
    if (entries[metric] < 2) continue;
    p.level_name = std::to_string(entries[metric]) + " entries";
    p.judgement = judge_pairs(p.entry() + " " + metric, p.base, p.candidate, rule);
    out.push_back(std::move(p));
  }
  return out;
}

size_t AbResult::alarms() const {
  size_t n = 0;
  for (const AbQuantity& q : quantities) n += q.judgement.alarm ? 1 : 0;
  return n;
}

Expected<std::vector<AbEntry>> load_compare_set(const std::string& path, const std::string& set) {
  std::ifstream f(path);
  if (!f) return fail(ErrorKind::BadInput, path + ": cannot be read");
  json j;
  try {
    j = json::parse(f);
  } catch (const std::exception& e) {
    return fail(ErrorKind::BadInput, path + ": not JSON (" + std::string(e.what()) + ")");
  }
  if (j.value("version", 0) != 1) return fail(ErrorKind::BadInput, path + ": field 'version' must be 1");
  if (!j.contains("sets") || !j["sets"].is_object())
    return fail(ErrorKind::BadInput, path + ": field 'sets' must be an object of named entry lists");
  if (!j["sets"].contains(set)) {
    std::string known;
    for (auto& [name, v] : j["sets"].items()) known += (known.empty() ? "" : ", ") + name;
    return fail(ErrorKind::BadUsage, path + ": no set '" + set + "' (sets: " + known + ")");
  }
  std::vector<AbEntry> out;
  const json& list = j["sets"][set];
  if (!list.is_array() || list.empty())
    return fail(ErrorKind::BadInput, path + ": sets." + set + " must be a non-empty array");
  for (size_t i = 0; i < list.size(); ++i) {
    const json& e = list[i];
    const std::string where = path + ": sets." + set + "[" + std::to_string(i) + "]";
    for (const char* field : {"scene", "technique", "level"})
      if (!e.contains(field) || !e[field].is_string() || e[field].get<std::string>().empty())
        return fail(ErrorKind::BadInput, where + "." + field + " must be a non-empty string");
    out.push_back({e["scene"], e["technique"], e["level"]});
  }
  return out;
}

Expected<AbResult> run_ab_compare(const AbSettings& s) {
  if (s.entries.empty()) return fail(ErrorKind::BadUsage, "--compare: no entry to compare");
  if (s.pairs < 2) return fail(ErrorKind::BadUsage, "--pairs must be at least 2");
  if (s.frames < 1 || s.warmup < 0 || s.profile_frames < 0)
    return fail(ErrorKind::BadUsage, "--frames >= 1, --warmup and --profile-frames >= 0");
  // Every entry's technique and level must exist (in this build's registry) before hours of work.
  for (const AbEntry& e : s.entries) {
    if (e.level == "auto") {
      auto levels = resolve_levels(e.technique, {"0"});
      if (!levels.ok())
        return fail(ErrorKind::BadUsage, "entry " + e.scene + "/" + e.technique + "/auto: " + levels.error().message);
      continue;
    }
    auto levels = resolve_levels(e.technique, {e.level});
    if (!levels.ok() || levels->size() != 1)
      return fail(ErrorKind::BadUsage, "entry " + e.scene + "/" + e.technique + "/" + e.level + ": " +
                                           (levels.ok() ? "name one level" : levels.error().message));
  }
  AbResult result;
  result.base_binary = s.base_binary;
  result.candidate_binary = s.candidate_binary;
  result.pairs = s.pairs;
  result.frames = s.frames;
  result.warmup = s.warmup;
  result.profile_frames = s.profile_frames;
  result.rule = s.rule;
  result.lp_num_threads = ensure_lp_num_threads();
  // A worker that ends early (a base that is no mrgi, a crash) is an error on the pipe to it,
  // reported by name, not a SIGPIPE that ends this process without a word.
  signal(SIGPIPE, SIG_IGN);
  const auto t0 = std::chrono::steady_clock::now();
  auto base = Worker::start(s.base_binary, s.device, "base");
  if (!base.ok()) return base.error();
  auto cand = Worker::start(s.candidate_binary, s.device, "candidate");
  if (!cand.ok()) return cand.error();
  result.base_commit = git_head((*base)->source());
  result.candidate_commit = git_head((*cand)->source());
  Worker* workers[2] = {base->get(), cand->get()};
  std::vector<EntrySamples> samples(s.entries.size());
  const size_t steps = s.entries.size() * size_t(s.pairs + 1) * 2;
  size_t done = 0;
  for (size_t e = 0; e < s.entries.size(); ++e) {
    const AbEntry& entry = s.entries[e];
    const bool scheduled = entry.level == "auto";
    const json request = {{"op", "measure"},
                          {"suite", s.suite},
                          {"scene", entry.scene},
                          {"technique", entry.technique},
                          {"level", entry.level},
                          {"frames", scheduled ? s.scheduler_frames : s.frames},
                          {"warmup", scheduled ? s.scheduler_warmup : s.warmup},
                          {"profile_frames", scheduled ? 0 : s.profile_frames}};
    const std::string what = entry.scene + "/" + entry.technique + "/" + entry.level;
    // A first, unrecorded measurement of each: the runtime's creation and first frames.
    for (int pair = -1; pair < s.pairs; ++pair) {
      const int first = pair < 0 ? 0 : pair % 2;  // AB, BA, AB, ...
      for (int k = 0; k < 2; ++k) {
        const int side = k == 0 ? first : 1 - first;
        auto a = workers[side]->ask(request);
        if (!a.ok()) return fail(a.error().kind, what + ": " + a.error().message);
        if (pair >= 0) samples[e].answers[side].push_back(*a);
        samples[e].level_name = a->value("level_name", entry.level);
        if (result.device.empty()) result.device = a->value("device", "");
        ++done;
        if (s.progress)
          s.progress(what, done, steps, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
    }
  }
  for (size_t e = 0; e < s.entries.size(); ++e) add_quantities(s.entries[e], samples[e], s, result.quantities);
  const std::vector<AbQuantity> pooled = pool_pass_quantities(result.quantities, s.rule);
  result.quantities.insert(result.quantities.end(), pooled.begin(), pooled.end());
  std::vector<AbJudgement> family;
  for (const AbQuantity& q : result.quantities) family.push_back(q.judgement);
  judge_family(family, s.rule);
  for (size_t i = 0; i < family.size(); ++i) result.quantities[i].judgement = family[i];
  result.duration_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace mrgi::perf

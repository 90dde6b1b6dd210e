// OUT.partial/synth_resume.json (see synth_resume.h).
#include "synth_resume.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

namespace mrgi::reference {
namespace {

namespace fs = std::filesystem;

// FNV-1a, 64 bit: detects a changed input, nothing more is asked of it.
struct Fnv1a {
  uint64_t h = 14695981039346656037ull;
  void add(const char* p, size_t n) {
    for (size_t i = 0; i < n; ++i) h = (h ^ uint8_t(p[i])) * 1099511628211ull;
  }
  void add(const std::string& s) {
    add(s.data(), s.size());
    add("\0", 1);  // keeps "ab"+"c" apart from "a"+"bc"
  }
};

Status add_file(Fnv1a* hash, const std::string& path, const char* what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(ErrorKind::NotFound, path + ": cannot read " + what + " (needed to fingerprint the render)");
  char buf[1 << 16];
  while (in.read(buf, sizeof(buf)) || in.gcount() > 0) hash->add(buf, size_t(in.gcount()));
  return ok_status();
}

std::string number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.17g", v);
  return buf;
}

}  // namespace

Expected<SynthResumeState> synth_resume_identity(const SceneDescription& d, const SynthOptions& options) {
  SynthResumeState s;
  const Intrinsics& k = d.intrinsics;
  // The description's path is only named, not hashed: the same files resume from another
  // working directory.
  const std::string hashed = "frames " + std::to_string(d.frames) + ", " + std::to_string(k.width) +
               "x" + std::to_string(k.height) + " (fx " + number(k.fx) + " fy " + number(k.fy) + " cx " +
               number(k.cx) + " cy " + number(k.cy) + "), spp " + std::to_string(d.spp) + ", seed " +
               std::to_string(d.seed) + ", references " +
               (options.references == ReferenceStorage::Delta ? "delta" : "plain") + ", noise floor seed " +
               (options.noise_floor_seed ? std::to_string(*options.noise_floor_seed) : std::string("none"));
  s.settings = "description " + d.path + ", " + hashed;
  Fnv1a hash;
  hash.add(hashed);
  MRGI_TRY(add_file(&hash, d.path, "the scene description"));
  for (const auto& o : d.real_objects)
    if (!o.gltf.empty()) MRGI_TRY(add_file(&hash, o.gltf, "a real object's glTF"));
  for (const auto& v : d.virtual_objects) MRGI_TRY(add_file(&hash, v.gltf, "a virtual object's glTF"));
  if (d.environment.present && !d.environment.sky)
    MRGI_TRY(add_file(&hash, d.environment.image, "the environment image"));
  char hex[17];
  std::snprintf(hex, sizeof(hex), "%016llx", static_cast<unsigned long long>(hash.h));
  s.fingerprint = hex;
  return s;
}

Expected<SynthResumeState> load_synth_resume(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    return fail(ErrorKind::NotFound, path + ": missing; the folder was not left by an interrupted `mrgi synth` "
                                            "(remove it to start again)");
  std::stringstream text;
  text << in.rdbuf();
  SynthResumeState s;
  try {
    const nlohmann::json j = nlohmann::json::parse(text.str());
    if (j.at("version").get<int>() != 1) return fail(ErrorKind::BadInput, path + ": version must be 1");
    s.fingerprint = j.at("fingerprint").get<std::string>();
    s.settings = j.at("settings").get<std::string>();
    for (const nlohmann::json& f : j.at("frames")) {
      SynthFrameRecord r;
      r.dropped_samples = f.at("dropped_samples").get<size_t>();
      r.seconds = f.at("seconds").get<double>();
      if (f.contains("noise_floor")) {
        const nlohmann::json& n = f.at("noise_floor");
        NoiseFloor nf;
        nf.rde_all = n.at("all").get<double>();
        nf.rde_real = n.at("real").get<double>();
        nf.rde_virtual = n.at("virtual").get<double>();
        nf.delta_rms = n.at("delta_rms").get<double>();
        r.noise_floor = nf;
      }
      s.frames.push_back(r);
    }
  } catch (const nlohmann::json::exception& e) {
    return fail(ErrorKind::BadInput, path + ": " + e.what());
  }
  return s;
}

Status save_synth_resume(const std::string& path, const SynthResumeState& state) {
  nlohmann::json j;
  j["version"] = 1;
  j["fingerprint"] = state.fingerprint;
  j["settings"] = state.settings;
  j["frames"] = nlohmann::json::array();
  for (const SynthFrameRecord& r : state.frames) {
    nlohmann::json f;
    f["dropped_samples"] = r.dropped_samples;
    f["seconds"] = r.seconds;
    if (r.noise_floor)
      f["noise_floor"] = {{"all", r.noise_floor->rde_all},
                          {"real", r.noise_floor->rde_real},
                          {"virtual", r.noise_floor->rde_virtual},
                          {"delta_rms", r.noise_floor->delta_rms}};
    j["frames"].push_back(f);
  }
  // Write then rename: a kill mid-write leaves the previous state.
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << j.dump(2) << "\n";
    if (!out) return fail(ErrorKind::Device, tmp + ": write failed");
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) return fail(ErrorKind::Device, path + ": cannot rename " + tmp + " into place: " + ec.message());
  return ok_status();
}

}  // namespace mrgi::reference

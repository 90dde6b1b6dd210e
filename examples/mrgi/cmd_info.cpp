// mrgi info: the Vulkan devices mrgi sees and the one it would use (--device / $MRGI_DEVICE;
// default lavapipe if present, else device 0). With --technique it also builds that technique's
// runtime for --level at --width x --height and states the memory it allocates at start-up
// (everything the frame loop will ever use).
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "mrgi/runtime.h"

namespace mrgi::tool {
namespace {

struct InfoOptions {
  std::string device;
  bool validate = false;
  std::string technique;
  std::vector<std::string> knobs;
  std::string level = "0";
  int width = 640;
  int height = 480;
  bool json = false;
};

std::string api_string(uint32_t v) {
  return std::to_string(v >> 22) + "." + std::to_string((v >> 12) & 0x3ff) + "." + std::to_string(v & 0xfff);
}


void run_info(const InfoOptions& o) {
  DeviceSettings ds;
  ds.device = o.device;
  ds.validate = o.validate;
  const std::vector<DeviceInfo> devices = take(list_devices(ds));

  nlohmann::json j;
  j["devices"] = nlohmann::json::array();
  for (const DeviceInfo& d : devices)
    j["devices"].push_back({{"index", d.index},
                            {"name", d.name},
                            {"type", d.type},
                            {"driver", d.driver},
                            {"api_version", api_string(d.api_version)},
                            {"device_local_mib", d.device_local_mib},
                            {"selected", d.selected}});
  j["validation"] = o.validate;

  if (!o.technique.empty()) {
    const std::vector<KnobSetting> knobs = parse_knobs(o.technique, o.knobs);
    const std::vector<QualityLevelInfo> ladder = take(technique_ladder(o.technique, knobs));
    nlohmann::json levels = nlohmann::json::array();
    for (size_t i = 0; i < ladder.size(); ++i) {
      nlohmann::json knob_list = nlohmann::json::array();
      for (const QualityKnob& k : ladder[i].knobs)
        knob_list.push_back({{"name", k.name}, {"value", k.value}, {"unit", k.unit}, {"min", k.min}, {"max", k.max},
                         {"power_of_two", k.power_of_two}});
      levels.push_back({{"index", i}, {"name", ladder[i].name}, {"internal_scale", ladder[i].internal_scale},
                        {"mesh_error_px", ladder[i].mesh_error_px}, {"knobs", knob_list}});
    }
    j["ladder"] = {{"technique", o.technique}, {"levels", levels}};
    if (o.width <= 0 || o.height <= 0)
      fail_with(fail(ErrorKind::BadUsage, "--width and --height must be > 0"));
    RuntimeSettings rs;
    rs.device = ds;
    rs.technique = o.technique;
    rs.level = resolve_level(o.technique, o.level);
    rs.knobs = knobs;
    rs.output_width = o.width;
    rs.output_height = o.height;
    CameraSetup cameras;
    cameras.color = cameras.color.scaled_to(o.width, o.height);
    cameras.depth = cameras.depth.scaled_to(o.width, o.height);
    // An empty scene: the allocation is sized by the technique, level and output size, which
    // are what the budget depends on.
    auto runtime = take(create_runtime(rs, cameras, SceneDesc{}));
    const auto names = runtime->level_names();
    j["budget"] = {{"technique", o.technique},
                   {"level", rs.level},
                   {"level_name", rs.level < int(names.size()) ? names[rs.level] : std::string()},
                   {"width", o.width},
                   {"height", o.height},
                   {"memory_mib", runtime->memory_mib()}};
  }

  if (o.json) {
    std::cout << j.dump(2) << "\n";
    return;
  }
  std::cout << "Vulkan devices (" << devices.size() << "):\n";
  for (const DeviceInfo& d : devices) {
    std::cout << (d.selected ? " * " : "   ") << d.index << ": " << d.name << "\n"
              << "       type " << d.type << ", driver " << d.driver << ", Vulkan " << api_string(d.api_version)
              << ", device-local memory " << d.device_local_mib << " MiB\n";
  }
  std::cout << "(* = the device mrgi uses with this --device / MRGI_DEVICE; validation "
            << (o.validate ? "on" : "off") << ")\n";
  if (j.contains("ladder")) {
    std::cout << "ladder of " << o.technique << " (best first; --level takes the index or the name):\n";
    for (const auto& l : j["ladder"]["levels"]) {
      std::cout << "  " << l["index"].get<int>() << " " << l["name"].get<std::string>() << ": internal scale "
                << l["internal_scale"].get<double>() << " of the output";
      if (l["mesh_error_px"].get<double>() > 0.0)
        std::cout << ", mesh level of detail " << l["mesh_error_px"].get<double>() << " px";
      std::cout << "\n";
      for (const auto& k : l["knobs"]) {
        std::cout << "      " << k["name"].get<std::string>() << " = " << k["value"].get<double>() << " ("
                  << k["unit"].get<std::string>();
        if (k["min"].get<double>() < k["max"].get<double>())
          std::cout << "; --knob takes " << k["min"].get<double>() << ".." << k["max"].get<double>()
                    << (k["power_of_two"].get<bool>() ? ", a power of two" : "");
        else
          std::cout << "; fixed";
        std::cout << ")\n";
      }
    }
  }
  if (j.contains("budget")) {
    const auto& b = j["budget"];
    std::cout << "frame memory: " << b["technique"].get<std::string>() << " level " << b["level"].get<int>() << " ("
              << b["level_name"].get<std::string>() << ") at " << o.width << "x" << o.height << ": "
              << b["memory_mib"].get<double>() << " MiB allocated at start-up\n";
  }
}

void setup(CLI::App& app) {
  auto opts = std::make_shared<InfoOptions>();
  CLI::App* cmd = app.add_subcommand("info", "Vulkan devices, the one mrgi uses, and a technique's memory budget");
  cmd->add_option("--device", opts->device, "Vulkan device: index, cpu / lavapipe, gpu, or name part (default $MRGI_DEVICE, else lavapipe)");
  cmd->add_flag("--validate", opts->validate, "load the Khronos validation layer (fails if it is not installed)");
  cmd->add_option("--technique", opts->technique,
                  "also print this technique's quality ladder (every level's knobs with units) and its start-up "
                  "memory at --level");
  cmd->add_option("--knob", opts->knobs,
                  "set one quality knob at every level, NAME=VALUE (repeatable): the ladder and memory with it");
  cmd->add_option("--level", opts->level, "quality level: 0 = best, N, a level name, or 'last' = cheapest")->default_val("0");
  cmd->add_option("--width", opts->width, "output width in pixels")->default_val(640);
  cmd->add_option("--height", opts->height, "output height in pixels")->default_val(480);
  cmd->add_flag("--json", opts->json, "machine-readable output");
  cmd->callback([opts] { run_info(*opts); });
}

}  // namespace

MRGI_COMMAND(info, setup);

}  // namespace mrgi::tool

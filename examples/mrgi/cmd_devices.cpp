// mrgi devices [--json]: what every input adapter sees (OpenNI2 devices, V4L2 nodes, libcamera
// cameras, known USB sensors and the adapter that serves each). No device is not an error.
#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "mrgi/platform/devices.h"

namespace mrgi::tool {
namespace {

std::string hex4(int v) {
  char b[8];
  std::snprintf(b, sizeof b, "%04x", v & 0xffff);
  return b;
}

nlohmann::json to_json(const DeviceReport& r) {
  using nlohmann::json;
  json j;
  json on = json::array();
  for (const auto& d : r.openni)
    on.push_back({{"uri", d.uri}, {"name", d.name}, {"vendor", d.vendor}, {"usb_id", hex4(d.usb_vendor_id) + ":" + hex4(d.usb_product_id)}});
  j["openni"] = {{"available", r.openni_status.ok()},
                 {"status", r.openni_status.ok() ? (r.openni.empty() ? "none found" : "ok") : r.openni_status.error().message},
                 {"devices", on}};
  json v = json::array();
  for (const auto& n : r.v4l2) {
    json fmts = json::array();
    for (const auto& f : n.formats) {
      json sizes = json::array();
      for (auto [w, h] : f.sizes) sizes.push_back(std::to_string(w) + "x" + std::to_string(h));
      fmts.push_back({{"fourcc", f.fourcc}, {"supported", f.supported}, {"emulated", f.emulated}, {"sizes", sizes}});
    }
    v.push_back({{"path", n.path}, {"driver", n.driver}, {"card", n.card}, {"bus", n.bus_info},
                 {"capture", n.capture}, {"formats", fmts}, {"error", n.error}});
  }
  j["v4l2"] = {{"status", r.v4l2.empty() ? "none found (no /dev/video* nodes)" : "ok"}, {"nodes", v}};
  json lc = json::array();
  for (const auto& c : r.libcamera) lc.push_back({{"id", c.id}, {"model", c.model}, {"location", c.location}});
  j["libcamera"] = {{"available", r.libcamera_status.ok()},
                    {"status", r.libcamera_status.ok() ? (r.libcamera.empty() ? "none found" : "ok") : r.libcamera_status.error().message},
                    {"cameras", lc}};
  json usb = json::array();
  int sensors = 0;
  for (const auto& d : r.usb.devices) {
    if (!d.known) continue;
    ++sensors;
    usb.push_back({{"id", hex4(d.vendor) + ":" + hex4(d.product)}, {"bus", d.bus}, {"address", d.address},
                   {"name", d.known->name}, {"product", d.product_name}, {"adapter", d.known->adapter}, {"note", d.known->note}});
  }
  json adapters = json::array();
  for (const BuildAdapter& a : build_adapters())
    adapters.push_back({{"name", a.name}, {"built", a.built}, {"option", a.option}, {"package", a.package}});
  j["adapters"] = adapters;
  j["usb"] = {{"available", r.usb.available},
              {"status", !r.usb.available ? r.usb.status : sensors == 0 ? "no known sensor among " + std::to_string(r.usb.devices.size()) + " USB devices" : "ok"},
              {"devices_seen", r.usb.devices.size()},
              {"sensors", usb}};
  return j;
}

void print_text(const nlohmann::json& j) {
  auto section = [&](const char* title, const nlohmann::json& s) {
    std::cout << title << ": " << s["status"].get<std::string>() << "\n";
  };
  std::cout << "adapters in this build:";
  for (const auto& a : j["adapters"])
    std::cout << " " << a["name"].get<std::string>()
              << (a["built"].get<bool>() ? "" : " (left out: " + a["option"].get<std::string>() + "=OFF, needs " +
                                                  a["package"].get<std::string>() + ")");
  std::cout << "\n";
  section("OpenNI2", j["openni"]);
  for (const auto& d : j["openni"]["devices"])
    std::cout << "  " << d["uri"].get<std::string>() << "  " << d["vendor"].get<std::string>() << " "
              << d["name"].get<std::string>() << " [" << d["usb_id"].get<std::string>() << "]  -> openni:"
              << d["uri"].get<std::string>() << "\n";
  section("V4L2", j["v4l2"]);
  for (const auto& n : j["v4l2"]["nodes"]) {
    std::cout << "  " << n["path"].get<std::string>();
    if (!n["error"].get<std::string>().empty()) {
      std::cout << "  (cannot query: " << n["error"].get<std::string>() << ")\n";
      continue;
    }
    std::cout << "  " << n["card"].get<std::string>() << " (" << n["driver"].get<std::string>() << ", "
              << n["bus"].get<std::string>() << ")";
    if (!n["capture"].get<bool>()) {
      std::cout << "  not a streaming capture node\n";
      continue;
    }
    std::cout << "  formats:";
    for (const auto& f : n["formats"])
      std::cout << " " << f["fourcc"].get<std::string>() << (f["supported"].get<bool>() ? "" : "(unsupported)");
    std::cout << "  -> v4l2:" << n["path"].get<std::string>() << "\n";
  }
  section("libcamera", j["libcamera"]);
  for (const auto& c : j["libcamera"]["cameras"])
    std::cout << "  " << c["id"].get<std::string>() << "  " << c["model"].get<std::string>() << " "
              << c["location"].get<std::string>() << "  -> libcamera:" << c["id"].get<std::string>() << "\n";
  section("USB sensors", j["usb"]);
  for (const auto& d : j["usb"]["sensors"])
    std::cout << "  " << d["id"].get<std::string>() << " bus " << d["bus"].get<int>() << " addr "
              << d["address"].get<int>() << "  " << d["name"].get<std::string>() << "  -> adapter "
              << d["adapter"].get<std::string>() << " (" << d["note"].get<std::string>() << ")\n";
}

void setup(CLI::App& app) {
  auto json_out = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand("devices", "List the input devices every adapter sees (OpenNI2, V4L2, libcamera, USB)");
  cmd->add_flag("--json", *json_out, "print JSON instead of text");
  cmd->callback([json_out] {
    const nlohmann::json j = to_json(list_devices_all_adapters());
    if (*json_out) std::cout << j.dump(2) << "\n";
    else print_text(j);
  });
}

}  // namespace

MRGI_COMMAND(devices, setup);

}  // namespace mrgi::tool

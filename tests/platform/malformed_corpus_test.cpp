// The malformed-input corpus: broken captures generated here from a two-frame copy of
// the bundled sample (data/sample), one defect each, every one replayed by the real tool. Each
// must be refused with exit 1 and a message that names the broken file and the rule, and leave
// no output behind (neither OUT nor OUT.partial). The generator is the table below: a case is a
// name, the file its message must name, a fragment of the rule, and the edit that breaks it.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include "test_support.h"

namespace mrgi {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

void spit(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
}

// Replaces the first occurrence of `from` in FILE (which must hold it).
void edit(const fs::path& file, const std::string& from, const std::string& to) {
  std::string s = slurp(file);
  const size_t at = s.find(from);
  ASSERT_NE(at, std::string::npos) << file << " lacks '" << from << "'";
  s.replace(at, from.size(), to);
  spit(file, s);
}

// A valid two-frame capture: the sample's capture.json, scene.json and model, its first two
// colour/depth frames and their poses (no references: replay does not need them).
void make_base(const fs::path& dst) {
  const fs::path src = fs::path(MRGI_SOURCE_DIR) / "data" / "sample";
  fs::create_directories(dst / "rgb");
  fs::create_directories(dst / "depth");
  fs::create_directories(dst / "virtual");
  for (const char* f : {"capture.json", "scene.json", "virtual/0_bunny.glb", "rgb/000000.png", "rgb/000001.png",
                        "depth/000000.png", "depth/000001.png"})
    fs::copy_file(src / f, dst / f);
  auto head = [&](const char* list, size_t lines) {
    std::ifstream in(src / list);
    std::string out, line;
    size_t data = 0;
    while (data < lines && std::getline(in, line)) {
      out += line + "\n";
      if (!line.empty() && line[0] != '#') ++data;
    }
    spit(dst / list, out);
  };
  head("rgb.txt", 2);
  head("depth.txt", 2);
  head("groundtruth.txt", 2);
}

struct Case {
  const char* name;
  const char* file;  // the message must name it
  const char* rule;  // and hold this fragment of the rule
  std::function<void(const fs::path&)> apply;
};

std::vector<Case> cases() {
  auto set = [](const char* file, const char* from, const char* to) {
    return [=](const fs::path& d) { edit(d / file, from, to); };
  };
  auto write = [](const char* file, std::string text) {
    return [=](const fs::path& d) { spit(d / file, text); };
  };
  auto remove = [](const char* file) { return [=](const fs::path& d) { fs::remove(d / file); }; };
  auto truncate = [](const char* file, size_t keep) {
    return [=](const fs::path& d) { spit(d / file, slurp(d / file).substr(0, keep)); };
  };
  auto rgb_line2 = [](const std::string& line) {
    return [=](const fs::path& d) {
      spit(d / "rgb.txt", "# timestamp filename\n0 rgb/000000.png\n" + line + "\n");
    };
  };
  auto gt_line2 = [](const std::string& line) {
    return [=](const fs::path& d) {
      std::string s = slurp(d / "groundtruth.txt");
      s = s.substr(0, s.rfind('\n', s.size() - 2) + 1) + line + "\n";
      spit(d / "groundtruth.txt", s);
    };
  };
  const std::string png_text = "this is not a PNG file\n";
  return {
      // capture.json
      {"capture_json_is_folder", "capture.json", "regular file", [](const fs::path& d) {
         fs::remove(d / "capture.json");
         fs::create_directory(d / "capture.json");
       }},
      {"capture_json_empty", "capture.json", "", write("capture.json", "")},
      {"capture_json_not_json", "capture.json", "", write("capture.json", "{\"color\": [1, 2,")},
      {"capture_json_array", "capture.json", "", write("capture.json", "[1, 2, 3]")},
      {"capture_json_version_2", "capture.json", "version", set("capture.json", "\"version\": 1", "\"version\": 2")},
      {"capture_json_no_version", "capture.json", "version", set("capture.json", "\"version\": 1", "\"versio\": 1")},
      {"capture_json_no_color", "capture.json", "color", set("capture.json", "\"color\"", "\"colour\"")},
      {"capture_json_width_zero", "capture.json", "width", set("capture.json", "\"width\": 640", "\"width\": 0")},
      {"capture_json_width_negative", "capture.json", "width", set("capture.json", "\"width\": 640", "\"width\": -640")},
      {"capture_json_width_string", "capture.json", "width", set("capture.json", "\"width\": 640", "\"width\": \"640\"")},
      {"capture_json_width_fraction", "capture.json", "width", set("capture.json", "\"width\": 640", "\"width\": 640.5")},
      {"capture_json_width_huge", "capture.json", "width", set("capture.json", "\"width\": 640", "\"width\": 100000000")},
      {"capture_json_fx_zero", "capture.json", "fx", set("capture.json", "\"fx\": 525.0", "\"fx\": 0.0")},
      {"capture_json_fx_infinite", "capture.json", "", set("capture.json", "\"fx\": 525.0", "\"fx\": 1e400")},
      {"capture_json_fx_beyond_float", "capture.json", "", set("capture.json", "\"fx\": 525.0", "\"fx\": 1e39")},
      {"capture_json_depth_scale_zero", "capture.json", "depth_scale", set("capture.json", "\"depth_scale\": 5000.0", "\"depth_scale\": 0")},
      {"capture_json_depth_scale_negative", "capture.json", "depth_scale", set("capture.json", "\"depth_scale\": 5000.0", "\"depth_scale\": -5000")},
      {"capture_json_duplicate_key", "capture.json", "", set("capture.json", "\"depth_scale\": 5000.0", "\"depth_scale\": -1, \"depth_scale\": 5000")},
      {"capture_json_exposure_zero", "capture.json", "exposure", set("capture.json", "\"exposure\": 1.0", "\"exposure\": 0")},
      {"capture_json_exposure_negative", "capture.json", "exposure", set("capture.json", "\"exposure\": 1.0", "\"exposure\": -2")},
      {"capture_json_size_differs_from_png", "rgb", "", set("capture.json", "\"width\": 640", "\"width\": 320")},
      // rgb.txt
      {"rgb_list_missing", "rgb.txt", "", remove("rgb.txt")},
      {"rgb_list_no_frames", "rgb.txt", "", write("rgb.txt", "# timestamp filename\n")},
      {"rgb_timestamp_not_a_number", "rgb.txt", "timestamp", rgb_line2("zero rgb/000001.png")},
      {"rgb_timestamp_decreasing", "rgb.txt", "timestamp", rgb_line2("-1 rgb/000001.png")},
      {"rgb_timestamp_repeated", "rgb.txt", "timestamp", rgb_line2("0 rgb/000001.png")},
      {"rgb_timestamp_nan", "rgb.txt", "timestamp", rgb_line2("nan rgb/000001.png")},
      {"rgb_listed_file_missing", "rgb.txt", "", rgb_line2("0.1 rgb/000009.png")},
      {"rgb_path_outside_capture", "rgb.txt", "inside the capture", rgb_line2("0.1 ../rgb/000001.png")},
      {"rgb_path_absolute", "rgb.txt", "inside the capture", rgb_line2("0.1 /etc/hostname")},
      {"rgb_path_is_folder", "rgb.txt", "regular file", rgb_line2("0.1 rgb")},
      {"rgb_list_is_fifo", "rgb.txt", "regular file", [](const fs::path& d) {
         fs::remove(d / "rgb.txt");
         ASSERT_EQ(::mkfifo((d / "rgb.txt").c_str(), 0600), 0);
       }},
      {"rgb_nul_byte", "rgb.txt", "", rgb_line2(std::string("0.1 rgb/000001.png\0x", 20))},
      {"rgb_too_many_fields", "rgb.txt", "", rgb_line2("0.1 rgb/000001.png extra more")},
      {"rgb_no_path", "rgb.txt", "", rgb_line2("0.1")},
      {"rgb_png_truncated", "000000.png", "", truncate("rgb/000000.png", 300)},
      {"rgb_png_is_text", "000000.png", "", write("rgb/000000.png", png_text)},
      {"rgb_png_empty", "000000.png", "", write("rgb/000000.png", "")},
      {"rgb_png_is_depth", "000000.png", "", [](const fs::path& d) {
         fs::copy_file(d / "depth/000000.png", d / "rgb/000000.png", fs::copy_options::overwrite_existing);
       }},
      // depth.txt
      {"depth_list_missing", "depth.txt", "", remove("depth.txt")},
      {"depth_listed_file_missing", "depth.txt", "", write("depth.txt", "0 depth/000000.png\n0.1 depth/000007.png\n")},
      {"depth_timestamp_decreasing", "depth.txt", "timestamp", write("depth.txt", "0 depth/000000.png\n-0.1 depth/000001.png\n")},
      {"depth_png_is_colour", "000000.png", "", [](const fs::path& d) {
         fs::copy_file(d / "rgb/000000.png", d / "depth/000000.png", fs::copy_options::overwrite_existing);
       }},
      {"depth_png_truncated", "000000.png", "", truncate("depth/000000.png", 200)},
      {"depth_png_is_text", "000000.png", "", write("depth/000000.png", png_text)},
      // groundtruth.txt
      {"poses_six_fields", "groundtruth.txt", "", gt_line2("0.1 0 1 0 0 0 1")},
      {"poses_zero_quaternion", "groundtruth.txt", "", gt_line2("0.1 0 1 0 0 0 0 0")},
      {"poses_nan", "groundtruth.txt", "", gt_line2("0.1 nan 1 0 0 0 0 1")},
      {"poses_infinite", "groundtruth.txt", "", gt_line2("0.1 inf 1 0 0 0 0 1")},
      {"poses_decreasing", "groundtruth.txt", "timestamp", gt_line2("-5 0 1 0 0 0 0 1")},
      {"poses_garbage", "groundtruth.txt", "", write("groundtruth.txt", "\x01\x02\x03 garbage\n")},
      // scene.json
      {"scene_not_json", "scene.json", "", write("scene.json", "{\"lights\": [")},
      {"scene_is_folder", "scene.json", "regular file", [](const fs::path& d) {
         fs::remove(d / "scene.json");
         fs::create_directory(d / "scene.json");
       }},
      {"scene_dangling_symlink", "scene.json", "dangling", [](const fs::path& d) {
         fs::remove(d / "scene.json");
         fs::create_symlink(d / "nothing_here.json", d / "scene.json");
       }},
      {"scene_version_2", "scene.json", "version", set("scene.json", "\"version\": 1", "\"version\": 2")},
      {"scene_lights_not_array", "scene.json", "lights", write("scene.json", "{\"version\": 1, \"lights\": 5}")},
      {"poses_list_is_folder", "groundtruth.txt", "regular file", [](const fs::path& d) {
         fs::remove(d / "groundtruth.txt");
         fs::create_directory(d / "groundtruth.txt");
       }},
      {"scene_light_type_unknown", "scene.json", "type", set("scene.json", "\"type\": \"spot\"", "\"type\": \"laser\"")},
      {"scene_light_intensity_negative", "scene.json", "intensity", set("scene.json", "\"intensity\": 2.5", "\"intensity\": -2.5")},
      {"scene_light_intensity_beyond_float", "scene.json", "", set("scene.json", "\"intensity\": 2.5", "\"intensity\": 1e39")},
      {"scene_spot_outer_below_inner", "scene.json", "angle", set("scene.json", "\"outer_angle_deg\": 45.0", "\"outer_angle_deg\": 10.0")},
      {"scene_duplicate_key", "scene.json", "", set("scene.json", "\"intensity\": 2.5", "\"intensity\": -1, \"intensity\": 2.5")},
      {"scene_gltf_missing", "scene.json", "", set("scene.json", "virtual/0_bunny.glb", "virtual/none.glb")},
      {"scene_gltf_outside_capture", "", "", set("scene.json", "virtual/0_bunny.glb", "../../../../etc/hostname")},
      {"scene_gltf_is_folder", "", "", set("scene.json", "virtual/0_bunny.glb", "virtual")},
      {"scene_gltf_garbage", "0_bunny.glb", "", write("virtual/0_bunny.glb", "glTF\x02\0\0\0garbage")},
      {"scene_gltf_truncated", "0_bunny.glb", "", truncate("virtual/0_bunny.glb", 5000)},
      {"scene_object_scale_zero", "scene.json", "scale", [](const fs::path& d) {
         std::string s = slurp(d / "scene.json");
         const size_t at = s.find("\"scale\"");
         ASSERT_NE(at, std::string::npos);
         const size_t end = s.find(']', at) + 1;  // the sample gives [x, y, z]
         s.replace(at, end - at, "\"scale\": 0");
         spit(d / "scene.json", s);
       }},
      {"scene_color_negative", "scene.json", "color", set("scene.json", "1.0,\n        0.949999988079071", "-1.0,\n        0.949999988079071")},
  };
}

int run(const std::string& cmd) {
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

TEST(MalformedCorpus, EveryBrokenCaptureIsRefusedByNameAndLeavesNothing) {
  if (!fs::exists(MRGI_TOOL)) GTEST_SKIP() << "mrgi tool not built at " << MRGI_TOOL;
  test::TempDir dir("malformed");
  const fs::path base = dir.path / "base";
  make_base(base);
  {  // The base itself replays: every failure below is its one defect.
    const std::string out = (dir.path / "base_out").string();
    const std::string cmd = std::string("LP_NUM_THREADS=2 timeout 120 ") + MRGI_TOOL + " replay " + base.string() +
                            " --out " + out + " --frames 1 -q > /dev/null 2> " + (dir.path / "base.err").string();
    ASSERT_EQ(run(cmd), 0) << slurp(dir.path / "base.err");
  }
  const std::vector<Case> all = cases();
  ASSERT_GE(all.size(), 60u);
  for (const Case& c : all) {
    SCOPED_TRACE(c.name);
    const fs::path cap = dir.path / c.name;
    fs::copy(base, cap, fs::copy_options::recursive);
    c.apply(cap);
    const fs::path out = dir.path / (std::string(c.name) + "_out");
    const fs::path err = dir.path / (std::string(c.name) + ".err");
    const std::string cmd = std::string("LP_NUM_THREADS=2 timeout 120 ") + MRGI_TOOL + " replay " + cap.string() +
                            " --out " + out.string() + " --frames 2 -q > /dev/null 2> " + err.string();
    const int rc = run(cmd);
    const std::string message = slurp(err);
    EXPECT_EQ(rc, 1) << message;
    EXPECT_NE(message.find(c.file), std::string::npos) << "names not '" << c.file << "': " << message;
    EXPECT_NE(message.find(c.rule), std::string::npos) << "lacks '" << c.rule << "': " << message;
    EXPECT_EQ(message.find("internal error"), std::string::npos) << message;
    EXPECT_FALSE(fs::exists(out)) << "left " << out;
    EXPECT_FALSE(fs::exists(out.string() + ".partial")) << "left " << out << ".partial";
    std::printf("%-36s rc %d  %s", c.name, rc, message.c_str());
    std::error_code ec;
    fs::remove_all(cap, ec);
  }
}

}  // namespace
}  // namespace mrgi

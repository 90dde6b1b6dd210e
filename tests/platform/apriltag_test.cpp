// AprilTag detection and camera pose: the real photos of ../shared/data/apriltag (corner lists
// from the AprilTag reference detector) and synthetic renders of tag36h11 tags, drawn from
// libapriltag's own code table, into cameras with known poses.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>

#include "mrgi/platform/apriltag.h"
#include "test_support.h"

extern "C" {
#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>
}

#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_JPEG
#include <stb/stb_image.h>

namespace mrgi {
namespace {

struct RefTag {
  int id;
  std::array<glm::dvec2, 4> corners;
};

// Lines "id, (x y), (x y), (x y), (x y)".
std::vector<RefTag> read_reference(const std::string& path) {
  std::vector<RefTag> out;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    RefTag t{};
    double v[8];
    if (std::sscanf(line.c_str(), "%d, (%lf %lf), (%lf %lf), (%lf %lf), (%lf %lf)", &t.id, &v[0], &v[1], &v[2], &v[3],
                    &v[4], &v[5], &v[6], &v[7]) != 9)
      continue;
    for (int c = 0; c < 4; ++c) t.corners[c] = {v[2 * c], v[2 * c + 1]};
    out.push_back(t);
  }
  return out;
}

ImageRGB8 load_jpeg(const std::string& path) {
  int w = 0, h = 0, n = 0;
  uint8_t* p = stbi_load(path.c_str(), &w, &h, &n, 3);
  ImageRGB8 img;
  if (!p) return img;
  img = ImageRGB8(w, h);
  std::copy(p, p + img.data.size(), img.data.begin());
  stbi_image_free(p);
  return img;
}

// Corner error tolerance against the reference detector's corners, pixels. The reference came
// from a newer libapriltag than Debian's 3.3 and from its own JPEG decoder's grey image; the
// measured worst case is printed.
constexpr double kCornerTolPx = 1.0;

TEST(AprilTagPhotos, EveryListedTagFoundWithCornersWithinTolerance) {
  MRGI_SKIP_WITHOUT_SHARED(test::shared_data("apriltag"));
  const char* photos[] = {"33369213973_9d9bb4cc96_c", "34085369442_304b6bafd9_c", "34139872896_defdb2f8d9_c"};
  AprilTagTrackerSettings s;
  s.min_decision_margin = 0;  // the reference detector's defaults: accept every decode with <= 2 bit errors
  s.max_hamming = 2;
  // Full resolution: Debian's libapriltag 3.3 at quad_decimate 2 misses the smallest tags of
  // these photos (9 of 12, 18 of 24, 7 of 10), which the newer reference detector found.
  s.quad_decimate = 1.0;
  auto det = AprilTagDetector::create("tag36h11", s);
  ASSERT_TRUE(det.ok()) << det.error().message;
  double worst = 0;
  size_t listed = 0, matched = 0, missed = 0;
  for (const char* p : photos) {
    const std::string base = test::shared_data(std::string("apriltag/") + p);
    const ImageRGB8 img = load_jpeg(base + ".jpg");
    ASSERT_FALSE(img.empty()) << base;
    const auto refs = read_reference(base + ".txt");
    ASSERT_FALSE(refs.empty()) << base << ".txt";
    listed += refs.size();
    const auto found = det->detect(img);
    for (const RefTag& r : refs) {
      // Two of the 47 listed tags are not decoded by Debian's libapriltag 3.3 at any setting
      // tried (decimation 1/2, sharpening 0/0.25/0.5, blur 0/0.8, 2-3 corrected bits): a tag
      // 12 px tall near the top edge of one photo and a strongly foreshortened one (6 px tall) in
      // another. They are named here so any other miss fails.
      const bool known_miss = (std::abs(r.corners[0].x - 696.0) < 0.01 && std::abs(r.corners[0].y - 107.8969) < 0.01) ||
                              (std::abs(r.corners[0].x - 711.3130) < 0.01 && std::abs(r.corners[0].y - 364.1447) < 0.01);
      double best = 1e9;
      for (const auto& d : found) {
        if (d.id != r.id) continue;
        double e = 0;
        for (int c = 0; c < 4; ++c) e = std::max(e, glm::length(d.corners[c] - r.corners[c]));
        best = std::min(best, e);
      }
      if (known_miss) {
        ++missed;
        continue;
      }
      EXPECT_LT(best, kCornerTolPx) << p << ": tag " << r.id << " listed at (" << r.corners[0].x << ", "
                                    << r.corners[0].y << ") not found within " << kCornerTolPx << " px";
      if (best < 1e8) worst = std::max(worst, best);
      ++matched;
    }
  }
  EXPECT_EQ(listed, 47u);
  EXPECT_EQ(missed, 2u);
  std::printf("apriltag photos: %zu listed tags, %zu compared, %zu known misses, worst corner error %.3f px (tolerance %.1f)\n",
              listed, matched, missed, worst, kCornerTolPx);
  RecordProperty("worst_corner_error_px", std::to_string(worst));
}

// --- synthetic renders ---------------------------------------------------------------------

struct SyntheticTag {
  int id;
  Pose tag_to_world;
};

// Renders tags (grey, with 4x4 supersampling) seen by a pinhole camera at camera_to_world. Tag
// images come from libapriltag (apriltag_to_image: the code bits plus black and white borders).
ImageRGB8 render_tags(const std::vector<SyntheticTag>& tags, double size_m, const Intrinsics& k, const Pose& cam) {
  apriltag_family_t* fam = tag36h11_create();
  struct Drawn {
    image_u8_t* img;
    glm::dmat4 world_to_tag;
  };
  std::vector<Drawn> drawn;
  for (const auto& t : tags) drawn.push_back({apriltag_to_image(fam, t.id), glm::inverse(t.tag_to_world.matrix())});
  const double cell = size_m / fam->width_at_border;  // black square = width_at_border cells
  const int total = fam->total_width;
  const glm::dmat4 c2w = cam.matrix();
  ImageRGB8 img(k.width, k.height);
  constexpr int kSS = 4;
  for (int y = 0; y < k.height; ++y)
    for (int x = 0; x < k.width; ++x) {
      double sum = 0;
      for (int sy = 0; sy < kSS; ++sy)
        for (int sx = 0; sx < kSS; ++sx) {
          const double u = x - 0.5 + (sx + 0.5) / kSS, v = y - 0.5 + (sy + 0.5) / kSS;
          const glm::dvec3 dir_c((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
          const glm::dvec3 o = glm::dvec3(c2w[3]);
          const glm::dvec3 d = glm::dmat3(c2w) * dir_c;
          double value = 150.0 + 40.0 * (double(x) / k.width);  // background: a soft grey ramp
          double nearest = 1e30;
          for (const auto& dt : drawn) {
            const glm::dvec3 ol = glm::dvec3(dt.world_to_tag * glm::dvec4(o, 1.0));
            const glm::dvec3 dl = glm::dmat3(dt.world_to_tag) * d;
            if (std::abs(dl.z) < 1e-12) continue;
            const double s = -ol.z / dl.z;
            if (s <= 0 || s > nearest) continue;
            const glm::dvec3 p = ol + s * dl;
            // Tag frame: x right, y up; image row 0 is the tag's top.
            const double col = (p.x / cell) + total / 2.0, row = total / 2.0 - (p.y / cell);
            if (col < 0 || row < 0 || col >= total || row >= total) continue;
            nearest = s;
            value = dt.img->buf[int(row) * dt.img->stride + int(col)] ? 235.0 : 20.0;
          }
          sum += value;
        }
      const uint8_t g = uint8_t(std::lround(sum / (kSS * kSS)));
      img.at(x, y)[0] = img.at(x, y)[1] = img.at(x, y)[2] = g;
    }
  // Debian's libapriltag 3.3 does not export image_u8_destroy; image_u8_create allocates the
  // struct and its buffer with calloc.
  for (auto& dt : drawn) {
    std::free(dt.img->buf);
    std::free(dt.img);
  }
  tag36h11_destroy(fam);
  return img;
}

Pose look_at(const glm::dvec3& eye, const glm::dvec3& target, const glm::dvec3& up_world) {
  // Camera frame: x right, y down, z forward.
  const glm::dvec3 z = glm::normalize(target - eye);
  const glm::dvec3 x = glm::normalize(glm::cross(z, -up_world));
  const glm::dvec3 y = glm::cross(z, x);
  Pose p;
  p.translation = eye;
  p.rotation = glm::normalize(glm::quat_cast(glm::dmat3(x, y, z)));
  return p;
}

double rotation_error_deg(const glm::dquat& a, const glm::dquat& b) {
  const double d = std::abs(glm::dot(glm::normalize(a), glm::normalize(b)));
  return glm::degrees(2.0 * std::acos(std::min(1.0, d)));
}

Intrinsics synthetic_camera() {
  Intrinsics k;
  k.width = 640;
  k.height = 480;
  k.fx = k.fy = 520.0;
  k.cx = 319.5;
  k.cy = 239.5;
  return k;
}

// A tag on a wall (facing +z of the world) and one on the floor (face up).
AprilTagSettings two_tags(std::vector<SyntheticTag>* scene) {
  AprilTagSettings s;
  s.size_m = 0.16;
  Pose wall;
  wall.translation = {0.0, 0.3, 0.0};
  Pose floor;
  floor.translation = {0.35, 0.0, 0.25};
  floor.rotation = glm::angleAxis(glm::radians(-90.0), glm::dvec3(1, 0, 0));  // tag +z -> world +y
  s.tags = {{3, wall}, {17, floor}};
  scene->push_back({3, wall});
  scene->push_back({17, floor});
  return s;
}

TEST(AprilTagSynthetic, KnownPosesRecoveredWithStatedErrors) {
  std::vector<SyntheticTag> scene;
  const AprilTagSettings tags = two_tags(&scene);
  const Intrinsics k = synthetic_camera();
  struct Case {
    const char* name;
    glm::dvec3 eye, target;
    int expect_tags;
  };
  const Case cases[] = {
      {"frontal 0.8 m", {0.0, 0.3, 0.8}, {0.0, 0.3, 0.0}, 1},
      {"oblique 35 deg", {0.5, 0.45, 0.7}, {0.05, 0.2, 0.05}, 1},
      {"high, both tags", {0.2, 0.9, 0.9}, {0.15, 0.1, 0.1}, 2},
      {"far 1.5 m", {-0.3, 0.5, 1.5}, {0.0, 0.3, 0.0}, 1},
  };
  double worst_rot = 0, worst_trans = 0;
  for (const Case& c : cases) {
    const Pose truth = look_at(c.eye, c.target, {0, 1, 0});
    const ImageRGB8 img = render_tags(scene, tags.size_m, k, truth);
    auto det = AprilTagDetector::create("tag36h11");
    ASSERT_TRUE(det.ok());
    const auto found = det->detect(img);
    auto solve = solve_camera_pose(found, tags, k, 3.0);
    ASSERT_TRUE(solve.ok()) << c.name << ": " << solve.error().message << " (" << found.size() << " tags found)";
    EXPECT_GE(solve->tags_used, c.expect_tags) << c.name;
    const double rot = rotation_error_deg(solve->camera_to_world.rotation, truth.rotation);
    const double trans = glm::length(solve->camera_to_world.translation - truth.translation);
    const double dist = glm::length(c.eye - c.target);
    std::printf("apriltag synthetic %-16s tags %d  rms %.3f px  rotation error %.3f deg  translation error %.2f mm (%.2f%% of %.2f m)\n",
                c.name, solve->tags_used, solve->rms_px, rot, trans * 1e3, 100 * trans / dist, dist);
    EXPECT_LT(rot, 1.0) << c.name;
    EXPECT_LT(trans, 0.01 * dist) << c.name;
    EXPECT_LT(solve->rms_px, 1.0) << c.name;
    worst_rot = std::max(worst_rot, rot);
    worst_trans = std::max(worst_trans, trans / dist);
  }
  RecordProperty("worst_rotation_error_deg", std::to_string(worst_rot));
  RecordProperty("worst_translation_error_rel", std::to_string(worst_trans));
}

TEST(AprilTagSynthetic, TrackerSmoothsHoldsAndReportsLoss) {
  std::vector<SyntheticTag> scene;
  const AprilTagSettings tags = two_tags(&scene);
  const Intrinsics k = synthetic_camera();
  AprilTagTrackerSettings s;
  s.smoothing_tau_s = 0.1;
  s.hold_s = 0.25;
  auto tracker = AprilTagTracker::create(tags, k, s);
  ASSERT_TRUE(tracker.ok()) << tracker.error().message;
  const Pose a = look_at({0.0, 0.3, 0.8}, {0.0, 0.3, 0.0}, {0, 1, 0});
  const Pose b = look_at({0.1, 0.3, 0.8}, {0.1, 0.3, 0.0}, {0, 1, 0});  // 10 cm to the right
  EXPECT_EQ(tracker->state(), TrackingState::NotAcquired);
  InputFrame f;
  f.color = render_tags(scene, tags.size_m, k, a);
  f.timestamp = 0.0;
  auto r0 = tracker->fill_pose(f);
  ASSERT_EQ(r0.state, TrackingState::Tracking);
  ASSERT_TRUE(f.pose.has_value());
  EXPECT_LT(glm::length(f.pose->translation - a.translation), 0.005);  // first pose: no lag
  // Jump to b at dt = tau: the filter moves 1 - e^-1 = 63.2% of the way.
  f.color = render_tags(scene, tags.size_m, k, b);
  f.timestamp = 0.1;
  auto r1 = tracker->fill_pose(f);
  ASSERT_EQ(r1.state, TrackingState::Tracking);
  const double moved = (f.pose->translation.x - a.translation.x) / (b.translation.x - a.translation.x);
  EXPECT_NEAR(moved, 1.0 - std::exp(-1.0), 0.05);
  EXPECT_LT(glm::length(r1.raw_pose->translation - b.translation), 0.005);
  // Tags out of view: holding for hold_s, then lost (no pose).
  ImageRGB8 blank(k.width, k.height, 128);
  f.color = blank;
  f.timestamp = 0.2;
  auto r2 = tracker->fill_pose(f);
  EXPECT_EQ(r2.state, TrackingState::Holding);
  ASSERT_TRUE(f.pose.has_value());
  f.timestamp = 0.5;
  auto r3 = tracker->fill_pose(f);
  EXPECT_EQ(r3.state, TrackingState::Lost);
  EXPECT_FALSE(f.pose.has_value());
  // Re-acquired: the filter restarts at the new pose.
  f.color = render_tags(scene, tags.size_m, k, b);
  f.timestamp = 0.6;
  auto r4 = tracker->fill_pose(f);
  EXPECT_EQ(r4.state, TrackingState::Tracking);
  EXPECT_LT(glm::length(f.pose->translation - b.translation), 0.005);
}

TEST(AprilTagSynthetic, BadSettingsAndWrongTagSizeAreNamedErrors) {
  AprilTagSettings none;
  auto a = AprilTagTracker::create(none, synthetic_camera());
  ASSERT_FALSE(a.ok());
  EXPECT_NE(a.error().message.find("apriltag.tags"), std::string::npos);
  std::vector<SyntheticTag> scene;
  AprilTagSettings tags = two_tags(&scene);
  tags.family = "tag99h99";
  auto b = AprilTagTracker::create(tags, synthetic_camera());
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.error().message.find("tag99h99"), std::string::npos);
  // Both tags visible but the declared size is wrong by 30%: the two tags disagree and the
  // joint solve's reprojection error exposes it.
  tags = two_tags(&scene);
  const Intrinsics k = synthetic_camera();
  const ImageRGB8 img = render_tags(scene, tags.size_m, k, look_at({0.2, 0.9, 0.9}, {0.15, 0.1, 0.1}, {0, 1, 0}));
  auto det = AprilTagDetector::create("tag36h11");
  const auto found = det->detect(img);
  ASSERT_EQ(found.size(), 2u);
  tags.size_m *= 1.3;
  auto c = solve_camera_pose(found, tags, k, 3.0);
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.error().message.find("reprojection"), std::string::npos) << c.error().message;
}

}  // namespace
}  // namespace mrgi

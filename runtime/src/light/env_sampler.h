// Importance sampling of an environment image into N directional lights by median cut
// (Debevec 2005, "A Median Cut Algorithm for Light Probe Sampling"; the DIR and DLPV papers
// sample their environment maps into lights the same way: regions of equal energy, one light
// each), plus the SH projection of the whole image for what the lights leave out.
//
// The image (equirectangular or equidistant fisheye, EnvCamera) is first gathered into a fixed
// world-space equirectangular grid: every image pixel adds its radiance times its solid angle to
// the grid cell its direction falls in, so a small bright sun is kept however coarse the grid is
// (point sampling the image at the cells' centres misses it); a pixel wider than a cell is split
// into sub-pixels, so a small image fills every cell. The pixel -> cell map is computed once per
// image size, model and rotation and reused, so a frame costs a few multiply-adds per pixel.
// Directions no pixel covers (below a fisheye's horizon) hold no light.
//
// Stability over frames (an env camera's frames differ by noise even in a still scene): the grid
// is filtered over frames with an exponential moving average (`filter_frames`), and each light
// sits at the energy-weighted mean direction of its region, which moves continuously with the
// image; only a cut moving by a cell can move a light, by a fraction of its region.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "light/sh_tools.h"
#include "mrgi/expected.h"
#include "mrgi/frame.h"
#include "mrgi/image.h"

namespace mrgi::light {

struct EnvSamplerSettings {
  // Width of the world-space grid in cells (height = width / 2); 8..1024, even. 64: cells of
  // 5.6 degrees, finer than any region of a 16-light cut of a real environment.
  int grid_width = 64;
  // Lights the median cut makes: a power of two, 1..256. Fewer when regions cannot be split
  // further (a single cell).
  int samples = 16;
  // Exponential moving average of the grid over frames: the time constant in frames (a step
  // moves 1 - exp(-1 / filter_frames) of the way). 0 = no filtering. The lag of a change is about
  // this many frames.
  double filter_frames = 2.0;
  // A cell belongs to a light source when its luminance is at least this many times the mean
  // over the lit cells; each 8-connected group of such cells (wrapping around in azimuth) is one
  // source, whose solid angle (its energy over its peak radiance, so the cells it covers only
  // in part do not inflate it) each region reports (EnvLight::source_solid_angle_sr).
  double source_contrast = 3.0;
};

// One light of the cut: a region of the sphere collapsed to a directional light.
struct EnvLight {
  glm::dvec3 direction{0.0, 1.0, 0.0};  // unit, world, towards the light
  glm::dvec3 irradiance{0.0};           // W/m^2 per linear RGB channel at normal incidence
  double solid_angle_sr = 0.0;          // of its region
  double lit_solid_angle_sr = 0.0;      // of its cells holding light (seen by the image)
  // Solid angle of the light source (EnvSamplerSettings::source_contrast) its brightest cell
  // belongs to; 0 when that cell is not bright enough to be part of one.
  double source_solid_angle_sr = 0.0;
  // Radiance SH (4 bands) of the region's own cells: what the environment's SH loses when this
  // region is drawn as a light instead (radiance_sh() minus it is >= 0 everywhere the SH of
  // the other regions is, unlike subtracting a delta light's SH, which rings).
  ShRgb region_sh{};
};

// A light source of the environment (EnvSamplerSettings::source_contrast): its connected cells
// at least that many times the mean radiance, gathered whole, however a median cut splits it.
struct EnvSource {
  glm::dvec3 direction{0.0, 1.0, 0.0};  // unit, world, luminance-weighted, towards it
  glm::dvec3 irradiance{0.0};           // W/m^2 per linear RGB channel at normal incidence
  double solid_angle_sr = 0.0;          // of its cells
  ShRgb sh{};                           // radiance SH (4 bands) of its cells
};

// A part of a region (EnvSampler::split_light): a sub-region of equal energy collapsed to a
// directional light.
struct EnvPart {
  glm::dvec3 direction{0.0, 1.0, 0.0};  // unit, world, towards the light
  glm::dvec3 irradiance{0.0};           // W/m^2 per linear RGB channel at normal incidence
  double solid_angle_sr = 0.0;          // of its cells
};

class EnvSampler {
 public:
  // BadUsage naming the field when a setting is out of range.
  static Expected<EnvSampler> create(const EnvSamplerSettings& settings);

  // Gathers `image` (linear radiance times `intensity`; camera.rotation and `env_to_world` map
  // its directions to the world) into the grid, filters it with the previous frames, cuts it.
  // BadInput for an empty image or a fisheye without a focal length. NaN, Inf and negative
  // texels count as 0.
  // Cells no pixel covers (below a fisheye's horizon) take `unseen_radiance` (the light stage's
  // prior for what the env camera cannot see; 0 = no light from there).
  Status update(const ImageRGBF& image, const EnvCamera& camera, const glm::dquat& env_to_world,
                double intensity = 1.0, const glm::dvec3& unseen_radiance = glm::dvec3(0.0));
  // Forgets the history (the next update is not blended with earlier frames).
  void reset() { have_history_ = false; }

  bool valid() const { return have_history_; }
  // The lights, strongest (luminance of the irradiance) first.
  const std::vector<EnvLight>& lights() const { return lights_; }
  // The light sources' parts outside the regions `excluded` (indices into lights(): those drawn
  // as lights apart), strongest (luminance of the irradiance) first, at most `count`; `out` is
  // cleared first (reserve it: nothing is allocated when it holds `count`).
  void sources_outside(const std::vector<size_t>& excluded, size_t count, std::vector<EnvSource>& out) const;
  // Light `index` (into lights()) as `parts` lights (a power of two, at most 64), by carrying
  // the median cut on inside its region: equal-energy parts at their own mean directions, whose
  // irradiances add up to the light's; a single cell that cannot be halved again stands for both
  // halves with half its light each. For a broad region drawn as several shadowed lights (soft
  // shadows), not one. Written to out[0, parts); returns parts (0 for a bad index or count).
  int split_light(size_t index, int parts, EnvPart* out) const;
  // Radiance SH (4 bands) of the whole filtered grid.
  const ShRgb& radiance_sh() const { return sh_; }
  // Mean luminance of the radiance over the cells holding light (what the image saw), 0 when
  // none does: what a region's own mean radiance is compared with (LightStageSettings::
  // shadowed_min_contrast).
  double mean_lit_luminance() const { return mean_lit_luminance_; }
  const EnvSamplerSettings& settings() const { return settings_; }
  int grid_height() const { return settings_.grid_width / 2; }
  // Filtered radiance of grid cell (x, y), linear RGB (for tests and plots).
  glm::dvec3 cell_radiance(int x, int y) const { return radiance_[size_t(y) * settings_.grid_width + x]; }
  // Unit world direction of the centre of grid cell (x, y) (the equirectangular convention of
  // light_from_environment: u = 0.5 + atan2(x, -z) / 2 pi, v = acos(y) / pi).
  glm::dvec3 cell_direction(double x, double y) const;
  // The grid and its pyramid for cones wider than a cell (shaders/common/env_grid.glsl): level
  // 0 is the grid, each next level half as wide, a cell the solid-angle-weighted mean of the
  // 2 x 2 cells below it, down to `levels` levels or a level 4 cells wide; the levels one after
  // the other in `out` (rgb radiance, a 0), resized to fit. Returns the levels written.
  int cone_pyramid(int levels, std::vector<glm::vec4>& out) const;
  // The cells cone_pyramid writes for `levels` levels of a grid `width` cells wide.
  static size_t cone_pyramid_cells(int width, int levels);

 private:
  explicit EnvSampler(const EnvSamplerSettings& s) : settings_(s) {}
  Status build_map(const ImageRGBF& image, const EnvCamera& camera, const glm::dquat& env_to_world);
  void cut();

  EnvSamplerSettings settings_;
  // The image geometry the map was built for.
  struct MapKey {
    int width = 0, height = 0;
    EnvModel model = EnvModel::Equirectangular;
    double f = 0, cx = 0, cy = 0, fov = 0;
    glm::dquat rotation{1, 0, 0, 0};
    bool operator==(const MapKey&) const = default;
  } map_key_;
  bool have_map_ = false;
  // One (sub-)pixel of the image: the cell its direction falls in, its solid angle, its world
  // direction.
  struct MapEntry {
    uint32_t pixel;
    int32_t cell;
    float solid_angle;
    glm::vec3 direction;
  };
  std::vector<MapEntry> entries_;
  // A rectangle of grid cells [x0, x1) x [y0, y1).
  struct RegionRect {
    int x0, x1, y0, y1;
  };
  std::vector<RegionRect> regions_, next_regions_;
  // The cut's tools: a rect's energy (from energy_sat_, as of the last cut), its median split
  // (false for a single cell), and its light (region_sh only with `with_sh`).
  double rect_energy(const RegionRect& r) const;
  bool split_rect(const RegionRect& r, RegionRect& a, RegionRect& b) const;
  void collapse(const RegionRect& r, EnvLight& l, bool with_sh) const;
  std::vector<RegionRect> light_rects_;        // lights_'s regions, in lights_'s order
  std::vector<size_t> light_order_;            // cut()'s sort of the regions by luminance
  std::vector<double> cell_solid_angle_;       // grid geometry
  std::vector<glm::dvec3> cell_sum_;           // this frame: sum of L dw per cell
  std::vector<double> cell_seen_;              // this frame: sum of dw per cell
  std::vector<glm::dvec3> radiance_;           // filtered radiance per cell
  std::vector<glm::dvec3> frame_moment_;       // this frame: sum of luminance(L) dw d per cell
  std::vector<glm::dvec3> moment_;             // filtered, scaled to a fully seen cell
  std::vector<double> energy_sat_;             // summed-area table of luminance * cell dw
  bool have_history_ = false;
  std::vector<EnvLight> lights_;
  double mean_lit_luminance_ = 0.0;
  // Per cell: its source's index into source_solid_angle_ (-1: not in a source); reserved at
  // start-up, as is the flood's stack.
  std::vector<int32_t> cell_source_;
  std::vector<double> source_solid_angle_;
  std::vector<int32_t> flood_;
  // sources_outside()'s scratch, one entry a source, reserved at start-up.
  mutable std::vector<EnvSource> source_sum_;
  mutable std::vector<glm::dvec3> source_moment_;
  mutable std::vector<uint8_t> cell_excluded_;
  void find_sources();
  ShRgb sh_{};
  std::vector<ShVector> cell_sh_;              // Y_i(cell centre) * cell dw
};

}  // namespace mrgi::light

// The probeless estimate's memory of the views a user sweeps: radiance samples (a surface
// patch's world position and normal, its diffuse transfer vector T, the colour it showed) kept in
// world space across frames, so the least-squares system for the environment SH holds every
// orientation of surface the camera has seen, not only the current view's (one view of a floor
// and a box constrains 1-3 of the 16 SH directions; a 90-degree sweep adds walls, table sides and
// the other faces of objects).
//
// A sample stands for a cell of `cell_m` metres and one of 32 orientations (a table's top and
// its side in the same cell are two samples). Each observation of the cell moves the sample's
// colour and transfer towards the new one with a running mean over `colour_frames` observations,
// so noise and the differences between views average out. Every sample is one row of the system
// (each patch of surface counts alike, however often or closely it was seen).
//
// Stale samples: when the light changes (a lamp switched on) the samples not in view keep the
// old light's colours. A change is detected without the estimate (which may itself be wrong where
// the view is new): surfaces seen again show a different brightness than they had. When at least
// `change_fraction` of the re-observed samples of a frame (and `change_min_samples` of them)
// differ in luminance by more than a factor `change_ratio`, the frame is a light change: every
// sample not observed in that frame is dropped, the observed ones restart from their new colour.
// A camera move or a new view cannot trigger it (new cells are not re-observations); a moving
// shadow can only where it covers half of what is seen again.
//
// Distant light seen directly (`distant_views`): where the depth frame has no surface over a block and around it
// (ProbelessSettings::distant_margin), the colour frame shows the radiance arriving from beyond
// the sensor's range in that direction (sky, a window, a far wall): a sample of the distant light
// L(w) itself, not of a surface it lit. Such views are kept per direction bin (an equal-area grid
// of `distant_rows` bands in the cosine of the elevation by 2 `distant_rows` in azimuth; each
// with the running means of its directions and colours) and each seen bin is one row
// Y(w) . l = colour of the system. Why: the surfaces in view pin the light they face (mostly the
// sky above a floor and a table); a sweep that shows the horizon sees the light the objects get
// from the side directly (a sunlit facade across a courtyard). Not counted for light changes.
//
// Everything is allocated at start-up for `capacity` samples and the distant bins; when full, the
// quarter least recently seen samples are dropped.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include <glm/glm.hpp>

#include "light/sh_estimator.h"
#include "mrgi/expected.h"

namespace mrgi::light {

struct RadianceSampleSettings {
  // Accumulate over views; false: every solve from the current view's samples only.
  bool enabled = true;
  double cell_m = 0.06;        // side of the world cell a sample stands for, metres (0.005..1)
  int capacity = 8192;         // samples kept (64..65536)
  // Observations a sample's running mean spans (1..1024). Long, so a sample's value converges
  // whatever order the views come in (16: the estimate swung +-1.5 degrees with the camera's
  // phase on a looped sweep; 256: within 0.05 after settling); a change of the light is followed
  // by the detector below, not by the mean.
  int colour_frames = 256;
  double change_ratio = 1.12;  // luminance factor that counts a re-observed sample as changed (> 1)
  double change_fraction = 0.5;  // of a frame's re-observed samples, for a light change (0..1]
  int change_min_samples = 12;   // re-observed samples a frame needs before it can be a change
  // Observations after which a sample's transfer vector is kept and later views give colour only
  // (1..1024): the screen-space visibility of 64 directions is most of the stage's cost, and a
  // surface seen from 8 views has a settled transfer (0.3 of the stage's CPU ms at 640x480 after
  // a sweep, against 2.4 with every sample's transfer computed each view).
  int settle_observations = 8;
  // Read blocks without depth as views of the distant light (see above; only above the dominant
  // real surface, add_to). Without that rule the far floor a camera sees beyond the sensor's range
  // was read as light from below: env_fisheye lit by the estimate 0.590 -> 0.602, the independent
  // courtyard_bunny 0.795 -> 0.800 (perf/results/light-moving/README.md).
  bool distant_views = true;
  // Distant-light bins' elevation bands (1..64), 2x as many azimuth bins each: 16 gives 512 bins
  // of 0.025 sr (about 9 degrees).
  int distant_rows = 16;
  // Weight of a distant bin's row against a surface sample's (each 1 before normal balancing),
  // > 0. 1: a direction seen counts as much as a patch of surface.
  double distant_weight = 1.0;
};

class RadianceSamples {
 public:
  // BadUsage naming the field for a setting out of range.
  static Expected<RadianceSamples> create(const RadianceSampleSettings& settings);

  // One observation of frame `frame`: world position (metres), unit world normal, its
  // orientation bin (0..63), the transfer vector and the colour (the row's right-hand side) and
  // the row's weight (ProbelessSettings::balance_normals; 1 otherwise).
  // `clipped`: bit c set where channel c of the colour is a lower bound (a pixel of the block
  // saturated in that channel; the other channels are measurements). A sample keeps its
  // unclipped observations over clipped ones, and clipped ones never count as a light change.
  // A position or colour that is not finite (a broken pose) is ignored.
  void observe(const glm::dvec3& position, const glm::vec3& normal, int orientation_bin, const ShVector& transfer,
               const glm::dvec3& colour, float row_weight, int64_t frame, uint8_t clipped = 0);
  // The same observation without a transfer vector, taken only where the sample exists and
  // has `settle_observations` already (its transfer stays): false, and nothing done, otherwise.
  bool observe_if_settled(const glm::dvec3& position, const glm::vec3& normal, int orientation_bin,
                          const glm::dvec3& colour, float row_weight, int64_t frame, uint8_t clipped);
  // A view of the distant light (see above): the world direction it arrives from (towards the
  // light, need not be unit), its colour (radiance, exposure divided out) and which channels are
  // lower bounds (`clipped`, as observe's). Nothing when distant_views is off or it is not finite.
  void observe_distant(const glm::vec3& direction, const glm::dvec3& colour, int64_t frame, uint8_t clipped);
  bool distant_enabled() const { return settings_.distant_views; }
  // Closes frame `frame`'s observations: true when they showed a light change (the samples
  // and distant bins not observed in it are then gone, see above).
  bool end_frame(int64_t frame);
  // Adds every sample as a row (weight sqrt(row_weight) on both sides, as a direct row). A
  // clipped channel is censored data: its row value is the larger of its bound and what
  // `estimate` (radiance SH; the surfaces' `albedo` per channel) predicts there, so a bound the
  // estimate meets says nothing more, one it misses pulls the estimate up (one EM step of
  // least squares with one-sided rows per solve), and the sample's unclipped channels stay
  // measurements (a sunlit surface clips in red first: its green and blue still tell the sun's
  // colour). Without an estimate samples with a clipped channel are left out.
  // With `lamp_position` / `lamp_intensity` (a near lamp found by PointLampFitter: radiant
  // intensity W/sr, RGB), each row's colour has that lamp's unshadowed light taken off
  // (albedo / pi * I cos / d^2, clamped at 0), so the system holds what the lamp does not explain.
  // With `taken_off`, each row's colour has what it returns for the sample taken off first
  // (clamped at 0): the light the surfaces around bounce onto it (albedo_fit.h).
  // Then each distant bin seen: the row Y(w) . l = albedo * colour (the system's rows are
  // divided by the albedo, LightEstimator; LightSystem::add_view), clipped channels censored as
  // above; only the bins on the side `in_front_of` (a unit normal) faces, none without it. Why: the estimator holds
  // that no light arrives from behind the dominant real surface (the floor:
  // LightEstimatorSettings::below_surface_penalty; its bounce is the near field's), and what a
  // camera sees without depth below the horizon is that surface far away, not distant light.
  void add_to(LightSystem& system, const ShRgb* estimate = nullptr, const glm::dvec3& albedo = glm::dvec3(0.5),
              const glm::dvec3* lamp_position = nullptr, const glm::dvec3* lamp_intensity = nullptr,
              const std::function<glm::dvec3(const glm::vec3&, const glm::vec3&)>* taken_off = nullptr,
              const glm::dvec3* in_front_of = nullptr) const;

  struct Sample {
    uint64_t key;
    ShVector transfer;
    glm::dvec3 colour;
    glm::dvec3 last_colour;  // the newest observation (a restart after a change begins there)
    glm::vec3 position;      // running mean of the observations' world positions, metres
    glm::vec3 normal;        // running mean of their unit world normals (not renormalised)
    float row_weight;
    uint8_t clipped;  // bit c: channel c of `colour` is a lower bound
    int observations;
    int64_t last_frame;
  };
  struct DistantBin {
    glm::vec3 direction;     // running mean of the unit directions seen in the bin
    glm::dvec3 colour;       // running mean radiance
    glm::dvec3 last_colour;
    uint8_t clipped;         // bit c: channel c of `colour` is a lower bound
    int observations;        // 0: never seen (or dropped at a light change)
    int64_t last_frame;
  };
  const std::vector<DistantBin>& distant_bins() const { return distant_; }
  const std::vector<Sample>& samples() const { return samples_; }
  size_t size() const { return samples_.size(); }
  int64_t changes() const { return changes_; }
  const RadianceSampleSettings& settings() const { return settings_; }
  void clear();

 private:
  RadianceSamples() = default;
  uint64_t key_of(const glm::dvec3& position, int orientation_bin) const;
  void begin(int64_t frame);  // a new frame's observations: the change counts restart
  // Folds an observation into sample `s` (transfer null: kept); counts re-observations.
  void update(Sample& s, const glm::dvec3& position, const glm::vec3& normal, const ShVector* transfer,
              const glm::dvec3& colour, float row_weight, int64_t frame, uint8_t clipped);
  int64_t find_slot(uint64_t key) const;  // the table slot holding `key` or the empty one it goes in
  void rebuild_table();
  void evict_oldest();
  static double luminance(const glm::dvec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

  RadianceSampleSettings settings_;
  std::vector<Sample> samples_;    // reserved to capacity
  std::vector<DistantBin> distant_;  // 2 distant_rows^2 bins
  std::vector<int32_t> table_;     // open addressing, -1 empty; 2x capacity rounded to a power of 2
  std::vector<int64_t> scratch_;   // last frames, for eviction
  uint64_t table_mask_ = 0;
  int64_t frame_ = -1;             // the frame being observed
  int reobserved_ = 0, changed_ = 0;
  int64_t changes_ = 0;
};

}  // namespace mrgi::light

// The light stage's own probeless input (image-space-illumination-dynamic-ar.md Sec. 5.1-5.2, on
// the CPU): per sample of the depth image, the diffuse radiance transfer vector T(x) in SH with
// screen-space visibility (the continuous K of eq. 7-9, shaders/shared/transfer_math.h, the same
// functions the ssrt technique's transfer pass runs) and the camera's linear colour I_c(x), summed
// into the normal equations T^T T l = T^T I_c that light::LightEstimator solves.
//
// Why on the CPU and coarse: the estimate is a 16-coefficient least-squares fit whose error is
// ruled by what the view shows (which normals, which shadows), not by how many pixels vote, so a
// grid of about 80 samples across the depth image (one per 8 x 8 pixels at 640 x 480, per 4 x 4
// at 320 x 240: relative to the input, so a small capture is not sampled more coarsely) carries
// the same information as every pixel. Each sample's depth and colour are averages over its block, which
// also takes out most of the sensor noise. At that size the work is a few ms of one core, and it
// is spread over `parts` frames (rows interleaved) so no frame pays it all: every technique gets
// the estimate for a constant, small cost instead of a GPU pass (ssrt, whose transfer pass
// computes T at every pixel anyway, hands its own sums to the same estimator instead).
//
// Deviation from the paper: visibility is searched in the current depth image only (no TSDF
// auxiliary views): an occluder outside the view does not shadow. Saturated colour (a channel
// at 250 or more of 255) is not a linear measurement of the light: a single view leaves such a
// block out; the store of the views seen keeps its saturated channels as lower bounds and the
// others as measurements (RadianceSamples::add_to), so a sunlit surface the camera clips still
// says the light is at least that bright, and what colour it is.
//
// With the store and RadianceSampleSettings::distant_views, blocks without depth around them are views of the distant light itself
// (ProbelessSettings::distant_margin, RadianceSamples::observe_distant): the sky or a window
// beyond the depth sensor's range shows the light arriving from there.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "light/radiance_samples.h"
#include "light/sh_estimator.h"
#include "mrgi/expected.h"
#include "frame/camera_view.h"
#include "mrgi/frame.h"
#include "mrgi/scene.h"

namespace mrgi::light {

class CameraColor;  // light/camera_color.h

struct ProbelessSettings {
  // Samples across the depth image's width (16..512); each stands for a square block of
  // width / grid_width pixels (at least 2).
  int grid_width = 80;
  int directions = 64;        // visibility directions over the sphere (Fibonacci), 16..1024
  int march_steps = 6;        // depth-image steps per direction (1..64)
  double radius_m = 0.6;      // how far an occluder is searched, metres (> 0)
  // Frames a full system is spread over (rows interleaved), 1..16: the solve runs every
  // `parts` frames. 8 at 640x480 on lavapipe x2: 2.6 ms a frame, under 2 floor passes (4: 5.2).
  int parts = 8;
  // Weight each sample by the inverse of how many samples share its orientation (normals binned
  // into 32 directions), so every orientation the view shows counts alike. Why: the direction
  // of the light is pinned by the differences between surfaces that face different ways, and a
  // view is mostly floor: unweighted, the few samples on walls and box sides that carry the
  // directional information are outvoted by the regulariser. Off: on the light family's tuning
  // half it helped one scene (a floor with boxes under a low sun, 38 -> 11 degrees) and cost
  // others more (a red wall, 22 -> 39): median 20.6 -> 23.9 degrees.
  bool balance_normals = false;
  // The light's colour by a vote of the samples instead of gray-world's mean
  // (ProbelessBuilder::vote_light_colour), so a coloured wall or table in view is not read as
  // coloured light. Off: chosen on the light family's tuning half (direction median 17.4 ->
  // 12.3 degrees, colour worst 0.49 -> 0.13: its coloured surfaces are minorities), it made the
  // held-out half worse (29.4 -> 32.6 degrees, colour 0.36 -> 0.43: blue and green walls that
  // fill the view win the vote and the light turns blue or green). A mode is no better than a
  // mean when the coloured surface is the majority; it needs a prior on which colours light can
  // have (near the daylight locus) before it can be on.
  bool grey_vote = false;
  // A block is a view of the distant light (RadianceSamples::observe_distant: the sky, a window,
  // anything beyond the depth sensor's range) when neither it nor any block within this many
  // blocks has depth (0..8). Why a margin: a depth sensor also drops the few pixels along a
  // near surface's edges and on dark or shiny spots; those holes are narrow, the far background
  // is not. Only with the store of views, and not while known lamps are taken off (a declared
  // lamp in view would be counted twice).
  int distant_margin = 2;
};

// Irradiance a lamp sends to world point `p` (per channel, at normal incidence: W/m^2 for the
// scene's units; spot cone and inverse square included, no shadow) and the unit direction
// towards it.
glm::dvec3 lamp_irradiance(const LightDesc& l, const glm::dvec3& p, glm::dvec3& to_light);

class ProbelessBuilder {
 public:
  // BadUsage naming the field for settings out of range; BadInput for intrinsics without size
  // or focal length.
  static Expected<ProbelessBuilder> create(const ProbelessSettings& settings, const Intrinsics& color,
                                           const Intrinsics& depth, double depth_scale);

  // Adds the sample rows of part `part` (0..parts-1) of the camera frame `camera` (at its pose)
  // to `system`: I_c is the linear camera value divided by `exposure` (radiance units, the
  // estimator divides by the albedo). Frames whose images do not have the intrinsics' sizes are
  // refused (BadInput).
  // With `samples`, the rows go into that store of the views seen (radiance_samples.h) instead
  // of `system`.
  Status add_part(const frame::CameraView& camera, double exposure, int part, LightSystem& system,
                  RadianceSamples* samples = nullptr);
  // Light the rows should not explain (the residual estimate, light_stage.h): every later row's
  // intensity has albedo / pi * E_lamps(x) taken off, E_lamps the lamps' irradiance at the
  // sample (lamp_irradiance, cosine, and the sample's visibility towards the lamp searched in
  // the depth grid as for the transfer: a screen-space shadow). `albedo` is the estimator's
  // gray-world albedo, so that the subtracted light is in the rows' units (I_c = a T l).
  // An empty list subtracts nothing. Copies the lamps (call at start-up or when they change).
  void set_known_lamps(const std::vector<LightDesc>& lamps, double albedo);
  const ProbelessSettings& settings() const { return settings_; }
  int grid_width() const { return grid_w_; }
  int grid_height() const { return grid_h_; }

 private:
  ProbelessBuilder() = default;
  // Camera-space positions of every grid cell from its block's depth (z 0 = none).
  void build_positions(const frame::DepthView& depth);
  // Normals (camera space, 0 = none) of every cell, their orientation bins and row weights.
  void build_normals(const glm::mat3& camera_to_world_rotation);
  static constexpr int kNormalBins = 32;
  // The light's colour as the mode of the samples' chromaticities; samples far from it take it
  // (their luminance kept). See probeless.cpp.
  void vote_light_colour();
  // The linear mean colour (exposure divided out) of the colour frame's block of one sample
  // around colour pixel c; `saturated` bit ch: channel ch reached kSaturated in a pixel of it.
  // False for an empty block, or (`stop_at_saturated`) one with a saturated pixel.
  bool block_colour(const CameraColor& camera, double exposure, const glm::vec2& c, bool stop_at_saturated,
                    glm::dvec3& colour, uint8_t& saturated) const;
  // Part `part`'s blocks without depth around them (distant_margin) into `samples` as views of
  // the distant light along their world directions.
  void add_distant_views(int part, const glm::mat3& camera_to_world_rotation, const CameraColor& camera,
                         double exposure, int64_t frame, RadianceSamples& samples) const;
  struct Sample {
    int cell;
    glm::dvec3 colour;  // linear, exposure divided out
    uint8_t clipped;    // bit c: a pixel of the block at kSaturated in channel c, a lower bound there
  };
  std::vector<Sample> samples_;         // this part's, reserved at start-up
  std::vector<LightDesc> known_lamps_;  // set_known_lamps
  double known_albedo_ = 0.0;
  static constexpr int kChromaBins = 100;
  std::vector<int> chroma_hist_;        // kChromaBins^2, (r, g) chromaticity

  ProbelessSettings settings_;
  Intrinsics color_, depth_;
  double depth_scale_ = 5000.0;
  int stride_ = 8;                      // depth pixels per sample, each side
  int grid_w_ = 0, grid_h_ = 0;
  float chi_ = 0.0f;
  std::vector<glm::vec3> directions_;   // unit, world
  std::vector<ShVector> direction_sh_;  // Y_i(w) for each direction
  std::vector<glm::vec3> position_;     // camera space, per grid cell; z 0 = none
  std::vector<glm::vec3> normal_;       // camera space, per grid cell; 0 = none
  std::vector<int> bin_;                // orientation bin per cell, -1 = none
  std::vector<float> balance_;          // row weight per cell
  std::vector<int> bin_count_;
  std::vector<glm::vec3> bin_direction_;
};

}  // namespace mrgi::light

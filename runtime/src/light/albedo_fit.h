// The real surfaces' albedo from their interreflection, read off the views a user swept (the
// probeless source's store, radiance_samples.h). A camera sees albedo times irradiance, so one
// view, or any number of views of diffuse surfaces under one light, cannot tell a white room
// under a dim light from a grey room under a bright one: the estimate assumes a grey-world
// albedo (0.5) and is as far off as the room's albedo is from it (a white corner, 0.75, read
// twice too bright with its interreflection).
//
// Interreflection breaks the tie. The light a surface receives from the surfaces around it is
// seen directly, in absolute terms: it is their observed radiance, whatever their albedo. A
// sample at x with normal n receives, from the other kept samples y (patches of area cell^2),
//     B(x) = sum_y L_y max(0, n . w) max(0, -n_y . w) cell^2 / max(d^2, cell^2),   w = (y - x) / d,
// and shows
//     I(x) = a (T(x) . l + B(x) / pi)  [+ a I_lamp / pi max(0, n . v) / |v|^3 for a near lamp],
// T the diffuse transfer, l the distant light's SH (3 bands). With l' = a l this is linear in
// (l', a): a weighted least-squares fit over the samples (on luminance: one grey albedo, by
// default) gives the albedo a where B varies across them differently from what a distant light
// can do (a corner brighter near its crease, a wall lit by a sunlit floor); where it does not,
// a is poorly determined, and where B holds nothing beyond the other columns (a floor alone)
// there is no fit. On a corner rendered here with 4 bounces the fit reads 0.755 for 0.8 and
// 0.314 for 0.3 (tests/light/albedo_fit_test.cpp).
//
// Prior (stated, and tested): real albedos are mostly 0.1-0.9; a Gaussian of mean `prior`
// (the grey world, 0.5) and standard deviation `prior_sigma` (0.15) is combined with the fit's
// own estimate and its standard error (from the residual), so an unconstrained fit returns the
// grey world and a well-constrained one its data; the result is clamped to [min, max].
// Missing emitters (surfaces never seen: the ceiling, the wall behind the camera) make B too
// small, which reads as too high an albedo; the prior and the clamp bound that.
//
// The transfer T here is the store's own: each receiver's hemisphere in direction bins (a cube
// map), a bin covered by the nearest layer of kept samples seeing those samples' radiance (a
// sample seen from behind, dark), the rest of it the distant light. A bin's nearest layer is
// what lies within kLayer (1.5) times its nearest sample's distance: a table top hides the wall
// behind it, and a wall seen at a grazing angle, whose depth spans more within one bin, is not
// cut short (at 1.25 the corner above read 0.85 for 0.8 and 0.42 for 0.3; at 2, 0.74 and 0.29).
// Cost: receivers x emitters x 2; the stage spreads a fit over frames (`receivers_per_step` a
// frame, about 0.4 ms of one core at 640x480) with the emitters a strided subset standing for
// the rest.
//
// The same receivers, with a B / pi taken off their colour, are what the near-lamp search
// reads (point_lamp_fit.h): the light a lamp gives directly, so the walls' bounce does not
// flatten its fall-off. near_field_at() bins the whole sphere around a point the same way: the
// light the kept surfaces send to the virtual objects.
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "light/point_lamp_fit.h"
#include "light/radiance_samples.h"
#include "light/sh_tools.h"

namespace mrgi::light {

struct AlbedoFitSettings {
  bool enabled = true;
  int receivers = 192;         // samples the fit is over (strided over the unclipped ones), 16..4096
  int emitters = 1024;         // samples standing for the surfaces around them (strided), 64..65536
  // Samples the near field reads, 64..65536; beyond, strided and not split (the light stage sets
  // it to the store's capacity).
  int near_field_emitters = 8192;
  int receivers_per_step = 24; // receivers a step computes the terms of (one step a frame), >= 1
  int min_samples = 96;        // fewer unclipped samples: no fit (the prior stands)
  int bands = 3;               // SH bands of the distant light in the fit (1..4)
  double prior = 0.5;          // mean of the albedo prior (grey world)
  double prior_sigma = 0.15;   // its standard deviation (> 0)
  double min_albedo = 0.1, max_albedo = 0.95;
  // Each channel fitted on its own (a tinted room's colour taken off the light) or one grey
  // albedo from luminance (the light's colour left as the grey world reads it).
  bool per_channel = false;
};

struct AlbedoFit {
  bool found = false;            // a fit was made (else albedo is the prior)
  glm::dvec3 albedo{0.5};        // per channel, prior combined, clamped
  glm::dvec3 data_albedo{0.0};   // the data's own estimate per channel, before the prior
  glm::dvec3 data_sigma{0.0};    // its standard error
  double bounce_share = 0.0;     // mean a B / pi over mean I (luminance): how much the bounce explains
  int receivers = 0;
};

// The light reaching a point from `sources` (SH of everything estimated: the distant light, a
// near lamp) with the seen surfaces around it: their `near` field added and, of the `distant`
// light, the part `hidden` behind them (near_field_at) taken off; a lamp in `sources` but not in
// `distant` is left whole (it is in the room, in front of the surfaces it lights).
ShRgb light_at_point(const ShRgb& sources, const ShRgb& distant, const ShRgb& near, const ShMatrix& hidden);

class AlbedoFitter {
 public:
  static constexpr int kFace = 8;  // direction bins per cube face side
  static constexpr int kBins = 6 * kFace * kFace;
  struct Receiver {
    glm::dvec3 p, n, c;
    glm::dvec3 bounce;  // B / pi: the light bounced onto it, in the samples' colour units
    double weight;
    ShVector t;         // its transfer through the bins no kept sample covers
  };

  explicit AlbedoFitter(const AlbedoFitSettings& settings);
  // Starts a fit over the store as it is now (receivers and emitters copied out of it). False,
  // with nothing to step, when the store has fewer than `min_samples` unclipped samples.
  bool begin(const RadianceSamples& store);
  // Computes the next `receivers_per_step` receivers' terms (or `count` where > 0): true once
  // every receiver has them.
  bool step(int count = 0);
  bool busy() const { return next_ < receivers_.size(); }
  // Forgets the fit under way and the fitted receivers (the light changed: their colours are
  // the old light's).
  void restart() {
    receivers_.clear();
    fitted_.clear();
    next_ = 0;
  }
  // The fit over the receivers begun (every one stepped), a near lamp's fall-off one more column
  // where `lamp` is given and found. The receivers become fitted().
  AlbedoFit solve(const PointLampFit* lamp);
  // begin, every step and solve at once.
  AlbedoFit fit(const RadianceSamples& store, const PointLampFit* lamp);
  // The radiance SH of the light `store`'s samples send to `focus` from every direction: the
  // near field a virtual object there receives. Every sample (up to near_field_emitters) is an
  // emitter of its cell's area, and one near the focus is split to the bins it spans (the table
  // under the objects is most of their lower hemisphere). False before any fit was begun (the
  // fitter then has not read the store's settings) or for an empty store.
  // `hidden` (optional) receives the part of the sphere the seen surfaces cover, as the SH
  // matrix H (H_ij = sum over bins of covered solid angle x Y_i Y_j): distant light l reaches the
  // focus as l - H l, the surfaces in front of it send the near field instead.
  bool near_field_at(const glm::dvec3& focus, const RadianceSamples& store, ShRgb& out, ShMatrix* hidden = nullptr);
  // The receivers of the last solved fit with their bounce (empty before the first).
  const std::vector<Receiver>& fitted() const { return fitted_; }
  const AlbedoFitSettings& settings() const { return settings_; }

 private:
  struct Bin {
    glm::dvec3 direction;
    double solid_angle;
    ShVector sh;
  };
  struct Emitter {
    glm::vec3 p, n, c;  // position, unit normal, colour
    float area;         // m^2: the cell's, times the samples it stands for
  };
  // A part of an emitter as a point sees it: an emitter near the point (a table top under the
  // objects) covers more than one direction bin, so it is split into m x m squares in its
  // tangent plane, each small enough for a bin (kMaxSplit^2 at most).
  struct Piece {
    glm::vec3 v;  // from the point to the piece
    float d;      // its distance
    float area;
    int bin;
    int emitter;
  };
  // The fit of `pick` . colour (a channel, or luminance): the bounce column's coefficient and
  // its standard error. False when the system is singular.
  bool solve_pick(const glm::dvec3& pick, const PointLampFit* lamp, double& albedo, double& sigma) const;
  // Fills coverage_ and radiance_ per bin for a point: the nearest layer of `emitters` (within
  // `hemisphere`'s side where given, else the whole sphere); with `split`, an emitter spanning
  // more than half a bin is split into pieces first.
  void cover_bins(const glm::vec3& p, const glm::vec3* hemisphere, const std::vector<Emitter>& emitters, bool split);
  void receiver_terms(Receiver& r);
  // Fills `out` (cleared) with at most `cap` of the store's samples as emitters, strided; the stride.
  size_t read_emitters(const RadianceSamples& store, size_t cap, std::vector<Emitter>& out) const;
  AlbedoFitSettings settings_;
  std::vector<Receiver> receivers_, fitted_;  // reserved to settings.receivers
  std::vector<Emitter> emitters_;             // reserved to settings.emitters
  std::vector<Emitter> near_emitters_;        // reserved to settings.near_field_emitters
  std::vector<Piece> pieces_;                 // the point's scratch; reserved, splitting stops short of full
  size_t next_ = 0;                           // the next receiver a step computes
  double min_d2_ = 0.0;                       // a cell's area: nearer samples are the receiver's own
  double layer_m_ = 0.0;                      // a bin's nearest layer reaches this beyond kLayer x nearest
  double min_bin_solid_angle_ = 1e9;          // sr, the smallest bin's (a cube map's corner texel)
  std::vector<Bin> bins_;
  std::vector<double> coverage_, nearest_;    // per bin, the receiver's scratch
  std::vector<glm::dvec3> radiance_;
};

}  // namespace mrgi::light

// Environment occlusion by the virtual objects, part of the direct-light block: a real surface
// near a virtual object loses the part of the ambient (environment) light the object hides
// from it, softly and in the colour of what is hidden, integrated over the whole environment
// (its SH), not as a few hard directional shadows; a virtual surface likewise loses what other
// parts of the objects hide from it. Differential: only what the virtual objects add (the
// camera already shows the real scene's own occlusion), so it darkens L_rv, never L_r.
//
// What the object shows in place of the sky it hides is its own surface, lit by the same
// ambient: its mean diffuse albedo / pi x the ambient irradiance on a surface facing the point.
// So a bright object on a grey floor under a dull sky takes less than it hides and tints the
// floor with its colour (the truth's soft, coloured halo), and a dark one takes nearly all.
// This one-bounce term is on for every technique: measured on the suite, a GI technique
// without it (its own bounce only) lost more than it gained (moving, dlpv high real-pixel RDE
// 0.416 with it, 0.478 without; medium 0.424 against 0.487).
//
// Each object is stood in for by sphere proxies fitted at load (frame/occluder_spheres.h); per
// texel, each sphere's cap of the sky is weighted by its exact cosine-weighted solid angle and
// the mean radiance of the ambient SH over the cap (shaders/shared/occlusion_math.h), less the
// object's radiance towards the point. Inscribed spheres overlap, and from a few radii away
// their caps lie over one another: each sphere's part is scaled by the object's silhouette
// (from its oriented patches) over its spheres' disc area (far_field_scale), so an object
// hides what its silhouette covers, not up to twice that. The real surfaces the objects darken
// reflect less light on to the rest of the scene: that second bounce is taken off every real
// point as from a diffuse emitter at each object's base (EnvOcclusionLevel::real_bounce_loss). The pass
// (shaders/shading/environment_occlusion.comp) runs on a grid of `divisor` x `divisor` internal
// pixels; the shading pass up-samples it with the surface key (distance to the camera, real or
// virtual) so an object's edge does not bleed onto the floor behind it.
//
// The light it occludes is the ambient only (the light stage's SH after its shadowed lights are
// taken out): shadowed lights already have their shadow maps. The ambient's bright sources,
// each whole (a low sun behind haze, a sunlit wall, a window: light::Lighting::ambient_regions),
// are taken out of the SH and hidden as cones, the exact part of each a proxy's cap covers
// (cap_overlap_solid_angle), so the soft shadow falls away from them as in the truth instead
// of spreading round the object as the SH's 4 bands do.
//
// What an object hides from a point is the environment only where nothing real lies beyond it:
// in a room corner a wall looks through the object at the floor or the other wall. From each
// real point the pass marches a ray per sphere proxy (towards its centre, from its far side)
// through the real G-buffer and, where it meets a real surface within the near-field reach,
// that sphere hides the surface's radiance (the camera's) instead of the sky's, and none of the
// regions beyond it (EnvOcclusionLevel::near_field_steps). Virtual points keep the sky: the
// inscribed spheres of their own object would show real surfaces through gaps the mesh does
// not have.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "frame/frame_resources.h"
#include "frame/surface_orientation.h"
#include "gpu/frame_graph.h"
#include "light/light_stage.h"
#include "light/sh_tools.h"
#include "mrgi/expected.h"

namespace mrgi::shading {

struct EnvOcclusionLevel {
  int divisor = 2;             // internal pixels per texel side, 1..8
  int spheres_per_object = 8;  // the first this many of each object's proxies; 0 = off
  // Of the light stage's bright sources (light::Lighting::ambient_regions), at most this
  // many are hidden as cones (exact cap overlap) instead of through the SH; 0..4.
  int regions = 4;
  // Near field (shaders/shared/occlusion_math.h): march steps of the ray past the objects that
  // looks for a real surface beyond them (0 = off: they always hide the environment), out to
  // near_field_m metres (a room: what lies farther is the environment the env camera sees).
  int near_field_steps = 8;
  float near_field_m = 3.0f;
  // What an object shows in place of what it hides includes the shadowed lights' (lamps,
  // shadowed environment sources) first bounce off its surface, as much of it as faces the point
  // (its oriented patches, occlusion_math.h lit_patch_term): a sunlit object brightens the wall
  // beside it. A technique whose own bounce (VPLs, volumes) carries that light leaves it off.
  // On by default: with the proxies scaled to the silhouette far off and the occlusion's second
  // bounce (below), baseline's all-pixel RDE with it against without, every level, is within
  // -0.011..+0.0036 on the suite and the Cycles tuning scenes (high: corner -0.0067, moving
  // -0.0044, desk_spot -0.0022, corner_blue_yellow -0.0028; glass_mirror +0.0025,
  // spot_in_fisheye +0.0022), and the real-pixel change comes within 30 % of the truth's on 7
  // of 8 Cycles scenes instead of 6 (spot_in_fisheye 2.25 -> 1.11 of it). Near a box lit from
  // above it is still stronger than the truth's (spot_in_fisheye, a few centimetres from the
  // box) and weaker a few decimetres away.
  // Perf/results/env-occlusion/lights-bounce-on-2026-12-06/.
  bool lights_bounce = true;
  // The real surfaces round an object, darkened by it, light the rest of the scene less (the
  // occlusion's second bounce): the flux the object takes from the light travelling down,
  // less what its own surface reflects down, times the surroundings' albedo (the ambient's
  // light from below over the irradiance reaching the ground), is taken off every real point
  // as from a diffuse emitter on the ground at the object's base (occlusion_math.h
  // real_bounce_loss). On by default: with it, the objects' broad darkening of a room's walls
  // comes out as in the truth where the proxies' far-field over-count (far_field_scale) had
  // stood in for it (Cycles window_room_duck: real-pixel change 0.78 of the truth's before
  // the scale, 0.65 with the scale alone, 0.90 with both; all-pixel RDE +0.0055 with the scale
  // alone, +0.0012 with both; perf/results/env-occlusion/far-field-and-real-bounce-2026-12-06/).
  bool real_bounce_loss = true;
  // The loss includes the shadowed lights' share (their light the object keeps from the
  // ground). A technique whose bounce (VPLs, volumes, cones) already loses the lamps' light
  // where the objects shadow it leaves this off.
  bool real_bounce_loss_lights = true;
};

// The radiance (linear RGB: albedo x E / pi) of a virtual object's oriented patch
// (frame/surface_orientation.h, world-space normal) lit by `lights` at the object's `centre`
// (world, metres): each light's irradiance there on the patch's orientation, no shadowing.
glm::vec3 lit_patch_radiance(const frame::OrientedPatch& patch, const glm::vec3& centre,
                             const std::vector<LightDesc>& lights);

// The flux (W per linear RGB channel) the real surfaces round a virtual object reflect less
// because of it (EnvOcclusionLevel::real_bounce_loss): of its `count` oriented patches (world
// normals and areas), the light travelling down they intercept (from the `ambient` radiance SH
// and `lights` at the object's `centre`) less what they reflect down, times the surroundings'
// albedo pi L_below / E_up (the ambient's mean radiance from below over the irradiance on the
// ground at `base`, lights included; at most 0.9). Negative where the object sends down more
// than it takes (a bright object under light from below).
glm::vec3 real_bounce_flux(const frame::OrientedPatch* patches, int count, const light::ShRgb& ambient,
                           const std::vector<LightDesc>& lights, const glm::vec3& centre, const glm::vec3& base);

class EnvironmentOcclusion {
 public:
  static Expected<std::unique_ptr<EnvironmentOcclusion>> create(const frame::FrameResources& frame);
  ~EnvironmentOcclusion();
  // Adds this frame's pass, or leaves it out (appending "env_occlusion: reason" to `skipped`)
  // when nothing is occluded or bounced: the level turns it off, no virtual object is visible,
  // or the ambient is black and no light bounces. `ambient` is the occludable light's radiance SH
  // (4 bands, world axes); `regions` the parts of it kept as cones (their SH is in `ambient`). `lights`: the shadowed
  // lights whose bounce off the objects the pass adds (level.lights_bounce); with
  // `occlude_ambient` false only that bounce is drawn (an ambient that is not to be occluded,
  // such as the lamps' residual estimate, hides nothing).
  void record(const EnvOcclusionLevel& level, const light::ShRgb& ambient,
              const std::vector<light::Lighting::AmbientRegion>& regions, const std::vector<LightDesc>& lights,
              bool occlude_ambient, std::vector<std::string>& skipped);
  // This frame's result (RGBA16F, rgb the irradiance the objects take away, W/m^2, negative
  // where they give more than they hide; a the surface key) and its divisor;
  // a 1x1 zero image with divisor 0 when the pass was left out.
  gpu::ImageHandle image() const;
  int divisor() const;

 private:
  struct Impl;
  explicit EnvironmentOcclusion(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace mrgi::shading

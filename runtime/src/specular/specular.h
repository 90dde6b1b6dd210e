// Reflective and refractive virtual objects (Knecht et al. 2013, "Reflective and refractive
// objects for mixed reality", ../shared/papers/reflective-refractive-caustics-dir.md), a stage of
// the runtime around the technique's shading, so a mirror or a glass object is specular whichever
// technique lights the diffuse scene (dir, the paper's base, or baseline, dlpv, dvct, ssrt).
//
// Per frame, where a reflective or refractive object is in view (shared/specular_math.h
// specular_kind: smooth metal, transmissive materials), before the technique (prepare):
//   specular impostor cells <s>  the real grid's triangles of each cube face of set s
//                                (impostor_cells.comp: a point per impostor texel over the real
//                                G-buffer, none across a depth edge)
//   specular impostors <s>       per set: six 90 degree faces drawn from the set's centre (the real
//                                grid, the proxies, the other virtual objects): world position,
//                                normal, albedo, real or virtual (shaders/specular/impostor.frag)
//   specular back faces          the refractive objects' back faces from the camera (Wyman 2005)
//   specular photon ... <l>      per spot lamp whose cone holds such an object: photon maps and
//                                photons (caustics.h; traced every caustic_refresh_period frames
//                                while nothing moves); the technique reads the photons (dir's
//                                caustic VPLs, frame::FrameInfo::caustics); at the fast level also
//                                their receiver maps, which its direct shading reads
// and after it (finish):
//   specular caustic splat <l>   the photons into the caustic buffer and the diffuse pixels' L_rv
//                                (the paper's levels; none where the shading read receiver maps)
//   specular trace list          the specular pixels, listed by kind
//   specular trace glass         per listed pixel: the reflected and refracted rays' hits, their
//   specular trace mirrors       light with and without the virtual objects, back-projection into
//                                the camera frame and the composite of eq. 6-11
//                                (shaders/specular/trace.comp), into lit_rv
//
// Deviations from the paper, and why:
//   - Impostors: Popescu et al. give each surrounding object its own billboard. Here the
//     surrounding scene is mostly one surface that encloses the object (the reconstructed table
//     under it, the wall behind), which no billboard can hold, so a set's impostor is the six
//     faces of a cube around its centre (distance impostors, Szirmay-Kalos et al. 2005), searched
//     by the same iterative refinement; one layer, so a surface hidden from the centre behind a
//     nearer one is missing (the search then passes behind the nearer one's silhouette).
//   - Eq. 3 sums the lamps and the VPLs at each hit. A hit on a surface the camera sees (the
//     depth validity test of the back-projection) takes the technique's L_rv and L_r there,
//     which is that sum for that surface point, with the technique's visibility (dir's ISMs) and
//     at one image read instead of a VPL loop per ray (the caustics splatted into it too); a hit
//     the camera does not see is lit by the lamps (with the technique's shadow maps where it drew
//     them) and the SH ambient, without VPLs, and the caustic buffer where it lies under a mirror
//     or glass. A virtual hit outside the view is Lambertian.
//   - L_env: the light stage's environment grid (64 x 32 cells of the filtered image, bilinear),
//     not the fish-eye image at its own resolution; the SH where there is no environment image.
//   - Eq. 9's validity is per path (specular_math.h specular_compose says why).
//   - Caustics (Sec. 4.2, caustics.h) add to L_rv; the technique's shadow maps hold the glass as
//     an opaque caster, so the light it lets through is the caustic's alone. dir's caustic VPLs
//     (Sec. 4.2.2) are gi/vpl_sample.comp's. Photons are splatted as points sized by their
//     footprint (Wyman 2008's adaptive quads), not Shah et al.'s fixed quads.
//   - The fast level's savings (SpecularLevel): impostors and photons are world-space and are
//     redrawn every eighth frame or retraced every sixteenth while nothing moved (the camera's
//     newly seen real surfaces wait that long), a quarter of the photons
//     reflected off glass carry four times the flux, glass reflections weaker than 10 %
//     show L_env instead of a traced hit, and the caustics are splatted once per trace into
//     receiver maps around the lamps (Wyman and Davis's light-space caustic maps, as an
//     octahedral map so photons a mirror throws outside the cone are kept) that the shading reads
//     instead of the camera's per-frame splat (SpecularLevel::caustic_receiver_map); hits outside
//     the view get their caustics from the maps too.
#pragma once
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "common/frame_constants.glsl"
#include "gpu/frame_graph.h"
#include "gpu/pipelines.h"
#include "mrgi/expected.h"
#include "frame/frame_resources.h"
#include "mrgi/research.h"
#include "shading/direct_light.h"

namespace mrgi::specular {

// One level of the stage's ladder. Units: texels per impostor face side; steps per ray.
struct SpecularLevel {
  const char* name;
  uint32_t impostor_face;  // texels per side of each of a set's six faces
  // Sets with their own centre: the first own_sets specular objects in view (nearest the camera
  // first) get one each, the rest share the last one, drawn around all of them.
  int own_sets;
  int search_steps;        // linear search steps along a ray through the impostors
  int refine_steps;        // secant refinements of a bracketed crossing
  int back_face_steps;     // search steps for the refracted ray's exit in the back faces
  // Glass pixels whose Fresnel reflectance is below this take the environment's radiance
  // (L_env) for their reflection instead of a traced one (0: every one traced). Glass reflects
  // 4-10% of the light over most of its face, and the reflected rays, mostly meeting far walls,
  // run the longest searches: at 0.1 the trace on glass_mirror's fast dir frame took ~1 of 3.4 ms
  // less; the error is at most that fraction of the difference between the two radiances.
  float glass_reflection_fresnel;
  // Frames between redraws of a set whose objects did not move (1: every frame). The impostors
  // are world-space surfaces, so a set a frame old differs only by what the camera newly sees
  // of the real scene; at 8, two sets cost a quarter of a set's drawing a frame.
  int refresh_period;
  uint32_t caustic_map;    // texels per side of each spot lamp's photon maps (0: no caustics)
  // Frames between traces of photons whose lamps and objects did not move (1: every frame; see
  // Caustics::Refresh). The splat, the camera's part, runs every frame.
  int caustic_refresh_period;
  // Photon-map texels per side of each photon reflected off glass (1: every texel's; 2: one
  // texel's in each 2 x 2 block, with four times the flux). Glass reflects a few percent of the
  // light, spread widely by its curvature, so those photons are dim and each covers the largest
  // splat: at 128^2 they took 1.4 of the splat's 2.5 ms on glass_mirror's fast dir frame (lavapipe
  // sets up each splat on one thread). A mirror's reflected photons, which a concave one focuses,
  // are every texel's.
  int glass_reflection_stride;
  // Whether dir's VPLs drawn on mirrors and glass move to where their photons landed (caustic
  // VPLs, paper Sec. 4.2.2; false: such a VPL stays on the object, lighting as a diffuse one).
  bool caustic_vpls;
  // Texels per side of each lamp's caustic receiver map (0: the paper's splat into the camera's
  // caustic buffer every frame). With a map, the photons are splatted once per trace into the
  // octahedral map of directions around the lamp (caustic_receiver.glsl), and the technique's
  // direct shading reads it at every pixel it lights (shading::DirectLightOutput::caustics_added:
  // the direct-light block's shading, under baseline, dir, dlpv and dvct; a technique without it would get the
  // camera's splat, but ssrt, the one that lights otherwise, is lit by its own estimate, not by
  // the spot lamps that make caustics). Why: the splat's per-photon setup is
  // lavapipe's single-threaded part, 2.1 ms a frame on glass_mirror's fast dir frame, and the
  // photons are world-space; 512^2 texels are about an internal pixel where that scene's spot
  // lamp points (2 / 512 rad at its 0.85 m: 3.3 mm, the camera's 3.8 mm), 3.3 mm to 7.5 mm
  // elsewhere (the map's texels span 1 to 5.2 times the pole's solid angle).
  uint32_t caustic_receiver_map;
};
// paper (512^2 impostors, a set per object up to four, 512^2 caustic maps), high (256^2, two
// sets, 256^2 caustic maps), fast (96^2 impostors, two sets, each redrawn every eighth frame
// while its objects stay put; 128^2 caustic maps whose photons are traced every sixteenth frame
// while the lamps and objects stay put, a quarter of the glass-reflected photons, no caustic
// VPLs: the fast path, for 33 ms at 640 x 480 on lavapipe x2).
const std::array<SpecularLevel, 3>& specular_levels();
// The stage's level for a technique's level: the technique's first level gets the paper's
// settings, its last two the fast ones, the others high.
const SpecularLevel& specular_level_for(int technique_level, int technique_levels);

// Ablations (RuntimeSettings knobs of the same names would go here once the runtime exposes
// them; the bench's images are made with these).
struct SpecularSettings {
  bool back_projection = true;  // false: every hit shows its rendered light (no camera colour)
  bool depth_test = true;       // false: a back-projection is trusted without the depth test
  uint32_t max_impostor_face = 512;  // allocated texels per face side (the largest level)
  int max_sets = 2;                  // allocated impostor sets
  // Fraction of the depth within which a back-projected hit must meet the real G-buffer's depth
  // (sensor noise and the impostor's texel size).
  float depth_tolerance = 0.04f;
  bool caustics = true;                 // false: no caustic maps (the ablation no-caustics)
  uint32_t max_caustic_map = 512;       // allocated texels per side of the photon maps
  uint32_t max_caustic_receiver_map = 512;  // allocated texels per side of the receiver maps
};

// The defaults with ResearchSettings::specular's flags applied (mrgi/research.h) (its `off` is the
// runtime's: no stage at all).
SpecularSettings settings_for(const SpecularAblation& ablation);

class SpecularStage {
 public:
  // nullptr (no error) when no virtual material is specular: nothing is allocated.
  static Expected<std::unique_ptr<SpecularStage>> create(const frame::FrameResources& shared,
                                                         const SpecularSettings& settings);
  ~SpecularStage();
  // Before the technique's record(): records this frame's impostors, back faces and caustics
  // (their photons are what a technique reads to move its VPLs off mirrors and glass:
  // caustic_photons()), or appends "specular: <reason>" to `skipped`. `fc` is this frame's
  // FrameConstants; the technique's level picks the stage's (specular_level_for).
  Status prepare(const shader::FrameConstants& fc, int technique_level, int technique_levels,
                 std::vector<std::string>& skipped);
  // This frame's caustic photons (after prepare; nullptr: none).
  const frame::CausticPhotons* caustic_photons() const;
  // After the technique's record(): the mirrors' and glass's pixels (specular trace) and the
  // caustics on the diffuse ones, over the technique's solutions. `direct`: what the technique's
  // direct-light block applied this frame (Technique::direct_light), whose lights and shadow
  // maps light the hits the same way; nullptr: it drew no shadow maps (the hits are lit
  // unshadowed).
  Status finish(const shading::DirectLightOutput* direct, std::vector<std::string>& skipped);
  // After record(): this frame's caustics may have lit pixels outside the technique's compose
  // tiles (Technique::compose_tiles): the frame must be composed everywhere.
  bool lights_outside_tiles() const;

 private:
  struct Impl;
  explicit SpecularStage(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace mrgi::specular

#version 460
// Environment occlusion by the virtual objects (shading/environment_occlusion.h): per texel of
// a grid of `divisor` x `divisor` internal pixels, the surface at the texel's centre pixel (the
// virtual one where there is one, else the real one) and the irradiance the virtual objects'
// sphere proxies hide from it of the occludable ambient light (its radiance SH), per
// shared/occlusion_math.h (each scaled to its object's silhouette far off: far_field_scale),
// less what their objects' surfaces send it instead (albedo / pi x
// the ambient irradiance facing the point, and the shadowed lights' light off as much of the
// object's surface as faces the point, where the level asks for it), plus what they hide of the broad regions kept apart
// from the SH (the part of each region's cone their caps cover). Near field (occlusion_math.h):
// where a sphere's ray past it meets a real surface within the reach, that surface's radiance
// (the camera's) is what the sphere hides instead of the sky's, and the regions beyond it were
// not reaching the point (real points only; spheres hiding at least 0.1 % of the hemisphere:
// the march is the pass's main cost, and a farther sphere hides the sky as before). On real
// points, where the level asks for it, the objects' surroundings, darkened by them, light the
// point less (real_bounce_loss). Written as rgb = that net irradiance taken away
// (W/m^2, negative where an object gives more than it hides), a = the surface's key:
// its distance to the camera, negative on a virtual surface, 0 where there is none (the
// direct-light pass up-samples by it).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "shared/mrgi_shared.h"
#include "shared/occlusion_math.h"
#include "common/frame_constants.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
// Every sphere belongs to object 0 or to none of the lit objects (the usual single object): its
// per-object values are computed once before the sphere loop and the loop's per-object block is
// compiled out. On lavapipe every lane runs that block on every sphere, taken or not, and its 27
// uniform reads at a dynamic object index are gathered lane by lane.
layout(constant_id = 0) const bool kOneObject = false;
layout(std140, set = 0, binding = 0) uniform FrameUbo { FrameConstants frame_ubo; };
FrameConstants frame;  // private copy (MRGI_UNIFORM_COPIES, frame_constants.glsl)
layout(std140, set = 0, binding = 1) uniform OcclusionUbo { EnvOcclusionSet occluders; };
layout(set = 0, binding = 2, rgba32f) readonly uniform image2D real_position;
layout(set = 0, binding = 3, rgba16f) readonly uniform image2D real_normal;
layout(set = 0, binding = 4, rgba32f) readonly uniform image2D virtual_position;
layout(set = 0, binding = 5, rgba16f) readonly uniform image2D virtual_normal;
layout(set = 0, binding = 6, rgba16f) writeonly uniform image2D env_occlusion;
layout(set = 0, binding = 7, r32ui) readonly uniform uimageBuffer color_words;  // the camera's colour words
#define MRGI_UPLOAD_COLOR_ONLY
#include "common/upload_gather.glsl"

// A march step meets a real surface where it lies behind the real G-buffer's depth by more than
// this (metres): the depth camera's noise is not a surface.
const float kNearFieldTolerance_m = 0.03f;

// The radiance the camera measured through internal pixel q (upload_gather.glsl's, at the
// nearest colour pixel; not clamped, unlike the real albedo estimate, so a surface brighter than
// 1 counts in full up to the camera's saturation).
vec3 camera_radiance_through(ivec2 q) {
  vec2 cp = project_pinhole(unproject_pinhole(vec2(q), 1.0f, frame.internal_k), frame.color_k);
  return camera_radiance(clamp(ivec2(floor(cp + 0.5f)), ivec2(0), frame.color_depth_size.xy - 1));
}

// The radiance of the first real surface the ray from p along w meets between `start` (the
// sphere's far side) and `reach` metres (a march step behind the real G-buffer's depth at its
// nearest internal pixel by more than the tolerance; the G-buffer's surfaces are taken as
// solid behind, as the camera cannot see past them), rgb; w 1 where it meets one, 0 where the
// ray leaves the view or meets nothing within the reach (the environment lies that way). A
// sphere whose far side is beyond the reach marches nowhere.
vec4 real_surface_beyond(vec3 p, vec3 w, float start, float reach, int steps) {
  if (!(start < reach)) return vec4(0.0f);
  const ivec2 used = frame.internal_output_size.xy;
  for (int k = 0; k < steps; ++k) {
    vec3 x = p + w * near_field_march_t(start, reach, k, steps);
    vec3 c = (frame.world_to_camera * vec4(x, 1.0f)).xyz;
    if (!(c.z > 1e-3f)) return vec4(0.0f);
    ivec2 q = ivec2(floor(project_pinhole(c, frame.internal_k) + 0.5f));
    if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, used))) return vec4(0.0f);
    float depth = imageLoad(real_position, q).w;
    if (depth > 0.0f && c.z > depth + kNearFieldTolerance_m) return vec4(camera_radiance_through(q), 1.0f);
  }
  return vec4(0.0f);
}

// What lit object k sends point p from its oriented patches (occlusion_math.h lit_patch_term).
vec3 object_lit_radiance(int k, vec3 p) {
  vec3 v = normalize(p - occluders.object_centre[k].xyz);
  const int base = k * MRGI_OBJECT_PATCHES;
  vec4 sum = vec4(0.0f);
  [[unroll]] for (int j = 0; j < MRGI_OBJECT_PATCHES; ++j)
    sum += lit_patch_term(occluders.object_patch[base + j], occluders.patch_radiance[base + j].rgb, v);
  return lit_object_radiance(sum);
}

// The far-field scale of object k's spheres seen from p (occlusion_math.h far_field_scale): its
// silhouette towards p from its oriented patches over its spheres' disc area.
float object_far_field_scale(int k, vec3 p) {
  vec3 d = occluders.object_centre[k].xyz - p;
  float l = length(d);
  vec4 far = occluders.object_far[k];
  if (!(far.x > 0.0f) || !(far.y > 0.0f) || !(l > 0.0f)) return 1.0f;
  vec3 w = d / l;
  const int base = k * MRGI_OBJECT_PATCHES;
  float silhouette = 0.0f;
  [[unroll]] for (int j = 0; j < MRGI_OBJECT_PATCHES; ++j) silhouette += silhouette_area_term(occluders.object_patch[base + j], w);
  return far_field_scale(silhouette, far.x, l / far.y);
}

// Spheres farther than this many radii are skipped: each would hide less than 1 / 64^2 of the
// sky (0.02 %). At 16 radii (0.4 % each) the many far terms of an object together were a
// visible part of the truth's broad darkening of a room (window_room_duck: the real-pixel change
// 0.68 of the truth's at 16, 0.82 at 64).
const float kReachRadii = 64.0f;

void main() {
  frame = frame_ubo;
  const int divisor = max(occluders.count.y, 1);
  const ivec2 internal_size = frame.internal_output_size.xy;
  const ivec2 texels = (internal_size + divisor - 1) / divisor;
  const ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(texel, texels))) return;
  const ivec2 pixel = min(texel * divisor + divisor / 2, internal_size - 1);
  vec4 vpos = imageLoad(virtual_position, pixel);
  bool is_virtual = vpos.w > 0.5f;
  vec4 pos = is_virtual ? vpos : imageLoad(real_position, pixel);
  if (!(pos.w > 0.0f)) {
    imageStore(env_occlusion, texel, vec4(0.0f));
    return;
  }
  vec3 n = normalize((is_virtual ? imageLoad(virtual_normal, pixel) : imageLoad(real_normal, pixel)).xyz);
  vec3 p = pos.xyz;
  SH16 sh_r, sh_g, sh_b;
  sh_r.c0 = occluders.radiance[0], sh_r.c1 = occluders.radiance[1], sh_r.c2 = occluders.radiance[2], sh_r.c3 = occluders.radiance[3];
  sh_g.c0 = occluders.radiance[4], sh_g.c1 = occluders.radiance[5], sh_g.c2 = occluders.radiance[6], sh_g.c3 = occluders.radiance[7];
  sh_b.c0 = occluders.radiance[8], sh_b.c1 = occluders.radiance[9], sh_b.c2 = occluders.radiance[10], sh_b.c3 = occluders.radiance[11];
  SphereOcclusion o = sphere_occlusion_none();
  const int count = min(occluders.count.x, MRGI_MAX_OCCLUDER_SPHERES);
  // The broad regions kept apart from the SH: the unblocked fraction of each one's cone.
  const int regions = clamp(occluders.count.z, 0, MRGI_MAX_OCCLUSION_REGIONS);
  // (Loops over the regions run to the constant bound, unrolled, so every index is a constant:
  // on lavapipe a dynamically indexed local or uniform array is gathered lane by lane.)
  vec4 region_open = vec4(1.0f);
  const bool lit = occluders.near_field.y > 0.5f;
  // Per object, once a texel (the spheres come object by object): its far-field scale and,
  // where lit, the light its surface sends the point.
  int seen_object = -1;
  float object_scale = 1.0f;
  vec3 lit_shown = vec3(0.0f);
  if (kOneObject) {
    object_scale = object_far_field_scale(0, p);
    lit_shown = lit ? object_lit_radiance(0, p) : vec3(0.0f);
  }
  for (int i = 0; i < count; ++i) {
    vec4 s = occluders.spheres[i];
    vec3 d = s.xyz - p;
    float l2 = dot(d, d), r2 = s.w * s.w;
    // Inside a proxy (a virtual surface in its own sphere, or a real point the object covers):
    // that sphere says nothing about what this point sees.
    if (l2 <= r2 * 1.0001f || l2 > r2 * (kReachRadii * kReachRadii)) continue;
    float inv_l = inversesqrt(l2);
    vec3 w = d * inv_l;
    float s2 = r2 / l2;
    const int object = int(occluders.albedo[i].w);
    if (!kOneObject && object >= 0 && object != seen_object) {
      seen_object = object;
      object_scale = object_far_field_scale(object, p);
      lit_shown = lit ? object_lit_radiance(object, p) : vec3(0.0f);
    }
    float f = sphere_form_factor(dot(n, w), s2) * (object >= 0 ? object_scale : 1.0f);
    if (f > 1e-5f) {
      // What the sphere hides (the sky's cap, or the real surface beyond it in the near field)
      // less what it shows instead: the object's own surface facing the point, lit by the same
      // ambient (albedo / pi x E(-w)).
      // (Marched from real points only, towards a centre above the point's horizon: a sphere
      // crossing it hides a sliver of sky near the horizon, not what lies beyond its centre
      // below it, such as the real surface under a thin plate's own proxies; and a virtual
      // point's own object, inscribed spheres standing in for its surface, would see real
      // surfaces through gaps the mesh does not have.)
      const int steps = is_virtual ? 0 : occluders.count.w;
      vec4 beyond = steps > 0 && f > 1e-3f && dot(n, w) > 0.0f ? real_surface_beyond(p, w, sqrt(l2) + s.w, occluders.near_field.x, steps) : vec4(0.0f);
      vec3 hidden = beyond.w > 0.5f ? beyond.rgb : sh_cap_mean_radiance(sh_r, sh_g, sh_b, w, sqrt(1.0f - s2));
      vec3 e_facing = sh_irradiance16(sh_r, sh_g, sh_b, -w);
      if (regions > 0) {
        // The part of each region's cone the sphere's cap covers (none where a real surface lies
        // beyond it: the region never reached the point); the object is lit by the regions too.
        float cap = asin(sqrt(s2)), vers_cap = 1.0f - sqrt(1.0f - s2);
        float open_beyond = beyond.w > 0.5f ? 0.0f : 1.0f;
        [[unroll]] for (int k = 0; k < MRGI_MAX_OCCLUSION_REGIONS; ++k) {
          if (k >= regions) break;
          vec4 region = occluders.regions[k];
          float cos_theta = dot(w, region.xyz);
          e_facing += occluders.region_irradiance[k].rgb * max(-cos_theta, 0.0f);
          float theta = acos(clamp(cos_theta, -1.0f, 1.0f));
          region_open[k] *= 1.0f - open_beyond * cap_covered_fraction_v(theta, cap, occluders.region_irradiance[k].w, vers_cap, region.w);
        }
      }
      vec3 shown = occluders.albedo[i].rgb * e_facing * (1.0f / MRGI_PI);
      if (lit && object >= 0 && !(is_virtual && distance(p, occluders.object_centre[object].xyz) < occluders.object_centre[object].w)) {
        // ... and by the shadowed lights, as much of its lit surface as faces the point (a
        // sunlit object sends its sunlight on to the wall beside it): once per object a texel.
        // Not on a virtual point within the object's bounding sphere, its own surface most
        // likely: its proxies (the sliver of an inscribed sphere above the point's horizon)
        // would light it with its own lit faces; other objects' light reaches it.
        shown += lit_shown;
      }
      o = sphere_occlusion_add(o, f, hidden - shown);
    }
  }
  float key = distance(p, frame.camera_world.xyz);
  vec3 hidden = sphere_occlusion_irradiance(o);
  if (occluders.near_field.w > 0.5f && !is_virtual) {
    // The objects' surroundings, darkened by them, light this real point less.
    const int objects = int(occluders.near_field.z);
    [[unroll]] for (int k = 0; k < MRGI_MAX_OCCLUSION_OBJECTS; ++k) {
      if (k >= objects) break;
      hidden += real_bounce_loss(occluders.object_loss[k].rgb, occluders.object_base[k].xyz, occluders.object_loss[k].w, p, n);
    }
  }
  if (regions > 0) {
    [[unroll]] for (int k = 0; k < MRGI_MAX_OCCLUSION_REGIONS; ++k) {
      if (k >= regions) break;
      hidden += occluders.region_irradiance[k].rgb * max(dot(n, occluders.regions[k].xyz), 0.0f) * (1.0f - region_open[k]);
    }
  }
  hidden = any(isnan(hidden)) || any(isinf(hidden)) ? vec3(0.0f) : clamp(hidden, vec3(-60000.0f), vec3(60000.0f));
  imageStore(env_occlusion, texel, vec4(hidden, is_virtual ? -key : key));
}

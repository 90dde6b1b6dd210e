// A room corner (floor, two walls, a box) ray-traced under a coloured sun, a blue sky and an
// optional point lamp, seen by an RGB-D camera: the light stage's probeless tests' scene.
#pragma once
#include <cmath>

#include <glm/glm.hpp>

#include "common/look_at.h"
#include "image/srgb.h"
#include "light/sh_tools.h"
#include "mrgi/frame.h"

namespace mrgi::test_room {
using namespace mrgi;
using namespace mrgi::light;

struct Hit {
  double t = 1e30;
  glm::dvec3 n{0.0};
  glm::dvec3 albedo{0.0};
};

// Axis-aligned rectangles and a box: enough for a corner with shadows.
struct Room {
  glm::dvec3 sun = glm::normalize(glm::dvec3(0.5, 0.8, 0.35));  // towards the sun
  glm::dvec3 sun_e{2.4, 2.0, 1.5};                               // warm, W/m^2
  glm::dvec3 sky{0.06, 0.09, 0.16};                              // blue radiance, upper hemisphere
  glm::dvec3 box_lo{0.1, 0.0, 0.6}, box_hi{0.45, 0.35, 0.95};
  glm::dvec3 left_wall_albedo{0.55, 0.55, 0.55};
  glm::dvec3 back_wall_albedo{0.6, 0.6, 0.6}, box_albedo{0.45, 0.45, 0.45};
  // A point lamp (W/sr per channel; 0 = none), shadowed by the room like the sun.
  glm::dvec3 lamp_position{0.9, 1.2, 0.4};
  glm::dvec3 lamp_intensity{0.0};

  static void plane(const glm::dvec3& o, const glm::dvec3& d, int axis, double at, const glm::dvec3& lo,
                    const glm::dvec3& hi, const glm::dvec3& n, const glm::dvec3& albedo, Hit& h) {
    if (std::abs(d[axis]) < 1e-12) return;
    const double t = (at - o[axis]) / d[axis];
    if (t <= 1e-6 || t >= h.t) return;
    const glm::dvec3 p = o + t * d;
    for (int a = 0; a < 3; ++a)
      if (a != axis && (p[a] < lo[a] || p[a] > hi[a])) return;
    h.t = t;
    h.n = n;
    h.albedo = albedo;
  }
  Hit trace(const glm::dvec3& o, const glm::dvec3& d) const {
    Hit h;
    plane(o, d, 1, 0.0, {-1, 0, -3}, {3, 0, 2}, {0, 1, 0}, {0.5, 0.5, 0.5}, h);       // floor
    plane(o, d, 2, 2.0, {-1, 0, 2}, {3, 1.5, 2}, {0, 0, -1}, back_wall_albedo, h);  // back wall
    plane(o, d, 0, -1.0, {-1, 0, -3}, {-1, 1.5, 2}, {1, 0, 0}, left_wall_albedo, h);  // left wall
    plane(o, d, 1, box_hi.y, {box_lo.x, 0, box_lo.z}, {box_hi.x, 0, box_hi.z}, {0, 1, 0}, box_albedo, h);
    plane(o, d, 0, box_lo.x, {0, box_lo.y, box_lo.z}, {0, box_hi.y, box_hi.z}, {-1, 0, 0}, box_albedo, h);
    plane(o, d, 0, box_hi.x, {0, box_lo.y, box_lo.z}, {0, box_hi.y, box_hi.z}, {1, 0, 0}, box_albedo, h);
    plane(o, d, 2, box_lo.z, {box_lo.x, box_lo.y, 0}, {box_hi.x, box_hi.y, 0}, {0, 0, -1}, box_albedo, h);
    plane(o, d, 2, box_hi.z, {box_lo.x, box_lo.y, 0}, {box_hi.x, box_hi.y, 0}, {0, 0, 1}, box_albedo, h);
    return h;
  }
  // Lambertian radiance at p: the sun and the sky, both shadowed by the room (the sky by
  // quadrature over a Fibonacci sphere), as the estimator's transfer models them.
  glm::dvec3 radiance(const glm::dvec3& p, const Hit& h) const {
    const double c = glm::dot(h.n, sun);
    const glm::dvec3 o = p + h.n * 1e-4;
    const bool lit = c > 0.0 && trace(o, sun).t > 1e20;
    constexpr int kSky = 96;
    double sky_cos = 0.0;
    for (int k = 0; k < kSky; ++k) {
      const glm::dvec3 w = fibonacci_direction(k, kSky);
      const double cw = glm::dot(h.n, w);
      if (w.y > 0.0 && cw > 0.0 && trace(o, w).t > 1e20) sky_cos += cw;
    }
    glm::dvec3 e = (lit ? sun_e * c : glm::dvec3(0.0)) + sky * (sky_cos * 4.0 * kPi / kSky);
    if (lamp_intensity != glm::dvec3(0.0)) {
      const glm::dvec3 to = lamp_position - p;
      const double d = glm::length(to), cl = glm::dot(h.n, to / d);
      if (cl > 0.0 && trace(o, to / d).t > d) e += lamp_intensity * (cl / (d * d));
    }
    return h.albedo / kPi * e;
  }
};

struct RenderedFrame {
  InputFrame frame;
  glm::dmat4 pose;
  Intrinsics k;
};

// `sky_background`: rays that leave the room upwards show the sky's radiance (no depth, as beyond
// a depth sensor's range); otherwise every miss is black.
inline RenderedFrame render(const Room& room, const glm::dvec3& eye, const glm::dvec3& target, int w, int h,
                            bool sky_background = false) {
  RenderedFrame r;
  r.k = Intrinsics{w, h, 0.82 * w, 0.82 * w, 0.5 * (w - 1), 0.5 * (h - 1)};
  r.pose = test::opencv_look_at(eye, target, {0, 1, 0});
  r.frame.color = ImageRGB8(w, h);
  r.frame.depth = ImageU16(w, h);
  const glm::dmat3 rot(r.pose);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const glm::dvec3 dc((u - r.k.cx) / r.k.fx, (v - r.k.cy) / r.k.fy, 1.0);
      const glm::dvec3 d = glm::normalize(rot * dc);
      const Hit hit = room.trace(eye, d);
      if (hit.t > 1e20) {
        if (sky_background && d.y > 0.0)
          for (int c = 0; c < 3; ++c) r.frame.color.at(u, v)[c] = linear_to_srgb8(float(room.sky[c]));
        continue;
      }
      const glm::dvec3 p = eye + hit.t * d;
      const double z = glm::dot(p - eye, glm::dvec3(r.pose[2]));
      r.frame.depth.at(u, v)[0] = uint16_t(std::lround(z * 5000.0));
      const glm::dvec3 l = room.radiance(p, hit);
      for (int c = 0; c < 3; ++c) r.frame.color.at(u, v)[c] = linear_to_srgb8(float(l[c]));
    }
  return r;
}

}  // namespace mrgi::test_room

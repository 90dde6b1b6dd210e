#!/usr/bin/env python3
"""Writes the light-estimation family's scene descriptions (perf/suite/light/<name>.json) and its
manifest (perf/suite/light/family.json): small captures (320x240, 2 frames) that
differ in everything a light estimator assumes, rendered by `mrgi synth` (render_family.sh).

Every scene is built so its main light reaches the virtual object (no wall between them): the
truth of an estimate is the light at the object. HDR intensities are scaled so the camera at
exposure 1 does not clip (interior.exr: irradiance 7 W/m^2 upwards, scaled by 0.3).

The split into a tuning half and a held-out half is fixed here, before any tuning: one of each
pair of related scenes is held out, so every kind of light (sun and sky, indoor HDR, one lamp,
two lamps) and of view is in both halves. Nothing in the held-out half may be used to choose a
parameter; perf/results/light-family/light-family.md reports both halves.

Run from the repository root: python3 perf/suite/light/make_family.py
"""
import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED_ENV = "../../../../shared/data/env"
BOX = "../assets/white_box.gltf"


def quat_axis(axis, deg):
    s = math.sin(math.radians(deg) / 2)
    return [axis[0] * s, axis[1] * s, axis[2] * s, math.cos(math.radians(deg) / 2)]


def floor(colour, size=6):
    return {"shape": "plane", "size": [size, size], "material": {"color": colour}}


def back_wall(z, colour, width=4, height=2.0):
    # A plane's normal is +y; rotated -90 degrees about x it faces -z.
    return {"shape": "plane", "size": [width, height], "position": [0, height / 2, z],
            "rotation": quat_axis([1, 0, 0], -90), "material": {"color": colour}}


def left_wall(x, colour, depth=4, height=2.0):
    # Rotated -90 degrees about z the normal faces +x.
    return {"shape": "plane", "size": [height, depth], "position": [x, height / 2, 0.5],
            "rotation": quat_axis([0, 0, 1], -90), "material": {"color": colour}}


def table(height, colour):
    return {"shape": "box", "size": [1.2, 0.04, 0.8], "position": [0, height - 0.02, 0.35],
            "material": {"color": colour}}


def box(pos, size, colour):
    return {"shape": "box", "size": size, "position": [pos[0], pos[1] + size[1] / 2, pos[2]],
            "material": {"color": colour}}


def sky(sun_elev_deg, sun_azim_deg, sun_e, zenith, horizon):
    e, a = math.radians(sun_elev_deg), math.radians(sun_azim_deg)
    d = [math.cos(e) * math.sin(a), math.sin(e), -math.cos(e) * math.cos(a)]
    return {"sky": {"sun_direction": [round(v, 5) for v in d], "sun_irradiance": sun_e, "sun_radius_deg": 1.5,
                    "zenith": zenith, "horizon": horizon, "ground": [0.03, 0.03, 0.03], "width": 256},
            "intensity": 1.0, "capture_width": 64}


def hdr(name, rot_deg, intensity=1.0):
    return {"image": f"{SHARED_ENV}/{name}", "intensity": intensity, "rotation": quat_axis([0, 1, 0], rot_deg),
            "capture_width": 64}


DOWN = [{"time": 0.0, "position": [0.1, 1.25, -0.75], "look_at": [0.0, 0.05, 0.35]},
        {"time": 0.0333, "position": [0.13, 1.25, -0.74], "look_at": [0.0, 0.05, 0.35]}]
LEVEL = [{"time": 0.0, "position": [0.15, 0.55, -1.4], "look_at": [0.0, 0.45, 0.6]},
         {"time": 0.0333, "position": [0.18, 0.55, -1.4], "look_at": [0.0, 0.45, 0.6]}]


def close_on(h):  # small visible area: a close look down at a table top
    return [{"time": 0.0, "position": [0.05, h + 0.55, -0.15], "look_at": [0.0, h, 0.35]},
            {"time": 0.0333, "position": [0.07, h + 0.55, -0.15], "look_at": [0.0, h, 0.35]}]


def far():  # large visible area
    return [{"time": 0.0, "position": [0.6, 1.5, -2.2], "look_at": [-0.1, 0.3, 0.5]},
            {"time": 0.0333, "position": [0.63, 1.5, -2.2], "look_at": [-0.1, 0.3, 0.5]}]


def virtual(pos, scale=1.0):
    return [{"gltf": BOX, "position": pos, "rotation": quat_axis([0, 1, 0], 20), "scale": scale}]


WHITE, GREY, RED, GREEN, BLUE, BEIGE, WOOD = ([0.75, 0.75, 0.75], [0.5, 0.5, 0.5], [0.7, 0.12, 0.1],
                                             [0.12, 0.55, 0.15], [0.15, 0.25, 0.65], [0.7, 0.62, 0.48],
                                             [0.55, 0.38, 0.22])
SKY_A = dict(sun_e=[3.0, 2.85, 2.5], zenith=[0.05, 0.09, 0.22], horizon=[0.13, 0.15, 0.2])
SKY_B = dict(sun_e=[2.6, 1.9, 1.2], zenith=[0.04, 0.07, 0.17], horizon=[0.16, 0.14, 0.13])

# name: (what it varies, held_out, description body)
SCENES = {
    "sky_high_down": ("sun 55 deg up, blue sky; grey floor and a box; camera looking down", False, dict(
        real=[floor(GREY), box([0.35, 0, 0.5], [0.2, 0.2, 0.2], WHITE)],
        environment=sky(55, 30, **SKY_A), camera=DOWN, virtual=virtual([-0.1, 0, 0.3]))),
    "sky_high_level": ("the same sky turned 90 deg; white floor, a white wall, a table; camera level", True, dict(
        real=[floor(WHITE), back_wall(1.2, WHITE), table(0.5, WOOD)],
        environment=sky(55, -60, **SKY_A), camera=LEVEL, virtual=virtual([0.1, 0.5, 0.3], 0.8))),
    "sky_low_red_wall": ("low warm sun 25 deg up; red wall beside a grey floor; camera looking down", False, dict(
        real=[floor(GREY), left_wall(-0.7, RED), box([0.3, 0, 0.6], [0.25, 0.15, 0.2], BEIGE)],
        environment=sky(25, 60, **SKY_B), camera=DOWN, virtual=virtual([0.0, 0, 0.3]))),
    "sky_low_table_close": ("low warm sun turned 240 deg; a table at 0.75 m seen close (small area)", True, dict(
        real=[floor(BEIGE), table(0.75, WOOD), box([0.25, 0.75, 0.45], [0.12, 0.12, 0.12], BLUE)],
        environment=sky(30, 180, **SKY_B), camera=close_on(0.75), virtual=virtual([-0.05, 0.75, 0.35], 0.6))),
    "courtyard_down": ("courtyard HDR; grey floor and boxes; camera looking down", False, dict(
        real=[floor(GREY), box([0.35, 0, 0.4], [0.2, 0.2, 0.2], WHITE), box([-0.4, 0, 0.7], [0.3, 0.1, 0.15], BEIGE)],
        environment=hdr("courtyard.exr", 0), camera=DOWN, virtual=virtual([0.0, 0, 0.3]))),
    "courtyard_level_green": ("courtyard HDR turned -90 deg; green wall, white floor; camera level", True, dict(
        real=[floor(WHITE), back_wall(1.0, GREEN), box([0.4, 0, 0.5], [0.2, 0.3, 0.2], GREY)],
        environment=hdr("courtyard.exr", -90), camera=LEVEL, virtual=virtual([0.0, 0, 0.3]))),
    "interior_corner_down": ("indoor HDR; white corner (floor, two walls); camera looking down", False, dict(
        real=[floor(WHITE), back_wall(1.1, WHITE), left_wall(-0.8, WHITE)],
        environment=hdr("interior.exr", 0, 0.3), camera=DOWN, virtual=virtual([0.0, 0, 0.4]))),
    "interior_blue_table_level": ("indoor HDR turned -90 deg; blue walls, a table; camera level", True, dict(
        real=[floor(BEIGE), back_wall(1.1, BLUE), left_wall(-0.9, BLUE), table(0.6, WOOD)],
        environment=hdr("interior.exr", -90, 0.3), camera=LEVEL, virtual=virtual([0.1, 0.6, 0.3], 0.8))),
    "lamp_point_corner": ("one warm point lamp above a white corner; camera looking down", False, dict(
        real=[floor(WHITE), back_wall(1.0, WHITE), left_wall(-0.8, WHITE)],
        lights=[{"type": "point", "position": [0.5, 1.4, 0.0], "color": [1.0, 0.85, 0.7], "intensity": 2.0}],
        camera=DOWN, virtual=virtual([0.0, 0, 0.35]))),
    "lamp_spot_table_level": ("one spot lamp over a table; beige floor; camera level", True, dict(
        real=[floor(BEIGE), table(0.7, WOOD), back_wall(1.3, WHITE)],
        lights=[{"type": "spot", "position": [-0.5, 1.6, 0.2], "direction": [0.35, -0.9, 0.1], "color": [1, 1, 1],
                 "intensity": 4.0, "inner_angle_deg": 35, "outer_angle_deg": 55}],
        camera=LEVEL, virtual=virtual([0.1, 0.7, 0.35], 0.8))),
    "lamps_two_colours": ("two point lamps, cool and warm, either side; grey floor, white wall; down", False, dict(
        real=[floor(GREY), back_wall(1.1, WHITE), box([0.3, 0, 0.6], [0.2, 0.2, 0.2], WHITE)],
        lights=[{"type": "point", "position": [-0.8, 1.2, -0.1], "color": [0.7, 0.85, 1.0], "intensity": 1.5},
                {"type": "point", "position": [0.9, 1.0, 0.4], "color": [1.0, 0.8, 0.6], "intensity": 1.0}],
        camera=DOWN, virtual=virtual([0.0, 0, 0.3]))),
    "lamps_two_far": ("a point and a spot lamp; floor, two walls, boxes seen from far (large area)", True, dict(
        real=[floor(WHITE), back_wall(1.2, BEIGE), left_wall(-1.0, GREEN), box([0.4, 0, 0.6], [0.25, 0.25, 0.25], GREY)],
        lights=[{"type": "point", "position": [0.6, 1.6, -0.4], "color": [1, 0.95, 0.9], "intensity": 2.5},
                {"type": "spot", "position": [-0.6, 1.8, 0.6], "direction": [0.3, -0.95, -0.1], "color": [1, 1, 1],
                 "intensity": 3.0, "inner_angle_deg": 30, "outer_angle_deg": 50}],
        camera=far(), virtual=virtual([0.0, 0, 0.35]))),
}


def description(body, seed):
    d = {"version": 1, "frames": 2, "fps": 30,
         "camera": {"width": 320, "height": 240, "fx": 262.5, "fy": 262.5, "exposure": 1.0},
         "camera_path": body["camera"],
         "render": {"spp": 128, "max_depth": 3, "rr_depth": 3, "seed": seed},
         "real_objects": body["real"],
         "virtual_objects": body["virtual"],
         "depth_sensor": {"depth_scale": 5000},
         "light_probe": {"width": 64, "spp": 256}}
    if "lights" in body:
        d["lights"] = body["lights"]
    if "environment" in body:
        d["environment"] = body["environment"]
    return d


def main():
    manifest = {"version": 1,
                "about": "Light-estimation family: 320x240 captures, 2 frames, rendered by mrgi synth "
                         "from the descriptions here (make_family.py writes them; render_family.sh renders). "
                         "held_out scenes are never used to choose a parameter.",
                "scenes": []}
    for i, (name, (what, held_out, body)) in enumerate(SCENES.items()):
        with open(os.path.join(HERE, name + ".json"), "w") as f:
            json.dump(description(body, 100 + i), f, indent=1)
            f.write("\n")
        manifest["scenes"].append({"name": name, "capture": f"perf/suite/light/{name}",
                                   "description": f"perf/suite/light/{name}.json", "varies": what,
                                   "held_out": held_out})
    with open(os.path.join(HERE, "family.json"), "w") as f:
        json.dump(manifest, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Writes the moving-camera light family's scene descriptions (perf/suite/light/moving/<name>.json)
and its manifest (perf/suite/light/moving/family.json): captures where the camera sweeps 90 degrees
around a virtual object standing on a table, as a user placing an object does, in several rooms
and light set-ups. Rendered by `mrgi synth` (render_moving_family.sh): 160x120 (the light stage's
estimate samples the depth image on a grid relative to its size, so a small capture carries what a
640x480 one does), 48 frames over the 90 degrees (1.9 degrees a frame).

Each set-up also has a light-switch pair (`<name>_off` / `<name>_on`, two frames each, the camera
still): the same room with one more lamp switched on. splice_switch.py joins them into a capture
whose lamp comes on at a stated frame, for the "followed within N frames" figure.

The split into a tuning half and a held-out half is fixed here, before any tuning: one of each pair
of related set-ups is held out, so every kind of light (sun and sky, outdoor HDR, indoor HDR, lamps)
and of room is in both halves. Nothing in the held-out half may be used to choose a parameter.

Run from the repository root: python3 perf/suite/light/make_moving_family.py
"""
import json
import math
import os

import make_family as fam

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "moving")
SHARED_ENV = "../../../../../shared/data/env"
BOX = "../../assets/white_box.gltf"
FRAMES = 48
SWEEP_DEG = 90.0
WIDTH, HEIGHT, FOCAL = 160, 120, 131.25


def hdr(name, rot_deg, intensity=1.0):
    return {"image": f"{SHARED_ENV}/{name}", "intensity": intensity, "rotation": fam.quat_axis([0, 1, 0], rot_deg),
            "capture_width": 64}


def sweep(centre, start_deg, radius=1.3, rise=0.55, frames=FRAMES):
    """The camera on a circle around `centre` (azimuth from -z towards +x), `rise` metres above it,
    from start_deg over SWEEP_DEG degrees, always looking at the centre."""
    keys = []
    for i in range(frames):
        a = math.radians(start_deg + SWEEP_DEG * i / max(1, frames - 1))
        pos = [centre[0] + radius * math.sin(a), centre[1] + rise, centre[2] - radius * math.cos(a)]
        keys.append({"time": round(i / 30.0, 6), "position": [round(v, 5) for v in pos], "look_at": centre})
    return keys


def still(centre, start_deg, radius=1.3, rise=0.55):
    a = math.radians(start_deg)
    pos = [centre[0] + radius * math.sin(a), centre[1] + rise, centre[2] - radius * math.cos(a)]
    pos2 = [pos[0] + 0.01, pos[1], pos[2]]
    return [{"time": 0.0, "position": [round(v, 5) for v in pos], "look_at": centre},
            {"time": 0.0333, "position": [round(v, 5) for v in pos2], "look_at": centre}]


def on_table(h):
    return [0.0, h, 0.35]


def virtual(pos, scale=0.6):
    return [{"gltf": BOX, "position": pos, "rotation": fam.quat_axis([0, 1, 0], 20), "scale": scale}]


W, G, RED, GREEN, BLUE, BEIGE, WOOD = fam.WHITE, fam.GREY, fam.RED, fam.GREEN, fam.BLUE, fam.BEIGE, fam.WOOD

# name: (what it varies, held_out, body, switch lamp)
SETUPS = {
    "sky_high_red_wall": ("sun 55 deg up and blue sky; grey floor, red wall, wooden table", False, dict(
        real=[fam.floor(G), fam.left_wall(-1.0, RED), fam.table(0.7, WOOD)],
        environment=fam.sky(55, 30, **fam.SKY_A), table=0.7, start=-30),
        {"type": "point", "position": [0.8, 1.5, -0.2], "color": [1.0, 0.85, 0.7], "intensity": 3.0}),
    "sky_low_blue_wall": ("low warm sun 28 deg up turned 200 deg; beige floor, blue wall, white table", True, dict(
        real=[fam.floor(BEIGE), fam.back_wall(1.3, BLUE), fam.table(0.75, W)],
        environment=fam.sky(28, 200, **fam.SKY_B), table=0.75, start=-30),
        {"type": "point", "position": [-0.7, 1.6, -0.3], "color": [0.8, 0.9, 1.0], "intensity": 3.0}),
    "courtyard_grey": ("courtyard HDR; grey floor, white table, a beige box", False, dict(
        real=[fam.floor(G), fam.table(0.7, W), fam.box([0.6, 0, 0.9], [0.3, 0.3, 0.3], BEIGE)],
        environment=hdr("courtyard.exr", 0), table=0.7, start=-45),
        {"type": "spot", "position": [0.5, 1.8, 0.0], "direction": [-0.3, -0.95, 0.2], "color": [1, 1, 1],
         "intensity": 4.0, "inner_angle_deg": 35, "outer_angle_deg": 55}),
    "courtyard_green_wall": ("courtyard HDR turned -120 deg; white floor, green wall, wooden table", True, dict(
        real=[fam.floor(W), fam.back_wall(1.2, GREEN), fam.table(0.65, WOOD)],
        environment=hdr("courtyard.exr", -120), table=0.65, start=-20),
        {"type": "point", "position": [0.9, 1.4, 0.1], "color": [1.0, 0.9, 0.75], "intensity": 3.0}),
    "interior_white_corner": ("indoor HDR; white corner, wooden table", False, dict(
        real=[fam.floor(W), fam.back_wall(1.2, W), fam.left_wall(-1.0, W), fam.table(0.7, WOOD)],
        environment=hdr("interior.exr", 0, 0.3), table=0.7, start=-30),
        {"type": "point", "position": [0.6, 1.6, -0.4], "color": [1.0, 0.8, 0.6], "intensity": 2.5}),
    "interior_blue_room": ("indoor HDR turned 90 deg; blue walls, beige floor, white table", True, dict(
        real=[fam.floor(BEIGE), fam.back_wall(1.2, BLUE), fam.left_wall(-1.0, BLUE), fam.table(0.7, W)],
        environment=hdr("interior.exr", 90, 0.3), table=0.7, start=-10),
        {"type": "spot", "position": [-0.4, 1.8, 0.1], "direction": [0.3, -0.95, 0.15], "color": [1, 1, 1],
         "intensity": 4.0, "inner_angle_deg": 30, "outer_angle_deg": 50}),
    "lamp_warm_corner": ("one warm point lamp; white corner, wooden table", False, dict(
        real=[fam.floor(W), fam.back_wall(1.1, W), fam.left_wall(-0.9, W), fam.table(0.7, WOOD)],
        lights=[{"type": "point", "position": [0.6, 1.5, 0.0], "color": [1.0, 0.85, 0.7], "intensity": 2.0}],
        table=0.7, start=-25),
        {"type": "point", "position": [-0.6, 1.5, -0.2], "color": [0.75, 0.85, 1.0], "intensity": 1.5}),
    "lamp_spot_beige": ("one spot lamp over the table; beige floor, white wall, grey table", True, dict(
        real=[fam.floor(BEIGE), fam.back_wall(1.3, W), fam.table(0.7, G)],
        lights=[{"type": "spot", "position": [-0.5, 1.7, 0.2], "direction": [0.35, -0.9, 0.1], "color": [1, 1, 1],
                 "intensity": 4.0, "inner_angle_deg": 35, "outer_angle_deg": 55}],
        table=0.7, start=-10),
        {"type": "point", "position": [0.8, 1.3, -0.3], "color": [1.0, 0.85, 0.7], "intensity": 2.0}),
}


def description(body, camera_path, frames, seed, extra_lights=()):
    d = {"version": 1, "frames": frames, "fps": 30,
         "camera": {"width": WIDTH, "height": HEIGHT, "fx": FOCAL, "fy": FOCAL, "exposure": 1.0},
         "camera_path": camera_path,
         "render": {"spp": 128, "max_depth": 3, "rr_depth": 3, "seed": seed},
         "real_objects": body["real"],
         "virtual_objects": virtual(on_table(body["table"])),
         "depth_sensor": {"depth_scale": 5000},
         "light_probe": {"width": 64, "spp": 256}}
    lights = list(body.get("lights", [])) + list(extra_lights)
    if lights:
        d["lights"] = lights
    if "environment" in body:
        d["environment"] = body["environment"]
    return d


def write(name, d):
    with open(os.path.join(HERE, name + ".json"), "w") as f:
        json.dump(d, f, indent=1)
        f.write("\n")


def main():
    os.makedirs(HERE, exist_ok=True)
    manifest = {"version": 1,
                "about": "Moving-camera light family: 160x120 captures, a 90-degree sweep in 48 frames around "
                         "a virtual object on a table, rendered by mrgi synth (make_moving_family.py writes the "
                         "descriptions, render_moving_family.sh renders, splice_switch.py joins the switch "
                         "pairs). held_out scenes are never used to choose a parameter.",
                "scenes": [], "switches": []}
    for i, (name, (what, held_out, body, switch_lamp)) in enumerate(SETUPS.items()):
        centre = on_table(body["table"])
        write(name, description(body, sweep(centre, body["start"]), FRAMES, 300 + i))
        write(name + "_off", description(body, still(centre, body["start"]), 2, 400 + i))
        write(name + "_on", description(body, still(centre, body["start"]), 2, 400 + i, [switch_lamp]))
        manifest["scenes"].append({"name": name, "capture": f"perf/suite/light/moving/{name}",
                                   "description": f"perf/suite/light/moving/{name}.json", "varies": what,
                                   "held_out": held_out})
        manifest["switches"].append({"name": name + "_switch", "off": f"perf/suite/light/moving/{name}_off",
                                     "on": f"perf/suite/light/moving/{name}_on",
                                     "capture": f"perf/suite/light/moving/{name}_switch", "held_out": held_out})
    with open(os.path.join(HERE, "family.json"), "w") as f:
        json.dump(manifest, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()

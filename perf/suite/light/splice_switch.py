#!/usr/bin/env python3
"""Joins each light-switch pair of the moving-camera light family into one capture whose lamp
comes on at a stated frame: frames 0..AT-1 are the `off` capture's, AT..FRAMES-1 the `on`
capture's, each half cycling through its own (still-camera) frames. The images are copied once;
the frame lists name them as often as they are shown. scene.json is the `on` capture's (the light
after the switch); the estimate is judged against it from frame AT on.

    python3 perf/suite/light/splice_switch.py perf/suite/light/moving/family.json [--at 48] [--frames 144]
"""
import argparse
import json
import os
import shutil
import sys


def read_list(path):
    rows = []
    with open(path) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                rows.append(line.split())
    return rows


def splice(off_dir, on_dir, out_dir, at, frames):
    for d in (off_dir, on_dir):
        if not os.path.isfile(os.path.join(d, "capture.json")):
            sys.exit(f"{d}: not a rendered capture (capture.json missing): run render_moving_family.sh first")
    tmp = out_dir + ".partial"
    shutil.rmtree(tmp, ignore_errors=True)
    os.makedirs(tmp)
    shutil.copy(os.path.join(on_dir, "capture.json"), tmp)
    shutil.copy(os.path.join(on_dir, "scene.json"), tmp)
    for sub in ("virtual", "environment", "light_probe"):
        if os.path.isdir(os.path.join(on_dir, sub)):
            shutil.copytree(os.path.join(on_dir, sub), os.path.join(tmp, sub))
    lists = {}
    for half, src in (("off", off_dir), ("on", on_dir)):
        lists[half] = {k: read_list(os.path.join(src, k + ".txt")) for k in ("rgb", "depth", "reference", "groundtruth")}
        for sub in ("rgb", "depth", "reference"):
            os.makedirs(os.path.join(tmp, half, sub), exist_ok=True)
            for name in os.listdir(os.path.join(src, sub)):
                shutil.copy(os.path.join(src, sub, name), os.path.join(tmp, half, sub, name))
    headers = {"rgb": "# colour images (mrgi capture format v1)\n# timestamp filename\n",
               "depth": "# depth images (mrgi capture format v1)\n# timestamp filename\n",
               "reference": "# ground-truth augmented frames (mrgi capture format v1)\n# timestamp filename [mask_filename]\n",
               "groundtruth": "# ground-truth camera-to-world poses (mrgi capture format v1)\n# timestamp tx ty tz qx qy qz qw\n"}
    for key, header in headers.items():
        with open(os.path.join(tmp, key + ".txt"), "w") as f:
            f.write(header)
            for i in range(frames):
                half = "off" if i < at else "on"
                rows = lists[half][key]
                row = rows[i % len(rows)]
                t = f"{i / 30.0:.6f}"
                if key == "groundtruth":
                    f.write(" ".join([t] + row[1:]) + "\n")
                else:
                    f.write(" ".join([t] + [f"{half}/{p}" for p in row[1:]]) + "\n")
    with open(os.path.join(tmp, "switch.json"), "w") as f:
        json.dump({"at": at, "frames": frames, "off": off_dir, "on": on_dir}, f, indent=1)
        f.write("\n")
    shutil.rmtree(out_dir, ignore_errors=True)
    os.rename(tmp, out_dir)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("manifest")
    ap.add_argument("--at", type=int, default=48, help="first frame with the lamp on (default 48)")
    ap.add_argument("--frames", type=int, default=144, help="frames in all (default 144)")
    a = ap.parse_args()
    if not 0 < a.at < a.frames:
        sys.exit(f"--at {a.at}: must be within 1..{a.frames - 1}")
    with open(a.manifest) as f:
        m = json.load(f)
    for w in m.get("switches", []):
        splice(w["off"], w["on"], w["capture"], a.at, a.frames)
        print(f"{w['capture']}: lamp on from frame {a.at} of {a.frames}")


if __name__ == "__main__":
    main()

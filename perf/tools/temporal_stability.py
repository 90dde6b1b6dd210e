#!/usr/bin/env python3
"""Temporal stability of a replay: the frame-to-frame change of the delta (output - camera) on
real surfaces that did not move (static regions).

For each frame t > 0, every real pixel with a measured depth is lifted to the world with frame
t's depth and pose and projected into frame t-1 (capture.json intrinsics, groundtruth.txt
poses, camera-to-world, TUM order); where it lands on a pixel whose own depth agrees within 2 %
(the same surface, not occluded) and that is real in both frames (the replay's virtual mask, or
the reference's), the delta of frame t is compared with frame t-1's there. Reported per frame
pair and as the mean: the mean absolute change of the delta in linear RGB (x 1000), over those
pixels, and the same for the path-traced reference's own deltas (what a perfect method's
frame-to-frame change is: the virtual object's effect on a moving view changes, the reference's
noise too). Plain numpy and PIL (Debian: python3-numpy, python3-pil).

    python3 perf/tools/temporal_stability.py CAPTURE REPLAY_OUT [REPLAY_OUT ...]
"""
import json
import sys
from pathlib import Path

import numpy as np
from PIL import Image


def linear(img8):
    a = img8.astype(np.float64) / 255.0
    return np.where(a <= 0.04045, a / 12.92, ((a + 0.055) / 1.055) ** 2.4)


def read_list(path):
    rows = []
    for line in Path(path).read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            rows.append(line.split())
    return rows


def pose_matrix(row):
    tx, ty, tz, qx, qy, qz, qw = (float(v) for v in row[1:8])
    n = np.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
    qx, qy, qz, qw = qx / n, qy / n, qz / n, qw / n
    r = np.array([[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
                  [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
                  [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)]])
    m = np.eye(4)
    m[:3, :3] = r
    m[:3, 3] = (tx, ty, tz)
    return m


def main(argv):
    if len(argv) < 3:
        print(__doc__.strip().splitlines()[-1], file=sys.stderr)
        return 2
    cap = Path(argv[1])
    info = json.loads((cap / "capture.json").read_text())
    k = info["depth"]
    if info["color"] != info["depth"]:
        print(f"{cap}/capture.json: colour and depth intrinsics differ; this tool needs them registered", file=sys.stderr)
        return 1
    scale = float(info.get("depth_scale", 5000.0))
    rgb = read_list(cap / "rgb.txt")
    depth = read_list(cap / "depth.txt")
    poses = read_list(cap / "groundtruth.txt")
    refs = read_list(cap / "reference.txt")
    n = min(len(rgb), len(depth), len(poses), len(refs))
    h, w = k["height"], k["width"]
    v, u = np.mgrid[0:h, 0:w].astype(np.float64)

    def load(t):
        cam8 = np.asarray(Image.open(cap / rgb[t][1]).convert("RGB")).astype(np.int32)
        z = np.asarray(Image.open(cap / depth[t][1])).astype(np.float64) / scale
        delta8 = np.asarray(Image.open(cap / refs[t][1]).convert("RGB")).astype(np.int32)
        ref8 = (cam8 + delta8) % 256
        ref_mask = np.asarray(Image.open(cap / refs[t][2]).convert("L")) > 127 if len(refs[t]) > 2 else np.zeros((h, w), bool)
        return linear(cam8), z, linear(ref8), ref_mask, pose_matrix(poses[t])

    frames = [load(t) for t in range(n)]
    runs = []
    for out in argv[2:]:
        o = Path(out)
        imgs = sorted((o / "frames").glob("*.png"))
        runs.append((o.name, [linear(np.asarray(Image.open(p).convert("RGB")).astype(np.int32)) for p in imgs[:n]]))
    pairs = []
    for t in range(1, n):
        cam, z, ref, ref_mask, pose = frames[t]
        cam0, z0, ref0, ref_mask0, pose0 = frames[t - 1]
        valid = z > 0
        x = (u - k["cx"]) / k["fx"] * z
        y = (v - k["cy"]) / k["fy"] * z
        p = np.stack([x, y, z, np.ones_like(z)], axis=-1)
        world = p @ pose.T
        prev = world @ np.linalg.inv(pose0).T
        zp = prev[..., 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            up = np.rint(prev[..., 0] / zp * k["fx"] + k["cx"]).astype(np.int64)
            vp = np.rint(prev[..., 1] / zp * k["fy"] + k["cy"]).astype(np.int64)
        inside = valid & (zp > 0) & (up >= 0) & (up < w) & (vp >= 0) & (vp < h)
        upc, vpc = np.clip(up, 0, w - 1), np.clip(vp, 0, h - 1)
        same = inside & (np.abs(z0[vpc, upc] - zp) <= 0.02 * zp) & ~ref_mask & ~ref_mask0[vpc, upc]
        row = {"pair": f"{t - 1}->{t}", "pixels": int(same.sum())}
        d_ref = (ref - cam)[same] - (ref0 - cam0)[vpc[same], upc[same]]
        row["reference"] = 1000.0 * float(np.abs(d_ref).mean())
        for name, imgs in runs:
            d = (imgs[t] - cam)[same] - (imgs[t - 1] - cam0)[vpc[same], upc[same]]
            row[name] = 1000.0 * float(np.abs(d).mean())
        pairs.append(row)
    names = ["reference"] + [name for name, _ in runs]
    print("| frames | static real pixels | " + " | ".join(names) + " |")
    print("|---|---:|" + "---:|" * len(names))
    for r in pairs:
        print(f"| {r['pair']} | {r['pixels']} | " + " | ".join(f"{r[nm]:.3f}" for nm in names) + " |")
    print("| **mean** | | " + " | ".join(f"**{np.mean([r[nm] for r in pairs]):.3f}**" for nm in names) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

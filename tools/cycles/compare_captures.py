# Compares two captures of the same scene description (capture format v1, docs/DESIGN.md): one from
# mrgi's own path tracer (`mrgi synth`), one converted from Blender Cycles renders (`mrgi synth
# --from-renders`), to show where the two renderers agree and by how much. Both went through the
# same camera model (exposure, sRGB, 8 bits), so the figures are in decoded linear camera values.
#
#   blender -b --factory-startup -noaudio -P tools/cycles/compare_captures.py -- MRGI_CAPTURE CYCLES_CAPTURE \
#       [--frames N] [--json OUT.json]
#
# (Blender's Python is used because it reads the PNGs and has numpy; nothing is rendered.)
# Per frame and over all frames it reports:
#   mean_c        mean linear value per channel of the camera frame C, each capture, and the ratio
#                 Cycles / mrgi (the overall light level: lamp units, materials, bounces)
#   mask_iou      intersection over union of the two virtual masks (placement, camera, intrinsics)
#   shadow        pixels outside both masks where G darkens C by more than 10 % of C's luminance
#                 and at least 0.005, both box-filtered over 9 x 9 pixels (the virtual object's
#                 shadow, without the speckle of a noisy render): IoU of the two sets, the
#                 distance between their centroids in pixels, and the mean of (G - C) luminance
#                 over each set
#   depth         of the pixels either depth frame measures: the share both measure, and the
#                 median and 99th percentile of |difference| in mm (both use mrgi's Kinect model
#                 with the same seed, so equal ideal depth and incidence give equal frames)
#   env_mean_ratio  when both captures have env frames: mean linear radiance per channel of the
#                 env frame inside the fisheye circle, Cycles / mrgi
#   delta_rde     ||D_cycles - D_mrgi|| / ||D_mrgi||, D = G - C linear, over all / real (mask 0 in
#                 both) / virtual pixels: the RDE an output that matched Cycles exactly would score
#                 against the mrgi reference; it includes both references' Monte Carlo noise
# and checks the stated tolerances (CHECKS below), exiting 1 if one fails.
import json
import os
import sys

import bpy
import numpy as np

CHECKS = {
    "mean_c_ratio": (0.9, 1.1),   # per channel, all frames
    "mask_iou_min": 0.95,
    "shadow_iou_min": 0.6,
    "shadow_centroid_px_max": 10.0,
    "depth_both_measured_min": 0.98,
    "depth_median_mm_max": 1.0,
}


def srgb_to_linear(v):
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def load_png_bytes(path, scale=255.0):
    if not os.path.exists(path):
        raise SystemExit("compare_captures: %s: missing" % path)
    im = bpy.data.images.load(path)
    im.colorspace_settings.name = "Non-Color"  # raw stored values, no conversion
    w, h = im.size
    a = np.array(im.pixels[:], dtype=np.float64).reshape(h, w, 4)[::-1]
    bpy.data.images.remove(im)
    return np.rint(a * scale).astype(np.int64)


def load_depth_m(capture, rel):
    with open(os.path.join(capture, "capture.json")) as f:
        scale = float(json.load(f).get("depth_scale", 5000.0))
    return load_png_bytes(os.path.join(capture, rel), 65535.0)[..., 0] / scale


def read_list(capture, name):
    out = []
    with open(os.path.join(capture, name)) as f:
        for line in f:
            line = line.strip()
            if line and not line.startswith("#"):
                out.append(line.split()[1])
    return out


def load_frame(capture, rgb_rel, ref_rel, exposure):
    c8 = load_png_bytes(os.path.join(capture, rgb_rel))[..., :3]
    r8 = load_png_bytes(os.path.join(capture, ref_rel))[..., :3]
    g8 = (c8 + r8) % 256 if ref_rel.endswith(".delta.png") else r8
    stem = ref_rel[:-len(".delta.png")] if ref_rel.endswith(".delta.png") else ref_rel[:-len(".png")]
    mask = load_png_bytes(os.path.join(capture, stem + "_mask.png"))[..., 0] > 127
    c = srgb_to_linear(c8 / 255.0) / exposure
    g = srgb_to_linear(g8 / 255.0) / exposure
    return c, g, mask


def load_exr(path):
    im = bpy.data.images.load(path)
    w, h = im.size
    a = np.array(im.pixels[:], dtype=np.float64).reshape(h, w, 4)[::-1, :, :3]
    bpy.data.images.remove(im)
    return a


def luminance(x):
    return 0.2126 * x[..., 0] + 0.7152 * x[..., 1] + 0.0722 * x[..., 2]


def box_blur(x, r):
    # Mean over a (2r+1)^2 window (edges clamped), by summed-area table.
    p = np.pad(x, r, mode="edge")
    s = np.pad(p.cumsum(0).cumsum(1), ((1, 0), (1, 0)))
    k = 2 * r + 1
    return (s[k:, k:] - s[:-k, k:] - s[k:, :-k] + s[:-k, :-k]) / (k * k)


def shadow_set(c, g, real):
    # Luminances box-filtered over 9 x 9 pixels first: at low sample counts the indirect light the
    # virtual object takes away is speckle noise over the whole room, which would otherwise pass
    # the threshold pixel by pixel and drag the centroid.
    lc, d = box_blur(luminance(c), 4), box_blur(luminance(g - c), 4)
    return real & (d < -0.1 * lc) & (d < -0.005)


def centroid(m):
    ys, xs = np.nonzero(m)
    return (float(xs.mean()), float(ys.mean())) if len(xs) else (float("nan"), float("nan"))


def rde(da, db, sel):
    num = float(((db - da)[sel] ** 2).sum())
    den = float((da[sel] ** 2).sum())
    return (num / den) ** 0.5 if den > 0 else float("nan")


def main():
    argv = sys.argv[sys.argv.index("--") + 1:]
    pos, frames, out_json = [], None, None
    i = 0
    while i < len(argv):
        if argv[i] == "--frames":
            frames = int(argv[i + 1]); i += 2
        elif argv[i] == "--json":
            out_json = argv[i + 1]; i += 2
        else:
            pos.append(argv[i]); i += 1
    if len(pos) != 2:
        raise SystemExit("usage: ... -- MRGI_CAPTURE CYCLES_CAPTURE [--frames N] [--json OUT.json]")
    caps = pos
    exposure = []
    for cap in caps:
        with open(os.path.join(cap, "capture.json")) as f:
            exposure.append(float(json.load(f).get("exposure", 1.0)))
    lists = [(read_list(cap, "rgb.txt"), read_list(cap, "reference.txt"), read_list(cap, "depth.txt")) for cap in caps]
    envs = [read_list(cap, "env.txt") if os.path.exists(os.path.join(cap, "env.txt")) else None for cap in caps]
    n = min(len(lists[0][0]), len(lists[1][0]))
    if frames:
        n = min(n, frames)
    report = {"mrgi": os.path.abspath(caps[0]), "cycles": os.path.abspath(caps[1]), "frames": []}
    sums = {"c": [np.zeros(3), np.zeros(3)], "num": np.zeros(3), "den": np.zeros(3)}
    failures = []
    for f in range(n):
        (cm, gm, mm), (cc, gc, mc) = [load_frame(caps[k], lists[k][0][f], lists[k][1][f], exposure[k]) for k in (0, 1)]
        dm, dc = gm - cm, gc - cc
        zm, zc = [load_depth_m(caps[k], lists[k][2][f]) for k in (0, 1)]
        either, both = (zm > 0) | (zc > 0), (zm > 0) & (zc > 0)
        dz = np.abs(zm - zc)[both] * 1000.0
        both_real = ~mm & ~mc
        virt = mm | mc
        sm, sc = shadow_set(cm, gm, both_real), shadow_set(cc, gc, both_real)
        inter, union = int((sm & sc).sum()), int((sm | sc).sum())
        cen_m, cen_c = centroid(sm), centroid(sc)
        mean_m, mean_c = cm.reshape(-1, 3).mean(0), cc.reshape(-1, 3).mean(0)
        sums["c"][0] += mean_m
        sums["c"][1] += mean_c
        all_px = np.ones_like(mm)
        for k, sel in enumerate((all_px, both_real, virt)):
            sums["num"][k] += float(((dc - dm)[sel] ** 2).sum())
            sums["den"][k] += float((dm[sel] ** 2).sum())
        fr = {
            "frame": f,
            "mean_c_mrgi": [round(float(v), 5) for v in mean_m],
            "mean_c_cycles": [round(float(v), 5) for v in mean_c],
            "mean_c_ratio": [round(float(a / b), 4) for a, b in zip(mean_c, mean_m)],
            "mask_iou": round(float((mm & mc).sum()) / max(1, int((mm | mc).sum())), 4),
            "shadow_iou": round(inter / union, 4) if union else None,
            "shadow_pixels": [int(sm.sum()), int(sc.sum())],
            "shadow_centroid_px": round(float(np.hypot(cen_m[0] - cen_c[0], cen_m[1] - cen_c[1])), 2),
            "shadow_mean_delta_luminance": [round(float(luminance(dm)[sm].mean()), 5) if sm.any() else None,
                                            round(float(luminance(dc)[sc].mean()), 5) if sc.any() else None],
            "delta_rde_all_real_virtual": [round(rde(dm, dc, s), 4) for s in (all_px, both_real, virt)],
            "depth_both_measured": round(float(both.sum()) / max(1, int(either.sum())), 4),
            "depth_abs_diff_mm_median_p99": [round(float(np.median(dz)), 2), round(float(np.percentile(dz, 99)), 2)]
            if dz.size else None,
        }
        if envs[0] and envs[1]:
            em, ec = [load_exr(os.path.join(caps[k], envs[k][f])) for k in (0, 1)]
            h, w = em.shape[:2]
            yy, xx = np.mgrid[0:h, 0:w]
            inside = np.hypot(xx - 0.5 * (w - 1), yy - 0.5 * (h - 1)) < 0.5 * min(w, h) - 1
            fr["env_mean_ratio"] = [round(float(a / b), 4) for a, b in zip(ec[inside].mean(0), em[inside].mean(0))]
        report["frames"].append(fr)
        print(json.dumps(fr))
    ratio = sums["c"][1] / sums["c"][0]
    report["mean_c_ratio"] = [round(float(v), 4) for v in ratio]
    report["delta_rde_all_real_virtual"] = [round(float((sums["num"][k] / sums["den"][k]) ** 0.5), 4) for k in range(3)]
    lo, hi = CHECKS["mean_c_ratio"]
    if not all(lo <= v <= hi for v in ratio):
        failures.append("mean C ratio %s outside [%g, %g]" % (report["mean_c_ratio"], lo, hi))
    for fr in report["frames"]:
        if fr["mask_iou"] < CHECKS["mask_iou_min"]:
            failures.append("frame %d: mask IoU %.3f < %g" % (fr["frame"], fr["mask_iou"], CHECKS["mask_iou_min"]))
        if fr["shadow_iou"] is not None and fr["shadow_iou"] < CHECKS["shadow_iou_min"]:
            failures.append("frame %d: shadow IoU %.3f < %g" % (fr["frame"], fr["shadow_iou"], CHECKS["shadow_iou_min"]))
        if fr["depth_both_measured"] < CHECKS["depth_both_measured_min"]:
            failures.append("frame %d: depth measured in both at %.3f of the pixels either measures < %g" %
                            (fr["frame"], fr["depth_both_measured"], CHECKS["depth_both_measured_min"]))
        dz = fr["depth_abs_diff_mm_median_p99"]
        if dz is not None and dz[0] > CHECKS["depth_median_mm_max"]:
            failures.append("frame %d: median depth difference %.2f mm > %g" % (fr["frame"], dz[0], CHECKS["depth_median_mm_max"]))
        if fr["shadow_centroid_px"] > CHECKS["shadow_centroid_px_max"]:
            failures.append("frame %d: shadow centroids %.1f px apart > %g" %
                            (fr["frame"], fr["shadow_centroid_px"], CHECKS["shadow_centroid_px_max"]))
    report["checks"] = CHECKS
    report["failures"] = failures
    print("over %d frames: mean C ratio (Cycles / mrgi) %s; delta RDE all/real/virtual %s" %
          (n, report["mean_c_ratio"], report["delta_rde_all_real_virtual"]))
    print("checks: " + ("all pass" if not failures else "; ".join(failures)))
    if out_json:
        with open(out_json, "w") as fh:
            json.dump(report, fh, indent=1)
    sys.stdout.flush()
    os._exit(1 if failures else 0)


main()

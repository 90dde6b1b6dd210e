#!/usr/bin/env python3
"""Keeps perf/suite.json's per-scene facts equal to their sources, so they cannot drift apart:
width, height, frames, spp, max_depth, seed from the scene description (perf/suite/<name>.json),
reference_noise_rde, delta_rms_linear and render_seconds from perf/suite/<name>.log (written by
render_suite.sh: the `mrgi synth --noise-floor-seed` line and `render_seconds N`).

    python3 perf/suite/sync_suite_json.py           # rewrite perf/suite.json (from the repo root)
    python3 perf/suite/sync_suite_json.py --check   # exit 1 and list what differs, change nothing
"""
import json
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SUITE = ROOT / "perf" / "suite.json"
NOISE = re.compile(r"all (\S+) real (\S+) virtual (\S+); delta rms (\S+)")


def facts_from_description(path):
    d = json.loads(path.read_text())
    return {
        "width": d["camera"]["width"],
        "height": d["camera"]["height"],
        "frames": d["frames"],
        "spp": d["render"]["spp"],
        "max_depth": d["render"]["max_depth"],
        "seed": d["render"]["seed"],
    }


def facts_from_log(path):
    facts = {}
    for line in path.read_text().splitlines():
        m = NOISE.search(line)
        if line.startswith("reference noise floor") and m:
            facts["reference_noise_rde"] = {k: float(v) for k, v in zip(("all", "real", "virtual"), m.groups()[:3])}
            facts["delta_rms_linear"] = float(m.group(4))
        elif line.startswith("render_seconds "):
            facts["render_seconds"] = int(line.split()[1])
    missing = {"reference_noise_rde", "render_seconds"} - facts.keys()
    if missing:
        sys.exit(f"{path}: lacks {', '.join(sorted(missing))} (expected the noise-floor line of "
                 "`mrgi synth --noise-floor-seed` and a `render_seconds N` line)")
    return facts


def main():
    check = sys.argv[1:] == ["--check"]
    if sys.argv[1:] and not check:
        sys.exit(__doc__)
    suite = json.loads(SUITE.read_text())
    differences = []
    for scene in suite["scenes"]:
        wanted = facts_from_description(ROOT / scene["description"])
        log = ROOT / "perf" / "suite" / (scene["name"] + ".log")
        if log.exists():
            wanted.update(facts_from_log(log))
        for key, value in wanted.items():
            if scene.get(key) != value:
                differences.append(f"{scene['name']}.{key}: {scene.get(key)} -> {value}")
                scene[key] = value
    for d in differences:
        print(d)
    if check:
        sys.exit(1 if differences else 0)
    SUITE.write_text(json.dumps(suite, indent=2) + "\n")


if __name__ == "__main__":
    main()

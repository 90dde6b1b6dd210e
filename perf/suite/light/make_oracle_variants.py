#!/usr/bin/env python3
"""Oracle variants of the light-estimation family: the same scenes with an assumption of the
probeless estimator made exactly true, to measure how much of its error each assumption causes.

  python3 perf/suite/light/make_oracle_variants.py OUT [--direct-only]

writes OUT/perf/suite/light/<name>.json for every scene of perf/suite/light/family.json with every
real and virtual surface grey (0.6: the estimator's grey-world albedo assumption holds), and with
--direct-only also render.max_depth 0 (no bounce light: the estimate's distant-light model sees
only the light sources), plus OUT/perf/suite/light/family.json (same split) and the assets.
Render them from OUT: cd OUT && MRGI=/path/to/mrgi bash /path/to/repo/perf/suite/light/render_family.sh, then
  mrgi light-family --root OUT --manifest OUT/perf/suite/light/family.json -o RESULTS
Run from the repository root."""
import json
import os
import shutil
import sys


def grey_materials(node):
    if isinstance(node, dict):
        for key, value in node.items():
            if key == "material" and isinstance(value, dict) and "color" in value:
                value["color"] = [0.6, 0.6, 0.6]
            else:
                grey_materials(value)
    elif isinstance(node, list):
        for value in node:
            grey_materials(value)


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    flags = [a for a in sys.argv[1:] if a.startswith("--")]
    if len(args) != 1 or any(f not in ("--direct-only",) for f in flags):
        sys.exit(__doc__)
    out = os.path.abspath(args[0])
    src = "perf/suite/light"
    if not os.path.isfile(os.path.join(src, "family.json")):
        sys.exit("make_oracle_variants.py: run from the repository root (no perf/suite/light/family.json here)")
    dst = os.path.join(out, src)
    os.makedirs(dst, exist_ok=True)
    family = json.load(open(os.path.join(src, "family.json")))
    for scene in family["scenes"]:
        desc = json.load(open(os.path.join(src, scene["name"] + ".json")))
        grey_materials(desc)
        if "--direct-only" in flags:
            desc["render"]["max_depth"] = 0
            desc["render"]["rr_depth"] = 1
        # Environment images by absolute path: OUT is not beside ../shared.
        env = desc.get("environment", {})
        if isinstance(env.get("image"), str) and not os.path.isabs(env["image"]):
            env["image"] = os.path.abspath(os.path.join(src, env["image"]))
        json.dump(desc, open(os.path.join(dst, scene["name"] + ".json"), "w"), indent=1)
    json.dump(family, open(os.path.join(dst, "family.json"), "w"), indent=1)
    shutil.copytree("perf/suite/assets", os.path.join(out, "perf/suite/assets"), dirs_exist_ok=True)
    print(f"{len(family['scenes'])} descriptions in {dst}")


if __name__ == "__main__":
    main()

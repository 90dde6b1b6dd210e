#!/usr/bin/env python3
"""Writes the suite's small virtual-object glTF files (self-contained .gltf, base64 buffers).

    python3 perf/suite/assets/make_assets.py     (from the repository root)

white_box.gltf     0.15 m white diffuse cube (albedo 0.8) resting on y = 0: shows real-to-virtual
                   colour bleeding in `corner`.
glass_sphere.gltf  0.08 m radius clear glass sphere (KHR_materials_transmission 1, KHR_materials_ior
                   1.5) resting on y = 0, for `glass_mirror`.
mirror_box.gltf    0.1 x 0.16 x 0.02 m perfect-mirror slab (metallic 1, roughness 0) standing on
                   y = 0, for `glass_mirror`.
For the independently rendered validation set (perf/cycles/scenes/): objects that span albedo and
colour, each diffuse (roughness 1) and resting on y = 0:
orange_box.gltf    0.16 m cube, albedo (0.8, 0.3, 0.08): colour bleeding onto white walls.
yellow_sphere.gltf 0.1 m radius, albedo (0.8, 0.7, 0.12).
dark_sphere.gltf   0.1 m radius, albedo 0.04: a virtual object that mostly blocks light.
white_sphere.gltf  0.1 m radius, albedo 0.85: a virtual object that mostly reflects it.
Made for this project; Apache-2.0, as the repository (LICENSE).
"""
import base64
import json
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


def box(sx, sy, sz):
    pos, nrm, idx = [], [], []
    h = (sx / 2, sy / 2, sz / 2)
    for axis in range(3):
        for sign in (-1, 1):
            n = [0.0, 0.0, 0.0]
            n[axis] = float(sign)
            a1, a2 = (axis + 1) % 3, (axis + 2) % 3
            u = [0.0] * 3
            v = [0.0] * 3
            u[a1] = h[a1]
            v[a2] = h[a2]
            c = [n[k] * h[k] for k in range(3)]
            corners = [(-1, -1), (1, -1), (1, 1), (-1, 1)] if sign > 0 else [(-1, -1), (-1, 1), (1, 1), (1, -1)]
            b = len(pos)
            for su, sv in corners:
                # rest on y = 0
                p = [c[k] + su * u[k] + sv * v[k] for k in range(3)]
                p[1] += h[1]
                pos.append(p)
                nrm.append(n)
            idx += [b, b + 1, b + 2, b, b + 2, b + 3]
    return pos, nrm, idx


def sphere(r, seg=48):
    rings = seg // 2
    pos, nrm, idx = [], [], []
    for i in range(rings + 1):
        t = math.pi * i / rings
        for j in range(seg + 1):
            p = 2 * math.pi * j / seg
            n = [math.sin(t) * math.cos(p), math.cos(t), -math.sin(t) * math.sin(p)]
            nrm.append(n)
            pos.append([r * n[0], r * n[1] + r, r * n[2]])
    row = seg + 1
    for i in range(rings):
        for j in range(seg):
            a = i * row + j
            b = a + row
            if i != 0:
                idx += [a, b, a + 1]
            if i != rings - 1:
                idx += [a + 1, b, b + 1]
    return pos, nrm, idx


def write(name, mesh, material, extensions_used):
    pos, nrm, idx = mesh
    pb = b"".join(struct.pack("<3f", *p) for p in pos)
    nb = b"".join(struct.pack("<3f", *n) for n in nrm)
    ib = b"".join(struct.pack("<I", i) for i in idx)
    data = pb + nb + ib
    mins = [min(p[k] for p in pos) for k in range(3)]
    maxs = [max(p[k] for p in pos) for k in range(3)]
    doc = {
        "asset": {"version": "2.0", "generator": "mrgi perf/suite/assets/make_assets.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": name}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": 0}]}],
        "materials": [material],
        "buffers": [{"byteLength": len(data),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": len(pb), "target": 34962},
            {"buffer": 0, "byteOffset": len(pb), "byteLength": len(nb), "target": 34962},
            {"buffer": 0, "byteOffset": len(pb) + len(nb), "byteLength": len(ib), "target": 34963},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(pos), "type": "VEC3", "min": mins, "max": maxs},
            {"bufferView": 1, "componentType": 5126, "count": len(nrm), "type": "VEC3"},
            {"bufferView": 2, "componentType": 5125, "count": len(idx), "type": "SCALAR"},
        ],
    }
    if extensions_used:
        doc["extensionsUsed"] = extensions_used
    with open(os.path.join(HERE, name + ".gltf"), "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


write("white_box", box(0.15, 0.15, 0.15),
      {"name": "white", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0,
                                                 "roughnessFactor": 1}}, [])
write("glass_sphere", sphere(0.08),
      {"name": "glass", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0,
                                                 "roughnessFactor": 0},
       "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0}, "KHR_materials_ior": {"ior": 1.5}}},
      ["KHR_materials_transmission", "KHR_materials_ior"])
write("mirror_box", box(0.1, 0.16, 0.02),
      {"name": "mirror", "pbrMetallicRoughness": {"baseColorFactor": [0.95, 0.95, 0.95, 1], "metallicFactor": 1,
                                                  "roughnessFactor": 0}}, [])


def diffuse(name, rgb):
    return {"name": name, "pbrMetallicRoughness": {"baseColorFactor": list(rgb) + [1], "metallicFactor": 0,
                                                   "roughnessFactor": 1}}


write("orange_box", box(0.16, 0.16, 0.16), diffuse("orange", (0.8, 0.3, 0.08)), [])
write("yellow_sphere", sphere(0.1), diffuse("yellow", (0.8, 0.7, 0.12)), [])
write("dark_sphere", sphere(0.1), diffuse("dark", (0.04, 0.04, 0.04)), [])
write("white_sphere", sphere(0.1), diffuse("white", (0.85, 0.85, 0.85)), [])

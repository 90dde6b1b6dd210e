#!/usr/bin/env python3
"""Writes the generated seeds of ../corpus: a one-triangle glTF (.gltf with a data URI and .glb,
two nodes, one material), Radiance .hdr (flat and run-length encoded) and small PNGs (RGB8,
grey, 16-bit depth, RGBA, RGB16). The JSON and list seeds are copies of the suite's files; the
JPEG and EXR seeds come from make_jpeg_seeds.c and make_exr_seed.cpp."""
import base64, json, os, struct, zlib

D = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'corpus')


def gltf_seeds():
    pos = struct.pack('<9f', 0, 0, 0, 1, 0, 0, 0, 1, 0)
    nrm = struct.pack('<9f', 0, 0, 1, 0, 0, 1, 0, 0, 1)
    uv = struct.pack('<6f', 0, 0, 1, 0, 0, 1)
    idx = struct.pack('<3H', 0, 1, 2) + b'\0\0'
    binbuf = pos + nrm + uv + idx

    def doc(uri):
        d = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
             "nodes": [{"mesh": 0, "translation": [0, 0.1, 0], "children": [1]}, {"mesh": 0, "scale": [0.5, 0.5, 0.5]}],
             "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0}]}],
             "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.2, 0.2, 1], "roughnessFactor": 0.5}, "doubleSided": False}],
             "buffers": [{"byteLength": len(binbuf)}],
             "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 36},
                             {"buffer": 0, "byteOffset": 72, "byteLength": 24}, {"buffer": 0, "byteOffset": 96, "byteLength": 6}],
             "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                           {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"},
                           {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"},
                           {"bufferView": 3, "componentType": 5123, "count": 3, "type": "SCALAR"}]}
        if uri:
            d["buffers"][0]["uri"] = uri
        return d

    uri = "data:application/octet-stream;base64," + base64.b64encode(binbuf).decode()
    open(os.path.join(D, 'gltf/triangle.gltf'), 'w').write(json.dumps(doc(uri)))
    j = json.dumps(doc(None)).encode()
    j += b' ' * ((4 - len(j) % 4) % 4)
    b = binbuf + b'\0' * ((4 - len(binbuf) % 4) % 4)
    glb = (struct.pack('<4sII', b'glTF', 2, 12 + 8 + len(j) + 8 + len(b)) + struct.pack('<I4s', len(j), b'JSON') + j +
           struct.pack('<I4s', len(b), b'BIN\0') + b)
    open(os.path.join(D, 'gltf/triangle.glb'), 'wb').write(glb)


def hdr_seeds():
    px = b''.join(bytes([128, 64, 32, 129]) for _ in range(8))
    open(os.path.join(D, 'hdr/flat_4x2.hdr'), 'wb').write(b'#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 4\n' + px)
    line = bytes([2, 2, 0, 8]) + b''.join(bytes([128 + 8, v]) for v in (100, 90, 80, 130))
    open(os.path.join(D, 'hdr/rle_8x2.hdr'), 'wb').write(b'#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 8\n' + line * 2)


def png(path, w, h, bitdepth, ctype, rows):
    def chunk(t, d):
        return struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)
    raw = b''.join(b'\0' + r for r in rows)
    data = (b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, bitdepth, ctype, 0, 0, 0)) +
            chunk(b'IDAT', zlib.compress(raw)) + chunk(b'IEND', b''))
    open(os.path.join(D, path), 'wb').write(data)


def png_seeds():
    png('png/rgb8.png', 8, 6, 8, 2, [bytes((x * 30 + y * 5) & 255 for x in range(24)) for y in range(6)])
    png('png/depth16.png', 8, 6, 16, 0, [b''.join(struct.pack('>H', 5000 + 100 * x + y) for x in range(8)) for y in range(6)])
    png('png/gray8.png', 8, 6, 8, 0, [bytes(range(y, y + 8)) for y in range(6)])
    png('texture/rgba8.png', 8, 6, 8, 6, [bytes((x * 13 + y) & 255 for x in range(32)) for y in range(6)])
    png('texture/rgb16.png', 4, 4, 16, 2, [bytes((x * 7 + y) & 255 for x in range(24)) for y in range(4)])


if __name__ == '__main__':
    gltf_seeds()
    hdr_seeds()
    png_seeds()

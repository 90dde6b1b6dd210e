#!/usr/bin/env python3
"""RDE over a virtual object's reflection region on a real floor or table (the glossy
suite scene), from a replay's frames against the capture's references. Standard library only.

The reflection region of a frame: the real pixels directly below the virtual object's silhouette
in the reference's mask, in each image column from the object's lowest pixel down by the
object's height in that column (a horizontal mirror under the object shows it upside down
there, foreshortened: this over-covers it, never misses it). RDE as mrgi/metrics.h defines it:
||(O - C) - (G - C)|| / ||G - C|| over those pixels, linear RGB, pooled over frames.

  perf/tools/reflection_rde.py CAPTURE REFERENCES_DIR REPLAY_DIR [REPLAY_DIR ...]

REFERENCES_DIR: `mrgi references CAPTURE --export DIR` (plain PNGs); REPLAY_DIR: `mrgi replay
... -o DIR` (frames/NNNNNN.png). Prints one line per replay: the pooled RDE and the pixel count.
"""
import os
import struct
import sys
import zlib


def read_png(path):
    data = open(path, 'rb').read()
    if data[:8] != b'\x89PNG\r\n\x1a\n':
        sys.exit(f'{path}: not a PNG')
    pos, idat = 8, b''
    while pos < len(data):
        n, = struct.unpack('>I', data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + n]
        pos += 12 + n
        if kind == b'IHDR':
            w, h, depth, ctype = struct.unpack('>IIBB', body[:10])
            if depth != 8 or ctype not in (0, 2, 6):
                sys.exit(f'{path}: only 8-bit grey, RGB or RGBA PNGs are read')
        elif kind == b'IDAT':
            idat += body
    raw = zlib.decompress(idat)
    bpp = {0: 1, 2: 3, 6: 4}[ctype]
    stride, out, prev, i = w * bpp, bytearray(), bytearray(w * bpp), 0
    for _ in range(h):
        f, line = raw[i], bytearray(raw[i + 1:i + 1 + stride])
        i += 1 + stride
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            b = prev[x]
            c = prev[x - bpp] if x >= bpp else 0
            if f == 1: line[x] = (line[x] + a) & 255
            elif f == 2: line[x] = (line[x] + b) & 255
            elif f == 3: line[x] = (line[x] + ((a + b) >> 1)) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        out += line
        prev = line
    return w, h, bpp, out


LIN = [((v / 255.0) / 12.92 if v / 255.0 <= 0.04045 else ((v / 255.0 + 0.055) / 1.055) ** 2.4) for v in range(256)]


def region(mask, w, h):
    """Real pixels below the silhouette, column by column (see the module's text)."""
    pixels = []
    for x in range(w):
        rows = [y for y in range(h) if mask[y * w + x]]
        if not rows:
            continue
        top, bottom = min(rows), max(rows)
        for y in range(bottom + 1, min(h, bottom + 1 + (bottom - top + 1))):
            if not mask[y * w + x]:
                pixels.append(y * w + x)
    return pixels


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    capture, refs, replays = sys.argv[1], sys.argv[2], sys.argv[3:]
    names = sorted(f for f in os.listdir(refs) if f.endswith('.png') and '_mask' not in f)
    if not names:
        sys.exit(f'{refs}: no reference PNGs (mrgi references {capture} --export {refs})')
    frames = []
    for name in names:
        index = name[:-4]
        w, h, _, mask = read_png(os.path.join(capture, 'reference', index + '_mask.png'))
        _, _, gb, g = read_png(os.path.join(refs, name))
        _, _, cb, c = read_png(os.path.join(capture, 'rgb', index + '.png'))
        frames.append((index, w, h, region(mask, w, h), (gb, g), (cb, c)))
    for replay in replays:
        err2 = ref2 = 0.0
        count = 0
        for index, w, h, pixels, (gb, g), (cb, c) in frames:
            path = os.path.join(replay, 'frames', index + '.png')
            if not os.path.exists(path):
                continue
            _, _, ob, o = read_png(path)
            for p in pixels:
                for k in range(3):
                    gl, cl, ol = LIN[g[p * gb + k]], LIN[c[p * cb + k]], LIN[o[p * ob + k]]
                    err2 += (ol - gl) ** 2
                    ref2 += (gl - cl) ** 2
            count += len(pixels)
        rde = (err2 / ref2) ** 0.5 if ref2 > 0 else float('nan')
        print(f'{replay}: reflection region RDE {rde:.3f} over {count} pixel-frames')


if __name__ == '__main__':
    main()

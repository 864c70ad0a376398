#!/usr/bin/env python3
"""Mean absolute difference, in 8-bit levels over the RGB channels, between two PNG files of
the same size (8-bit RGB or RGBA, non-interlaced: what the showcase and `render` write).
Standard library only. Usage: scripts/png_diff.py A.png B.png"""
import struct
import sys
import zlib


def read(path):
    data = open(path, "rb").read()
    pos, idat, head = 8, b"", None
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos : pos + 4])
        kind, body = data[pos + 4 : pos + 8], data[pos + 8 : pos + 8 + n]
        pos += 12 + n
        if kind == b"IHDR":
            head = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
    w, h, depth, color, _, _, interlace = head
    if depth != 8 or color not in (2, 6) or interlace:
        sys.exit(f"{path}: only 8-bit RGB or RGBA, non-interlaced")
    bpp = 3 if color == 2 else 4
    raw, stride, rows, prev, i = zlib.decompress(idat), w * bpp, [], bytearray(w * bpp), 0
    for _ in range(h):
        f, line = raw[i], bytearray(raw[i + 1 : i + 1 + stride])
        i += 1 + stride
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            b, c = prev[x], prev[x - bpp] if x >= bpp else 0
            if f == 1:
                line[x] = (line[x] + a) & 255
            elif f == 2:
                line[x] = (line[x] + b) & 255
            elif f == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    return w, h, bpp, rows


(w, h, pa, a), (w2, h2, pb, b) = read(sys.argv[1]), read(sys.argv[2])
if (w, h) != (w2, h2):
    sys.exit("sizes differ")
total = sum(abs(a[y][x * pa + c] - b[y][x * pb + c]) for y in range(h) for x in range(w) for c in range(3))
print(f"mean absolute difference {total / (w * h * 3):.3f} levels over {w}x{h}")

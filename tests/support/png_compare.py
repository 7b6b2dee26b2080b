#!/usr/bin/env python3
"""Compare a viewer screenshot with a CPU render (PNG files, pure Python: no imaging library).

Usage: png_compare.py SCREENSHOT CPU_RENDER IMAGE_X IMAGE_Y PANEL_X0 PANEL_Y0 PANEL_X1 PANEL_Y1
Checks: the CPU render lies in the screenshot with its top-left corner at (IMAGE_X, IMAGE_Y)
(the viewer's image viewport, which `lancer view` prints) and equals it there (each channel
within 1); the panel rectangle lies outside it and holds the UI (many distinct colours: text and
widgets); the whole screenshot is not blank (many distinct colours).
"""
import struct
import sys
import zlib


def read_png(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG")
    pos, idat, width = 8, b"", 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, ctype = struct.unpack(">IIBB", body[:10])
            if depth != 8 or ctype not in (2, 6):
                sys.exit(f"{path}: only 8-bit RGB/RGBA PNGs are read here")
            channels = 3 if ctype == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    pixel = lambda x, y: tuple(rows[y][x * channels:x * channels + 3])
    return width, height, pixel


def main():
    shot, cpu = sys.argv[1], sys.argv[2]
    ix, iy, px0, py0, px1, py1 = map(int, sys.argv[3:9])
    w, h, s = read_png(shot)
    cw, ch, c = read_png(cpu)
    if ix < 0 or iy < 0 or ix + cw > w or iy + ch > h:
        sys.exit(f"a {cw}x{ch} render at {ix},{iy} does not fit the {w}x{h} screenshot")
    if px0 < ix + cw and ix < px1 and py0 < iy + ch and iy < py1:
        sys.exit("the panel rectangle overlaps the image viewport")
    same = total = 0
    for y in range(ch):
        for x in range(cw):
            total += 1
            same += max(abs(a - b) for a, b in zip(s(ix + x, iy + y), c(x, y))) <= 1
    panel = {s(x, y) for y in range(py0, py1) for x in range(px0, px1)}
    colours = {s(x, y) for y in range(0, h, 3) for x in range(0, w, 3)}
    print(f"image viewport: {same}/{total} pixels equal the CPU render; panel: {len(panel)} "
          f"colours; {len(colours)} distinct colours")
    ok = same == total and len(panel) > 10 and len(colours) > 200
    sys.exit(0 if ok else 1)


main()

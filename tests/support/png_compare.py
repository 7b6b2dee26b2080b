#!/usr/bin/env python3
"""Compare a viewer screenshot with a CPU render (PNG files, pure Python: no imaging library).

Usage: png_compare.py SCREENSHOT CPU_RENDER X0 Y0 X1 Y1 PANEL_X0 PANEL_Y0 PANEL_X1 PANEL_Y1
Checks: the same size; inside the first rectangle (between the panels) the screenshot equals
the CPU render (each channel within 1); inside the second (a panel) most pixels differ (the UI
is drawn); the whole screenshot is not blank (many distinct colours).
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
    x0, y0, x1, y1, px0, py0, px1, py1 = map(int, sys.argv[3:11])
    w, h, s = read_png(shot)
    cw, ch, c = read_png(cpu)
    if (w, h) != (cw, ch):
        sys.exit(f"screenshot is {w}x{h}, the CPU render {cw}x{ch}")
    same = total = 0
    for y in range(y0, y1):
        for x in range(x0, x1):
            total += 1
            same += max(abs(a - b) for a, b in zip(s(x, y), c(x, y))) <= 1
    differ = ptotal = 0
    for y in range(py0, py1):
        for x in range(px0, px1):
            ptotal += 1
            differ += max(abs(a - b) for a, b in zip(s(x, y), c(x, y))) > 1
    colours = {s(x, y) for y in range(0, h, 3) for x in range(0, w, 3)}
    print(f"centre: {same}/{total} pixels equal the CPU render; panel: {differ}/{ptotal} differ; "
          f"{len(colours)} distinct colours")
    ok = same >= 0.999 * total and differ > ptotal // 2 and len(colours) > 200
    sys.exit(0 if ok else 1)


main()

#!/usr/bin/python3
"""CTest viewer_headless_frame: renders one frame of quathinge-viewer under Xvfb and checks the PNG is not blank.

    QUATHINGE_VIEWER=path/to/quathinge-viewer check_frame.py XVFB_RUN OUT.png [viewer arguments...]

Not blank: at least kMinColours distinct colours, and at least kMinDrawn of the pixels differ from the background
colour (bodies, the ground, the panel and its plots). Decodes the PNG itself (8-bit RGB, the five filters) with zlib,
so it needs nothing beyond Python's standard library.
"""
import os
import struct
import subprocess
import sys
import zlib

kMinColours = 50     # distinct RGB values
kMinDrawn = 0.02     # fraction of pixels not the clear colour
kBackground = (31, 31, 36)  # glClearColor(0.12, 0.12, 0.14)


def read_png(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, width = 8, b"", 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and colour == 2, "expected 8-bit RGB"
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw, stride, rows, prev = zlib.decompress(idat), width * 3, [], bytearray(width * 3)
    for y in range(height):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - 3] if i >= 3 else 0
            b = prev[i]
            c = prev[i - 3] if i >= 3 else 0
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
        rows.append(bytes(line))
        prev = line
    return width, height, rows


def main():
    xvfb, out, extra = sys.argv[1], sys.argv[2], sys.argv[3:]
    viewer = os.environ["QUATHINGE_VIEWER"]
    cmd = [xvfb, "-a", "-s", "-screen 0 1280x720x24", viewer, "--screenshot", out, "--frames", "30",
           "--scene", "heavy1000", "--kinds", "stock,quaternion+stab", "--size", "960"] + extra
    print(" ".join(cmd))
    subprocess.run(cmd, check=True, timeout=100)
    width, height, rows = read_png(out)
    colours, drawn = set(), 0
    for row in rows:
        for x in range(0, len(row), 3):
            px = row[x:x + 3]
            colours.add(px)
            if tuple(px) != kBackground:
                drawn += 1
    fraction = drawn / (width * height)
    print(f"{out}: {width}x{height}, {len(colours)} colours, {100 * fraction:.1f}% drawn")
    if len(colours) < kMinColours or fraction < kMinDrawn:
        sys.exit(f"blank frame: {len(colours)} colours (< {kMinColours}) or {100 * fraction:.1f}% drawn (< {100 * kMinDrawn}%)")


if __name__ == "__main__":
    main()

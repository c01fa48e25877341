#!/usr/bin/python3
"""CTest viewer_headless_frame: renders one frame of quathinge-viewer under Xvfb and checks the PNG is not blank.

    QUATHINGE_VIEWER=path/to/quathinge-viewer check_frame.py XVFB_RUN OUT.png [viewer arguments...]

Not blank: at least kMinColours distinct colours, and at least kMinDrawn of the pixels differ from the background
colour (bodies, the ground, the panel and its plots). The PNG is read with Debian's matplotlib (python3-matplotlib,
already needed by the report scripts).
"""
import os
import subprocess
import sys

import matplotlib.image
import numpy

kMinColours = 50             # distinct RGB values
kMinDrawn = 0.02             # fraction of pixels not the clear colour
kBackground = (31, 31, 36)   # glClearColor(0.12, 0.12, 0.14) in 8-bit


def main():
    xvfb, out, extra = sys.argv[1], sys.argv[2], sys.argv[3:]
    viewer = os.environ["QUATHINGE_VIEWER"]
    cmd = [xvfb, "-a", "-s", "-screen 0 1280x720x24", viewer, "--screenshot", out, "--frames", "30",
           "--scene", "heavy1000", "--kinds", "stock,quaternion+stab", "--size", "960"] + extra
    print(" ".join(cmd))
    subprocess.run(cmd, check=True, timeout=100)
    rgb = numpy.rint(matplotlib.image.imread(out)[:, :, :3] * 255).astype(numpy.int32)
    height, width = rgb.shape[:2]
    colours = len(numpy.unique(rgb.reshape(-1, 3), axis=0))
    drawn = float(numpy.mean(numpy.any(rgb != numpy.array(kBackground), axis=2)))
    print(f"{out}: {width}x{height}, {colours} colours, {100 * drawn:.1f}% drawn")
    if colours < kMinColours or drawn < kMinDrawn:
        sys.exit(f"blank frame: {colours} colours (< {kMinColours}) or {100 * drawn:.1f}% drawn (< {100 * kMinDrawn}%)")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Where the water caustic's "floor under the water" strip loses its light.

    scripts/water-floor-band.py IMAGE.exr REFERENCE.exr > OUT.md

IMAGE: photonmap's render of Bitterli's water caustic at 256 x 256
(`photonmap render scene-v4.pbrt --method sppm --width 256 --height 256
--time 60 --exr IMAGE.exr`); REFERENCE: its Tungsten reference averaged over
4 x 4 blocks (scripts/downsample-reference.py, as scripts/water-caustic.sh
makes it). Prints, for columns 96..160, the image's energy over the
reference's in the strip (rows 238..250) and in taller bands around it, and
in the strip against the reference blurred by a k x k box: if the light
reaches the floor in the right amount but is spread across the strip's
edges, the taller bands read 1 and a blurred reference meets the image.
Needs `pip install mitsuba numpy` (for reading EXR).
"""
import sys

import mitsuba as mi
import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

mi.set_variant("scalar_rgb")


def luminance(path):
    return np.array(mi.Bitmap(path))[:, :, :3].mean(axis=2)


def main():
    image, reference = (luminance(p) for p in sys.argv[1:3])
    cols = slice(96, 160)
    print(f"`scripts/water-floor-band.py {sys.argv[1]} {sys.argv[2]}`")
    print()
    print("| rows (columns 96..160) | image / reference |")
    print("|---|---|")
    for y0, y1 in [(238, 250), (234, 254), (226, 254), (200, 254)]:
        ratio = image[y0:y1, cols].sum() / reference[y0:y1, cols].sum()
        print(f"| {y0}..{y1} | {ratio:.3f} |")
    print()
    print("| reference blurred by a k x k box | its strip / the reference's | image / it, in the strip |")
    print("|---|---|---|")
    strip = (slice(238, 250), cols)
    for k in (1, 3, 5, 7):
        padded = np.pad(reference, k // 2, mode="edge")
        blurred = sliding_window_view(padded, (k, k)).mean(axis=(2, 3))
        print(
            f"| {k} | {blurred[strip].sum() / reference[strip].sum():.3f} "
            f"| {image[strip].sum() / blurred[strip].sum():.3f} |"
        )


if __name__ == "__main__":
    main()

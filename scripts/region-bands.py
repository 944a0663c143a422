#!/usr/bin/env python3
"""Whether a region reads wrong because its light is missing or because it
is spread across the region's edges.

    scripts/region-bands.py IMAGE.exr REFERENCE.exr X0:X1:Y0:Y1 > OUT.md

For the columns X0..X1, prints the image's energy over the reference's in
the rows Y0..Y1 and in bands of rows that grow around them, row by row, and
in the region against the reference blurred by a k x k box. If the light
arrives in the right amount but is spread across the region's edges (an
estimate's radius, a filter), the wider bands read 1 and a blurred
reference meets the image. Needs `pip install mitsuba numpy` (for EXR).
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
    x0, x1, y0, y1 = (int(v) for v in sys.argv[3].split(":"))
    cols = slice(x0, x1)
    ratio = lambda a, b: image[a:b, cols].sum() / reference[a:b, cols].sum()
    print(f"`scripts/region-bands.py {' '.join(sys.argv[1:4])}`")
    print()
    print(f"| rows (columns {x0}..{x1}) | image / reference |")
    print("|---|---|")
    height = (y1 - y0) // 2 + 2
    for grow in (0, height // 2, height, 2 * height):
        a, b = max(y0 - grow, 0), min(y1 + grow, reference.shape[0])
        print(f"| {a}..{b} | {ratio(a, b):.3f} |")
    print()
    print("| row | image / reference | reference's mean |")
    print("|---|---|---|")
    for y in range(max(y0 - 2, 0), min(y1 + 2, reference.shape[0])):
        print(f"| {y} | {ratio(y, y + 1):.3f} | {reference[y, cols].mean():.4f} |")
    print()
    print("| reference blurred by a k x k box | its region / the reference's | image / it, in the region |")
    print("|---|---|---|")
    region = (slice(y0, y1), cols)
    for k in (1, 3, 5, 7):
        padded = np.pad(reference, k // 2, mode="edge")
        blurred = sliding_window_view(padded, (k, k)).mean(axis=(2, 3))
        print(
            f"| {k} | {blurred[region].sum() / reference[region].sum():.3f} "
            f"| {image[region].sum() / blurred[region].sum():.3f} |"
        )


if __name__ == "__main__":
    main()

"""Average a reference image over N x N blocks (a render at 1/N of its
size compares with it pixel for pixel), and write a mask that leaves out
the blocks that hold any pixel of a given rectangle (a light whose
radiance the file clips, for instance). The import trial's Bitterli
references are made with it (docs/src/evaluation/import-trial.md).

    python scripts/downsample-reference.py IN.exr N OUT.exr MASK.png [X0:X1:Y0:Y1 ...]

Each X0:X1:Y0:Y1 names full-size pixels (columns X0..X1, rows Y0..Y1, row
0 at the top, ends excluded) whose blocks the mask leaves out. A pixel that
is not finite (a half float that overflowed) is read as the largest half
float, 65504, and its block must be left out. Needs `pip install mitsuba
numpy` (Mitsuba's Bitmap reads and writes the EXRs).
"""
import sys

import mitsuba as mi
import numpy as np


def main():
    if len(sys.argv) < 5:
        sys.exit(__doc__)
    src, n, out, mask_out = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4]
    mi.set_variant("scalar_rgb")
    bitmap = mi.Bitmap(src).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False)
    image = np.array(bitmap, dtype=np.float64)
    h, w, _ = image.shape
    if h % n or w % n:
        sys.exit(f"{src}: {w} x {h} is not a multiple of {n}")
    left_out = np.zeros((h, w), bool)
    for spec in sys.argv[5:]:
        x0, x1, y0, y1 = (int(v) for v in spec.split(":"))
        left_out[y0:y1, x0:x1] = True
    bad = ~np.isfinite(image).all(axis=2)
    image[~np.isfinite(image)] = 65504.0
    blocks = image.reshape(h // n, n, w // n, n, 3).mean(axis=(1, 3))
    out_blocks = left_out.reshape(h // n, n, w // n, n).any(axis=(1, 3))
    bad_blocks = bad.reshape(h // n, n, w // n, n).any(axis=(1, 3))
    if (bad_blocks & ~out_blocks).any():
        rows, cols = np.nonzero(bad_blocks & ~out_blocks)
        sys.exit(f"{src}: non-finite pixels in blocks the mask keeps (block row {rows[0]}, column {cols[0]})")
    mi.Bitmap(blocks.astype(np.float32)).write(out)
    mask = np.where(out_blocks, 0, 255).astype(np.uint8)
    mi.Bitmap(mask[:, :, None]).write(mask_out)
    print(f"{out}: {w // n} x {h // n}; {mask_out}: {int(out_blocks.sum())} blocks left out")


if __name__ == "__main__":
    main()

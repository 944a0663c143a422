"""Write an interior mask for a scene exported by `photonmap bench mitsuba`
(its `export.json`), made as the ground truth's masks are made but
stricter: a pixel is white where all 4 x 4 of its sub-pixel rays, and the
rays through its corners and along its border (a 9 x 9 lattice at eighths
of the pixel), first hit the same diffuse, non-emitting plane (one shape,
one normal, one offset). The border rays drop pixels whose square ends in a
silhouette that the 4 x 4 rays pass by, as on a face seen edge-on. Edges,
lights, mirrors, glass and curved surfaces are black. Mitsuba 3 intersects
the rays, so the mask shares no code with photonmap.

    python scripts/interior-mask.py EXPORT.json OUT.png [--scale N] [--check MASK.png]

--scale N: the export's size divided by N, a pixel white only where all
N x N of its full-size pixels are (as the truth's half-size masks are).
--check MASK.png: also count how many of OUT's white pixels MASK (another
mask of the same size, such as the truth's) has white.
Needs `pip install mitsuba numpy` (LLVM variant: DRJIT_LIBLLVM_PATH naming
libLLVM 16 or newer where the system's is older).
"""
import importlib.util
import json
import os
import shutil
import sys

import drjit as dr
import mitsuba as mi
import numpy as np

# Offsets within a pixel: the truth's 4 x 4 rays at the odd eighths, and
# the even eighths between and around them, 0 and 1 on the pixel's border.
OFFSETS = [i / 8 for i in range(9)]


def load_builder():
    here = os.path.dirname(os.path.abspath(__file__))
    path = os.path.join(here, "..", "src", "cli", "bench", "mitsuba", "mitsuba_render.py")
    spec = importlib.util.spec_from_file_location("mitsuba_render", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.build_scene


def masks(scene):
    """Two h x w masks at the scene's film size: white where all sub-pixel
    rays hit one diffuse, non-emitting plane; and where they all hit
    diffuse, non-emitting surfaces at all (the first plus the edges)."""
    sensor = scene.sensors()[0]
    w, h = sensor.film().crop_size()
    extent = float(dr.max(scene.bbox().extents()))
    py, px = np.mgrid[0:h, 0:w]
    keys = []
    for oy in OFFSETS:
        for ox in OFFSETS:
            u = ((px + ox) / w).ravel().astype(np.float32)
            v = ((py + oy) / h).ravel().astype(np.float32)
            ray, _ = sensor.sample_ray(0.0, 0.5, mi.Point2f(u, v), mi.Point2f(0.5, 0.5))
            si = scene.ray_intersect(ray)
            valid = np.array(si.is_valid())
            shape = np.array(dr.reinterpret_array(mi.UInt32, si.shape))
            emitter = np.array(si.shape.is_emitter())
            flags = np.array(si.bsdf().flags())
            diffuse = (flags & int(mi.BSDFFlags.Diffuse)) != 0
            specular = (flags & int(mi.BSDFFlags.Delta)) != 0
            n = np.stack([np.array(si.n.x), np.array(si.n.y), np.array(si.n.z)], axis=-1)
            p = np.stack([np.array(si.p.x), np.array(si.p.y), np.array(si.p.z)], axis=-1)
            offset = (n * p).sum(axis=-1) / extent
            keys.append((valid & ~emitter & diffuse & ~specular, shape, n, offset))
    good0, shape0, n0, d0 = keys[0]
    white, all_diffuse = good0.copy(), good0.copy()
    for good, shape, n, d in keys[1:]:
        all_diffuse &= good
        white &= good & (shape == shape0)
        white &= np.abs(n - n0).max(axis=-1) < 1e-3
        white &= np.abs(d - d0) < 1e-4
    return white.reshape(h, w), all_diffuse.reshape(h, w)


def main():
    args = sys.argv[1:]
    scale, check = 1, None
    if "--scale" in args:
        i = args.index("--scale")
        scale = int(args[i + 1])
        del args[i:i + 2]
    if "--check" in args:
        i = args.index("--check")
        check = args[i + 1]
        del args[i:i + 2]
    if len(args) != 2 or scale < 1:
        sys.exit(__doc__)
    export, out = args
    mi.set_variant("llvm_ad_rgb")
    s = json.load(open(export))
    w, h = s["camera"]["width"] * scale, s["camera"]["height"] * scale
    s["camera"]["width"], s["camera"]["height"] = w, h
    scene_dict, folder = load_builder()(mi, s, "path")
    scene = mi.load_dict(scene_dict)
    shutil.rmtree(folder, ignore_errors=True)
    mask, _ = masks(scene)
    if scale > 1:
        mask = mask.reshape(h // scale, scale, w // scale, scale).all(axis=(1, 3))
    mi.Bitmap((mask * 255).astype(np.uint8)).write(out)
    print("%s: %d x %d, %d white pixels" % (out, mask.shape[1], mask.shape[0], int(mask.sum())))
    if check:
        other = np.array(mi.Bitmap(check))
        other = (other.reshape(other.shape[0], other.shape[1], -1)[..., 0] > 127)
        print("%s: %d white pixels, %d of the %d above among them"
              % (check, int(other.sum()), int((mask & other).sum()), int(mask.sum())))


if __name__ == "__main__":
    main()

"""Render a Mitsuba 3 scene file to a linear EXR, or write its interior
mask: the import trial's Mitsuba side (docs/src/evaluation/import-trial.md).

    python scripts/mitsuba-render.py VARIANT SCENE.xml SPP SEED OUT.exr [OPTIONS] [NAME=VALUE ...]
    python scripts/mitsuba-render.py VARIANT SCENE.xml --mask OUT.png [--edges EDGES.png] [OPTIONS] [NAME=VALUE ...]

NAME=VALUE set the scene's <default> parameters (res=256, max_depth=64, ...).
The file is read into memory and changed there (the file itself is not):
every film's reconstruction filter becomes a box of one pixel, as
photonmap's (--keep-filter keeps the file's), and --black-emitters gives
every emitting shape a black BSDF, as photonmap's lights reflect nothing.

--mask writes a PNG that is white where all of a pixel's sub-pixel rays
(4 x 4, and along its border) first hit the same diffuse, non-emitting
plane (one shape, one normal, one offset), as scripts/interior-mask.py
makes its masks, the truth's rule made stricter at silhouettes; edges,
lights, mirrors, glass and curved surfaces are black. --edges writes the
pixels whose sub-pixel rays all hit diffuse, non-emitting surfaces but not
one plane: the edges between walls. The LLVM variants need
DRJIT_LIBLLVM_PATH naming libLLVM 16 or newer where the system's is older.
"""
import os
import sys
import time
import xml.etree.ElementTree as ET

import mitsuba as mi


def scene_text(path, keep_filter, black_emitters):
    """The scene file's XML with the film filters and emitters changed."""
    root = ET.parse(path).getroot()
    if not keep_filter:
        for film in root.iter("film"):
            for f in film.findall("rfilter"):
                film.remove(f)
            ET.SubElement(film, "rfilter", {"type": "box"})
    if black_emitters:
        for shape in root.iter("shape"):
            if shape.find("emitter") is None:
                continue
            for b in shape.findall("bsdf") + shape.findall("ref"):
                shape.remove(b)
            bsdf = ET.SubElement(shape, "bsdf", {"type": "diffuse"})
            ET.SubElement(bsdf, "rgb", {"name": "reflectance", "value": "0"})
    return ET.tostring(root, encoding="unicode")


def load(path, params, keep_filter=False, black_emitters=False):
    # Relative file names (meshes, includes) resolve against the file's folder.
    mi.file_resolver().prepend(os.path.dirname(os.path.abspath(path)))
    return mi.load_string(scene_text(path, keep_filter, black_emitters), **params)


def mask(scene, out, edges=None):
    import importlib.util

    import numpy as np

    here = os.path.dirname(os.path.abspath(__file__))
    spec = importlib.util.spec_from_file_location(
        "interior_mask", os.path.join(here, "interior-mask.py"))
    interior = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(interior)
    white, diffuse = interior.masks(scene)
    h, w = white.shape
    mi.Bitmap((white * 255).astype(np.uint8)).write(out)
    print(f"{out}: {w} x {h}, {int(white.sum())} white pixels")
    if edges:
        edge = diffuse & ~white
        mi.Bitmap((edge * 255).astype(np.uint8)).write(edges)
        print(f"{edges}: {w} x {h}, {int(edge.sum())} white pixels")


def main():
    args = sys.argv[1:]
    keep_filter = "--keep-filter" in args
    black_emitters = "--black-emitters" in args
    args = [a for a in args if a not in ("--keep-filter", "--black-emitters")]
    if len(args) >= 4 and args[2] == "--mask":
        variant, scene_path, _, out = args[:4]
        rest, edges = args[4:], None
        if rest[:1] == ["--edges"] and len(rest) >= 2:
            edges, rest = rest[1], rest[2:]
        mi.set_variant(variant)
        params = dict(a.split("=", 1) for a in rest)
        mask(load(scene_path, params, keep_filter, black_emitters), out, edges)
        return
    if len(args) < 5:
        sys.exit(__doc__)
    variant, scene_path, spp, seed, out = args[:5]
    mi.set_variant(variant)
    params = dict(a.split("=", 1) for a in args[5:])
    params.setdefault("spp", spp)
    scene = load(scene_path, params, keep_filter, black_emitters)
    start = time.time()
    img = mi.render(scene, seed=int(seed), spp=int(spp))
    mi.Bitmap(img).write(out)
    print(f"{out}: {spp} spp, seed {seed}, {time.time() - start:.1f} s")


if __name__ == "__main__":
    main()

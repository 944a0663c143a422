"""Render a Mitsuba 3 scene file to a linear EXR: the import trial's
Mitsuba side (docs/src/evaluation/import-trial.md).

    python scripts/mitsuba-render.py VARIANT SCENE.xml SPP SEED OUT.exr [NAME=VALUE ...]

NAME=VALUE set the scene's <default> parameters (res=256, resx=256, ...).
"""
import sys
import time

import mitsuba as mi

variant, scene_path, spp, seed, out = sys.argv[1:6]
mi.set_variant(variant)
params = dict(a.split("=", 1) for a in sys.argv[6:])
scene = mi.load_file(scene_path, spp=spp, **params)
start = time.time()
img = mi.render(scene, seed=int(seed), spp=int(spp))
mi.Bitmap(img).write(out)
print(f"{out}: {spp} spp, seed {seed}, {time.time() - start:.1f} s")

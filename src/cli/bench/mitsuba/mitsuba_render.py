#!/usr/bin/env python3
"""Renders a scene exported by `photonmap bench mitsuba` with Mitsuba 3 for a
wall-clock budget, and writes the image as linear EXR.

Usage: mitsuba_render.py EXPORT.json BUDGET_SECONDS OUT.exr INTEGRATOR VARIANT [CHECKPOINTS [SEED]]

The clock starts before the first render call (so Mitsuba's JIT compilation
counts, as a user would wait for it) and stops after the pass that crosses
the budget; importing Mitsuba and loading the scene do not count. Passes
with distinct seeds are accumulated: `batch` samples per pixel at first,
doubled (up to 2^25 camera paths a pass, which bounds its memory) after
each pass that took under a second and under a sixteenth of the budget: Mitsuba's LLVM back end traces each pass anew, so
large passes are its fastest (about 10 M paths/s at 1024 spp against 6 M
at 4 in GLASS BALL on 2 cores).
CHECKPOINTS (comma-separated seconds, optional) writes the running mean as
OUT-without-.exr + "_<k>.exr" after the first pass that crosses each; the
clock does not count writing them. Prints one JSON line: {"seconds": ...,
"spp": ..., "load_seconds": ..., "checkpoints": [{"seconds", "spp",
"file"}, ...]}. SEED (default 0) is the first pass's seed; each later
pass takes the next, so runs whose seeds are a million apart are
independent.
"""
import json
import os
import shutil
import struct
import sys
import tempfile
import time


def ply(path, vertices, faces):
    with open(path, "wb") as f:
        f.write(b"ply\nformat binary_little_endian 1.0\n")
        f.write(b"element vertex %d\nproperty float x\nproperty float y\nproperty float z\n" % len(vertices))
        f.write(b"element face %d\nproperty list uchar int vertex_indices\nend_header\n" % len(faces))
        for v in vertices:
            f.write(struct.pack("<3f", *v))
        for a, b, c in faces:
            f.write(struct.pack("<B3i", 3, a, b, c))


def rgb(v):
    return {"type": "rgb", "value": list(v)}


def bsdf(m):
    if m["type"] == "diffuse":
        return {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": rgb(m["albedo"])}}
    if m["type"] == "mirror":
        return {"type": "twosided", "bsdf": {"type": "conductor", "material": "none",
                                              "specular_reflectance": rgb(m["reflectance"])}}
    if m["type"] == "conductor":
        metal = {"type": "conductor", "eta": rgb(m["eta"]), "k": rgb(m["k"]),
                 "specular_reflectance": rgb(m["tint"])}
        if m["alpha"] > 0.0:
            metal.update({"type": "roughconductor", "distribution": m["distribution"],
                          "alpha": m["alpha"]})
        return {"type": "twosided", "bsdf": metal}
    if m["type"] == "glass":
        return {"type": "dielectric", "int_ior": m["ior"], "ext_ior": 1.0}
    # An emitter reflects nothing.
    return {"type": "diffuse", "reflectance": rgb([0.0, 0.0, 0.0])}


def build_scene(mi, s, integrator):
    """The Mitsuba scene dictionary of export `s` and the folder of its PLY
    meshes, which the caller removes once the scene is loaded."""
    cam = s["camera"]
    scene = {
        "type": "scene",
        "integrator": {"type": integrator, "max_depth": s["max_depth"]},
        "sensor": {
            "type": "perspective",
            "fov": cam["vfov"],
            "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(
                origin=cam["position"], target=cam["look_at"], up=cam["up"]),
            "film": {"type": "hdrfilm", "width": cam["width"], "height": cam["height"],
                     "rfilter": {"type": "box"}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": 1},
        },
    }
    folder = tempfile.mkdtemp(prefix="photonmap-mitsuba-")
    for i, m in enumerate(s["meshes"]):
        path = os.path.join(folder, "mesh%d.ply" % i)
        ply(path, m["vertices"], m["faces"])
        shape = {"type": "ply", "filename": path, "face_normals": True, "bsdf": bsdf(m["material"])}
        if m["material"]["type"] == "emitter":
            shape["emitter"] = {"type": "area", "radiance": rgb(m["material"]["radiance"])}
        scene["mesh%d" % i] = shape
    for i, sp in enumerate(s["spheres"]):
        scene["sphere%d" % i] = {"type": "sphere", "center": sp["center"], "radius": sp["radius"],
                                 "bsdf": bsdf(sp["material"])}
    for i, c in enumerate(s["cylinders"]):
        scene["cylinder%d" % i] = {"type": "cylinder", "p0": c["p0"], "p1": c["p1"],
                                   "radius": c["radius"], "bsdf": bsdf(c["material"])}
    for i, p in enumerate(s["points"]):
        scene["point%d" % i] = {"type": "point", "position": p["position"],
                                "intensity": rgb(p["intensity"])}
    return scene, folder


def main():
    export, budget, out, integrator, variant = sys.argv[1:6]
    checkpoints = sys.argv[6] if len(sys.argv) > 6 else ""
    first_seed = int(sys.argv[7]) if len(sys.argv) > 7 else 0
    budget = float(budget)
    import mitsuba as mi
    mi.set_variant(variant)
    import numpy as np

    s = json.load(open(export))
    cam = s["camera"]
    scene, folder = build_scene(mi, s, integrator)
    t = time.perf_counter()
    loaded = mi.load_dict(scene)
    load_seconds = time.perf_counter() - t
    shutil.rmtree(folder, ignore_errors=True)

    batch = int(s.get("batch", 4))
    pixels = cam["width"] * cam["height"]
    marks = sorted(float(c) for c in checkpoints.split(",") if c) if checkpoints else []
    written = []
    total, spp, seed, paused = None, 0, first_seed, 0.0
    t0 = time.perf_counter()
    while True:
        t1 = time.perf_counter()
        img = np.array(mi.render(loaded, spp=batch, seed=seed), dtype=np.float64)
        total = img * batch if total is None else total + img * batch
        spp += batch
        seed += 1
        # Fewer, larger passes once compiled: a pass's fixed cost is Mitsuba's
        # to save, while one pass still overshoots the budget by little.
        if seed > first_seed + 1 and time.perf_counter() - t1 < min(1.0, budget / 16) and 2 * batch * pixels <= 1 << 25:
            batch *= 2
        elapsed = time.perf_counter() - t0 - paused
        if elapsed >= budget:
            break
        if marks and elapsed >= marks[0]:
            t1 = time.perf_counter()
            while marks and elapsed >= marks[0]:
                marks.pop(0)
            path = "%s_%d.exr" % (out[:-4] if out.endswith(".exr") else out, len(written))
            mi.Bitmap((total / spp).astype(np.float32)).write(path)
            written.append({"seconds": elapsed, "spp": spp, "file": path})
            paused += time.perf_counter() - t1
    seconds = time.perf_counter() - t0 - paused
    mi.Bitmap((total / spp).astype(np.float32)).write(out)
    print(json.dumps({"seconds": seconds, "spp": spp, "load_seconds": load_seconds,
                      "checkpoints": written}))

if __name__ == "__main__":
    main()

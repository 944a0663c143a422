#!/usr/bin/env python3
"""Renders a scene exported by `photonmap bench mitsuba` with Mitsuba 3 for a
wall-clock budget, and writes the image as linear EXR.

Usage: mitsuba_render.py EXPORT.json BUDGET_SECONDS OUT.exr INTEGRATOR VARIANT

The clock starts before the first render call (so Mitsuba's JIT compilation
counts, as a user would wait for it) and stops after the batch that crosses
the budget; importing Mitsuba and loading the scene do not count. Batches of
`batch` samples per pixel with distinct seeds are averaged. Prints one JSON
line: {"seconds": ..., "spp": ..., "load_seconds": ...}.
"""
import json
import os
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
    if m["type"] == "glass":
        return {"type": "dielectric", "int_ior": m["ior"], "ext_ior": 1.0}
    # An emitter reflects nothing.
    return {"type": "diffuse", "reflectance": rgb([0.0, 0.0, 0.0])}


def main():
    export, budget, out, integrator, variant = sys.argv[1:6]
    budget = float(budget)
    import mitsuba as mi
    mi.set_variant(variant)
    import numpy as np

    s = json.load(open(export))
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
    t = time.perf_counter()
    loaded = mi.load_dict(scene)
    load_seconds = time.perf_counter() - t

    batch = int(s.get("batch", 4))
    total, spp, seed = None, 0, 0
    t0 = time.perf_counter()
    while True:
        img = np.array(mi.render(loaded, spp=batch, seed=seed), dtype=np.float64)
        total = img * batch if total is None else total + img * batch
        spp += batch
        seed += 1
        if time.perf_counter() - t0 >= budget:
            break
    seconds = time.perf_counter() - t0
    mi.Bitmap((total / spp).astype(np.float32)).write(out)
    print(json.dumps({"seconds": seconds, "spp": spp, "load_seconds": load_seconds}))


if __name__ == "__main__":
    main()

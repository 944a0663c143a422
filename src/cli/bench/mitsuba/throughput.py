#!/usr/bin/env python3
"""Mitsuba 3's rates on a scene exported by `photonmap bench throughput`:
the `direct` integrator (EMITTER_SAMPLES emitter samples, no BSDF samples)
at SPP samples per pixel, the match for photonmap's direct-light render;
and `ptracer`'s light paths per second at PT_SPP (light paths = PT_SPP x
the film's pixels), the match for photon tracing.

Usage: throughput.py EXPORT.json SPP EMITTER_SAMPLES PT_SPP VARIANT REPEATS

Each render runs once to compile (its time is reported as `first`), then
REPEATS times; the least is reported. Scene loading does not count.
Prints one JSON line.
"""
import json
import os
import shutil
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mitsuba_render  # noqa: E402  (the same scene as `bench mitsuba` renders)


def timed(mi, np, scene, spp, repeats):
    """(first, least) wall seconds of renders at spp, each read back."""
    times = []
    for seed in range(repeats + 1):
        t = time.perf_counter()
        np.array(mi.render(scene, spp=spp, seed=seed))
        times.append(time.perf_counter() - t)
    return times[0], min(times[1:])


def load(mi, s, integrator):
    scene, folder = mitsuba_render.build_scene(mi, s, integrator["type"])
    scene["integrator"] = integrator
    loaded = mi.load_dict(scene)
    shutil.rmtree(folder, ignore_errors=True)
    return loaded


def main():
    export, spp, emitter_samples, pt_spp, variant, repeats = sys.argv[1:7]
    spp, emitter_samples, pt_spp, repeats = int(spp), int(emitter_samples), int(pt_spp), int(repeats)
    import mitsuba as mi
    mi.set_variant(variant)
    import numpy as np

    s = json.load(open(export))
    cam = s["camera"]
    direct = load(mi, s, {"type": "direct", "emitter_samples": emitter_samples, "bsdf_samples": 0})
    direct_first, direct_seconds = timed(mi, np, direct, spp, repeats)
    ptracer = load(mi, s, {"type": "ptracer", "max_depth": s["max_depth"]})
    pt_first, pt_seconds = timed(mi, np, ptracer, pt_spp, repeats)
    print(json.dumps({
        "direct_seconds": direct_seconds,
        "direct_first_seconds": direct_first,
        "ptracer_paths": pt_spp * cam["width"] * cam["height"],
        "ptracer_seconds": pt_seconds,
        "ptracer_first_seconds": pt_first,
    }))


if __name__ == "__main__":
    main()

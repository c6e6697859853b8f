#!/usr/bin/env python3
"""Mitsuba 3 peer of the `luminaire` example (Sik & Krivanek 2013, Fig. 1b).

    python mitsuba_luminaire.py CASE_DIR

CASE_DIR is written by `luminaire --mitsuba`: `mesh.ply` (binary PLY,
x y z u v per vertex, UV with v = 0 at image row 0, triangles whose
counter-clockwise side emits), `texture.exr` (the emission, linear RGB)
and `scene.json` (the receiver image size, the samples per pixel, the
seed). The mesh becomes a Mitsuba `ply` shape with an `area` emitter whose
radiance is a `bitmap` texture (bilinear, clamped, raw); Mitsuba then
samples the emitter by the texture over the UV square and maps the UV to
the surface by a ray cast in UV space (`eval_parameterization`).

For every receiver pixel (the plane z = 0, normal +z, pixel (i, j) over
x in -2 + 4 [i, i+1) / W, y in -1 + 2 [j, j+1) / H) and every sample, a
uniform point of the pixel asks `Scene.sample_emitter_direction(it, u,
test_visibility=False)`: the next-event estimation step of Mitsuba's
`direct` and `path` integrators, without the shadow ray (the example
does not trace one either), which returns Le / pdf in solid angle; the
pixel's irradiance is the mean of that times cos theta at the receiver.

When scene.json says "direct": true (the rectangle, where nothing
occludes), the same scene is also rendered by Mitsuba's own `direct`
integrator (one emitter sample, no BSDF sample, per camera sample): the
receiver is a `rectangle` with a `diffuse` BSDF of albedo 1 seen straight
down by an `orthographic` camera at z = 0.25 (below the luminaire, which
a camera does not occlude) through a box pixel filter, so that pi times a
pixel's radiance is its irradiance averaged over the pixel. That checks
that the NEE step above is what Mitsuba renders.

Writes `mitsuba-<how>-<spp>.f32` (H x W x 3 little-endian float32, row j
of the receiver first; <how> is `nee` or `direct`) per spp and prints one
line per image on stdout: `how=<how> spp=<n> seconds=<s> file=<path>`; on
failure one line `error=<why>` and exit code 1.
"""

import json
import os
import sys
import time


def fail(why):
    print(f"error={why}")
    sys.exit(1)


def luminaire_dict(case):
    """The luminaire: the example's mesh with an area emitter whose
    radiance is the example's texture."""
    return {
        "type": "ply",
        "filename": os.path.join(case, "mesh.ply"),
        "face_normals": True,
        "emitter": {
            "type": "area",
            "radiance": {
                "type": "bitmap",
                "filename": os.path.join(case, "texture.exr"),
                "filter_type": "bilinear",
                "wrap_mode": "clamp",
                "raw": True,
            },
        },
    }


def direct(mi, np, case, meta, spp):
    """Mitsuba's `direct` integrator on a diffuse receiver (albedo 1) seen
    by an orthographic camera: pi x radiance = irradiance, rows flipped so
    that row j is the receiver's (the film's row 0 is y = +1)."""
    width, height = int(meta["width"]), int(meta["height"])
    x0, x1 = meta["receiver_x"]
    y0, y1 = meta["receiver_y"]
    if abs((x1 - x0) / (y1 - y0) - width / height) > 1e-9:
        fail("the direct integrator needs square pixels")
    T = mi.ScalarTransform4f
    half = (x1 - x0) / 2
    scene = mi.load_dict(
        {
            "type": "scene",
            "integrator": {"type": "direct", "emitter_samples": 1, "bsdf_samples": 0},
            "sensor": {
                "type": "orthographic",
                "near_clip": 1e-3,
                "far_clip": 10.0,
                "to_world": T()
                .look_at(
                    origin=[(x0 + x1) / 2, (y0 + y1) / 2, 0.25],
                    target=[(x0 + x1) / 2, (y0 + y1) / 2, -1.0],
                    up=[0, 1, 0],
                )
                @ T().scale([half, half, 1]),
                "film": {
                    "type": "hdrfilm",
                    "width": width,
                    "height": height,
                    "rfilter": {"type": "box"},
                    "pixel_format": "rgb",
                },
                "sampler": {
                    "type": "independent",
                    "sample_count": spp,
                    "seed": int(meta["seed"]),
                },
            },
            "receiver": {
                "type": "rectangle",
                "to_world": T().translate([(x0 + x1) / 2, (y0 + y1) / 2, 0.0])
                @ T().scale([2 * half, 2 * half, 1]),
                "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": 1.0}},
            },
            "luminaire": luminaire_dict(case),
        }
    )
    start = time.perf_counter()
    image = np.array(mi.render(scene), dtype=np.float64) * np.pi
    return image[::-1], time.perf_counter() - start


def main():
    if len(sys.argv) != 2:
        fail("usage: mitsuba_luminaire.py CASE_DIR")
    case = sys.argv[1]
    try:
        import numpy as np
        import mitsuba as mi
    except ImportError as e:
        fail(f"cannot import mitsuba or numpy: {e}")
    try:
        mi.set_variant("scalar_rgb")
    except Exception as e:  # noqa: BLE001 - report any failure as the peer's error
        fail(f"mitsuba variant scalar_rgb: {e}")
    try:
        with open(os.path.join(case, "scene.json")) as f:
            meta = json.load(f)
    except (OSError, ValueError) as e:
        fail(f"{case}/scene.json: {e}")
    width, height = int(meta["width"]), int(meta["height"])
    x0, x1 = meta["receiver_x"]
    y0, y1 = meta["receiver_y"]
    try:
        scene = mi.load_dict({"type": "scene", "luminaire": luminaire_dict(case)})
    except Exception as e:  # noqa: BLE001
        fail(f"mitsuba cannot load {case}: {e}")

    sample_direction = scene.sample_emitter_direction
    for spp in meta["spp"]:
        sampler = mi.load_dict({"type": "independent", "seed": int(meta["seed"])})
        sampler.seed(int(meta["seed"]) + spp)
        rng = np.random.default_rng(int(meta["seed"]) * 1000 + spp)
        jitter = rng.random((height, width, spp, 2))
        image = np.zeros((height, width, 3), dtype=np.float64)
        it = mi.Interaction3f()
        it.t = 0.0
        start = time.perf_counter()
        for j in range(height):
            for i in range(width):
                acc = [0.0, 0.0, 0.0]
                for k in range(spp):
                    fx, fy = jitter[j, i, k]
                    it.p = mi.Point3f(
                        x0 + (x1 - x0) * (i + fx) / width,
                        y0 + (y1 - y0) * (j + fy) / height,
                        0.0,
                    )
                    ds, spec = sample_direction(it, sampler.next_2d(), False)
                    cos = ds.d[2]
                    if cos > 0.0:
                        acc[0] += spec[0] * cos
                        acc[1] += spec[1] * cos
                        acc[2] += spec[2] * cos
                image[j, i] = acc
        seconds = time.perf_counter() - start
        image /= spp
        path = os.path.join(case, f"mitsuba-nee-{spp}.f32")
        image.astype("<f4").tofile(path)
        print(f"how=nee spp={spp} seconds={seconds:.6f} file={path}", flush=True)
    if meta.get("direct"):
        for spp in meta["spp"]:
            try:
                image, seconds = direct(mi, np, case, meta, spp)
            except Exception as e:  # noqa: BLE001
                fail(f"mitsuba's direct integrator: {e}")
            path = os.path.join(case, f"mitsuba-direct-{spp}.f32")
            np.ascontiguousarray(image).astype("<f4").tofile(path)
            print(f"how=direct spp={spp} seconds={seconds:.6f} file={path}", flush=True)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Where a technique is wrong: the per-pixel error of a render against the
CPU reference, in units of the reference's own standard error, as an EXR
(and a PNG heat map with matplotlib), plus the summary `strahl compare` prints.

    PYTHONPATH=build/python python3 examples/python/error_map.py scenes/godrays_window.json \\
        --set toth.samples=16"""
import argparse
import json
import os

import numpy as np
import strahl

ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
ap.add_argument("scene", nargs="?", default="scenes/godrays_window.json")
ap.add_argument("--size", type=int, default=128, help="square image size (default 128)")
ap.add_argument("--spp", type=int, default=64, help="reference samples per pixel (default 64)")
ap.add_argument("--bounces", type=int, default=1, help="reference diffuse bounces (default 1)")
ap.add_argument("--set", action="append", default=[], metavar="MODULE.PARAM=VALUE")
ap.add_argument("--out", default="out/error_map", help="output folder (default out/error_map)")
args = ap.parse_args()
os.makedirs(args.out, exist_ok=True)


def value(v):
    """A --set value as Python: a number if it reads as one, else the word."""
    for conv in (int, float):
        try:
            return conv(v)
        except ValueError:
            pass
    return {"true": True, "false": False}.get(v, v)


sets = {k: value(v) for k, v in (a.split("=", 1) for a in args.set)}
size = (args.size, args.size)
img = strahl.render(args.scene, size=size, set=sets)
ref, ref_se = strahl.reference(args.scene, size=size, spp=args.spp, bounces=args.bounces)
metrics = strahl.compare(img, ref, stderr=ref_se)

# |a - b| per pixel (mean over R, G, B), and the same in standard errors of
# the reference: values well above 3 are the technique's error, not noise.
diff = np.abs(img - ref).mean(axis=2)
z = diff / np.maximum(ref_se.mean(axis=2), 1e-12)
strahl.write_exr(os.path.join(args.out, "error.exr"), np.repeat(diff[:, :, None], 3, axis=2))
strahl.write_exr(os.path.join(args.out, "render.exr"), img)
strahl.write_exr(os.path.join(args.out, "reference.exr"), ref, ref_se)
print(json.dumps({k: metrics[k] for k in ("rmse", "rmse_debiased", "relmse_debiased", "scale")
                  if k in metrics}, indent=1))
print(f"pixels beyond 3 standard errors: {np.mean(z > 3):.1%}")
try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5, 4))
    im = ax.imshow(diff, cmap="inferno")
    fig.colorbar(im, ax=ax, label="|render - reference| (mean over R, G, B)")
    ax.set_title(os.path.basename(args.scene))
    fig.savefig(os.path.join(args.out, "error.png"), dpi=100)
except ImportError:
    pass  # the EXRs are the result; the PNG is a convenience
print(f"wrote {args.out}/error.exr, render.exr, reference.exr")

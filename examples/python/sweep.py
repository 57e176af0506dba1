#!/usr/bin/env python3
"""A two-parameter sweep of toth against the CPU reference: the error of every
(samples, interleave) setting, plotted with matplotlib if it is installed,
written as a CSV otherwise (or with --csv).

    PYTHONPATH=build/python python3 examples/python/sweep.py scenes/godrays_window.json

One World renders every setting (parameters change in place); the reference
is rendered once. For timings as well, strahl.bench does the same sweep
with `strahl bench`'s rows."""
import argparse
import csv
import os
import time

import strahl

ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
ap.add_argument("scene", nargs="?", default="scenes/godrays_window.json")
ap.add_argument("--size", type=int, default=128, help="square image size (default 128)")
ap.add_argument("--spp", type=int, default=64, help="reference samples per pixel (default 64)")
ap.add_argument("--samples", default="8,16,32,64", help="toth.samples values")
ap.add_argument("--interleave", default="1,2,4", help="toth.interleave values")
ap.add_argument("--out", default="out/sweep", help="output folder (default out/sweep)")
ap.add_argument("--csv", action="store_true", help="write the CSV even with matplotlib")
args = ap.parse_args()
samples = [int(v) for v in args.samples.split(",")]
interleave = [int(v) for v in args.interleave.split(",")]
os.makedirs(args.out, exist_ok=True)
size = (args.size, args.size)

ref, ref_se = strahl.reference(args.scene, size=size, spp=args.spp, bounces=0)
rows = []
with strahl.World(args.scene, size=size) as world:
    for il in interleave:
        for s in samples:
            world.set("toth.samples", s)
            world.set("toth.interleave", il)
            t0 = time.perf_counter()
            img = world.still()
            secs = time.perf_counter() - t0
            m = strahl.compare(img, ref, stderr=ref_se)
            rows.append({"samples": s, "interleave": il, "rmse": m["rmse_debiased"]["all"],
                         "rmse_raw": m["rmse"]["all"], "still_s": secs})
            print(f"samples={s:4d} interleave={il}: rmse {rows[-1]['rmse']:.5g}")

try:
    if args.csv:
        raise ImportError
    import matplotlib
    matplotlib.use("Agg")  # headless: the picture goes to a file
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    for il in interleave:
        pts = [r for r in rows if r["interleave"] == il]
        ax.loglog([r["samples"] for r in pts], [r["rmse"] for r in pts], "o-",
                  label=f"interleave {il}")
    ax.set_xlabel("toth.samples")
    ax.set_ylabel("RMSE against the reference (debiased)")
    ax.set_title(os.path.basename(args.scene))
    ax.legend()
    path = os.path.join(args.out, "sweep.png")
    fig.savefig(path, dpi=100)
except ImportError:
    path = os.path.join(args.out, "sweep.csv")
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
print(f"wrote {path}")

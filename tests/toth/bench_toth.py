#!/usr/bin/env python3
"""Benchmark of toth's uniform march for the lead's note (not a test; the
equi-angular default is benchmarked by tools/bench_all.sh).

Median frame time at 512x512 of every god-ray scene over samples 8..128 at
full resolution, interleaved (M = 2, 4), at half and quarter resolution, and
the error against a 512-sample full-resolution march, measured with the
documented commands:

    strahl render SCENE --set toth.X=Y ... --stats=json --frames 20 -o OUT.exr
    strahl compare OUT.exr REF.exr --json

Besides the wall-clock median that --stats reports, the CPU time of the
render process is recorded (getrusage of the child, 20 frames minus 1 frame,
per frame): on llvmpipe the GPU is the CPU, so CPU time is the work done and
does not change when other processes share the cores, while wall-clock time
does. toth's share is the frame minus the same scene without scattering
(where toth does not run).

usage: bench_toth.py BUILD_DIR OUT_DIR [--frames N] [--scenes a,b,...] [--extra]
                    [--only MODE:N,MODE:N,...]
Writes OUT_DIR/toth_bench.csv and prints it.
"""
import argparse
import csv
import json
import os
import resource
import subprocess
import sys

SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
SCENES = ["window", "colonnade", "hidden_hole", "light_front"]
# mode: (interleave, resolution, jitter, sample counts)
MODES = [
    ("full", 1, "full", True, [8, 16, 32, 64, 128]),
    ("full_nojitter", 1, "full", False, [128]),
    ("i2", 2, "full", True, [8, 16, 32, 64, 128]),
    ("i4", 4, "full", True, [16, 32, 64, 128]),
    ("half", 1, "half", True, [8, 16, 32, 64, 128]),
    ("half_i2", 2, "half", True, [8, 16, 32, 64, 128]),
    ("quarter", 1, "quarter", True, [8, 16, 32, 64, 128]),
]
# Beyond the 8..128 sweep (--extra): reduced work per pixel with more steps.
EXTRA = [
    ("i2", 2, "full", True, [256]),
    ("half_i2", 2, "half", True, [192, 256]),
    ("quarter", 1, "quarter", True, [256]),
]


def run(cmd):
    """Runs cmd; returns (stdout, CPU seconds of the child)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        sys.exit("failed (%d): %s\n%s" % (p.returncode, " ".join(cmd), p.stderr))
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return p.stdout, cpu


def render(strahl, scene, out, frames, sets):
    cmd = [strahl, "render", scene, "-o", out, "--size", "512x512", "--stats=json", "--frames", str(frames)]
    for k, v in sets.items():
        cmd += ["--set", "toth.%s=%s" % (k, v)]
    text, cpu = run(cmd)
    return json.loads(text), cpu


def measure(strahl, scene, out, frames, sets):
    """Wall median (ms), toth GPU-timer sum (ms), CPU ms per frame."""
    stats, cpu_n = render(strahl, scene, out, frames, sets)
    _, cpu_1 = render(strahl, scene, out + ".1.exr", 1, sets)
    os.remove(out + ".1.exr")
    gpu = sum(p["gpu_ms_median"] for p in stats["passes"] if p["module"] == "toth")
    return stats["frame_ms_median"], gpu, 1000.0 * (cpu_n - cpu_1) / (frames - 1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("build")
    ap.add_argument("out")
    ap.add_argument("--frames", type=int, default=20)
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--extra", action="store_true", help="also the EXTRA settings")
    ap.add_argument("--only", default="", help="only these MODE:N of the sweep (full:128 is always run)")
    a = ap.parse_args()
    only = set(a.only.split(",")) if a.only else None
    modes = MODES + (EXTRA if a.extra else [])
    strahl = os.path.join(a.build, "bin", "strahl")
    os.environ["STRAHL_MODULE_PATH"] = os.path.join(a.build, "modules")
    os.environ["STRAHL_SHADER_PATH"] = os.path.join(SRC, "shaders")
    os.makedirs(a.out, exist_ok=True)
    rows = []
    for name in a.scenes.split(","):
        scene = os.path.join(SRC, "scenes", "godrays_%s.json" % name)
        ref = os.path.join(a.out, "%s_ref512.exr" % name)
        render(strahl, scene, ref, 1, {"sampling": "uniform", "samples": 512, "interleave": 1, "resolution": "full",
                                       "jitter": "true"})
        # The same frame without scattering: toth does not run.
        d = json.load(open(scene))
        d["medium"]["sigma_s"] = [0, 0, 0]
        base_scene = os.path.join(a.out, "%s_nomedium.json" % name)
        json.dump(d, open(base_scene, "w"))
        base_wall, _, base_cpu = measure(strahl, base_scene, os.path.join(a.out, "base.exr"), a.frames, {})
        scene_rows = []
        for mode, il, res, jit, counts in modes:
            for n in counts:
                extra = (mode, il, res, jit, counts) in EXTRA
                if only is not None and not extra and "%s:%d" % (mode, n) not in only | {"full:128"}:
                    continue
                img = os.path.join(a.out, "%s_%s_%d.exr" % (name, mode, n))
                sets = {"sampling": "uniform", "samples": n, "interleave": il, "resolution": res,
                        "jitter": "true" if jit else "false"}
                wall, gpu, cpu = measure(strahl, scene, img, a.frames, sets)
                cmp, _ = run([strahl, "compare", img, ref, "--json"])
                m = json.loads(cmp)
                r = {"scene": name, "mode": mode, "samples": n, "interleave": il, "resolution": res,
                     "jitter": jit, "frame_ms": round(wall, 1), "toth_ms": round(wall - base_wall, 1),
                     "toth_gpu_ms": round(gpu, 1), "frame_cpu_ms": round(cpu, 1),
                     "toth_cpu_ms": round(cpu - base_cpu, 1), "rmse": m["rmse"]["all"],
                     "relmse": m["relmse"]["all"]}
                scene_rows.append(r)
                print(",".join(str(v) for v in r.values()), file=sys.stderr, flush=True)
        full = next(r for r in scene_rows if r["mode"] == "full" and r["samples"] == 128)
        for r in scene_rows:
            r["rmse_vs_full128"] = round(r["rmse"] / full["rmse"], 3)
            r["cpu_vs_full128"] = round(r["toth_cpu_ms"] / full["toth_cpu_ms"], 3)
        rows += scene_rows
    path = os.path.join(a.out, "toth_bench.csv")
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    print(open(path).read())


if __name__ == "__main__":
    main()

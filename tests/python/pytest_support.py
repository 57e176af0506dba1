"""What the Python module's tests share: arguments, a small scene, the CLI."""
import json
import os
import subprocess
import sys

import numpy as np
import strahl

CLI, SRC, SCRATCH = sys.argv[1], sys.argv[2], sys.argv[3]
failures = []


def check(cond, what):
    """Records a failed invariant (never skipped, unlike assert under -O)."""
    print(("ok    " if cond else "FAIL  ") + what)
    if not cond:
        failures.append(what)


def finish():
    if failures:
        print(f"{len(failures)} check(s) failed")
        sys.exit(1)


def scene_variant(name, drop=("atlas_gi",), camera=None):
    """scenes/cornell.json without the costly atlas_gi precompute (64 px stays
    cheap), optionally with camera keys replaced; returns its path."""
    with open(os.path.join(SRC, "scenes", "cornell.json")) as f:
        s = json.load(f)
    s["modules"] = [m for m in s["modules"] if m["name"] not in drop]
    s["camera"].update(camera or {})
    path = os.path.join(SCRATCH, name + ".json")
    with open(path, "w") as f:
        json.dump(s, f)
    return path


def cli_render(scene, out, *args):
    """`strahl render` to an EXR; returns its R, G, B."""
    path = os.path.join(SCRATCH, out)
    subprocess.run([CLI, "render", scene, "-o", path, *args], check=True,
                   stdout=subprocess.DEVNULL)
    return strahl.read_exr(path)[0]


def cli_error(*args):
    """The one-line message the CLI prints for a failing command (without
    its "strahl CMD: " prefix) and its exit code."""
    p = subprocess.run([CLI, *args], capture_output=True, text=True)
    line = p.stderr.strip().splitlines()[-1]
    return line.split(": ", 1)[1], p.returncode


def identical(a, b):
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


__all__ = ["np", "strahl", "check", "finish", "scene_variant", "cli_render", "cli_error",
           "identical", "CLI", "SRC", "SCRATCH"]

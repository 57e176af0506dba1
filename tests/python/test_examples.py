"""examples/python run headless on a small scene and write what they say."""
import csv
import math
import os
import subprocess
import sys

from pytest_support import *

small = scene_variant("small")
ex = os.path.join(SRC, "examples", "python")
env = dict(os.environ, MPLBACKEND="Agg")


def run(script, *args):
    p = subprocess.run([sys.executable, os.path.join(ex, script), small, "--size", "16", "--spp",
                        "2", *args], capture_output=True, text=True, env=env)
    check(p.returncode == 0, f"{script} runs (stderr {p.stderr[-300:]!r})")


out = os.path.join(SCRATCH, "sweep")
run("sweep.py", "--samples", "8,16", "--interleave", "1,2", "--csv", "--out", out)
with open(os.path.join(out, "sweep.csv")) as f:
    rows = list(csv.DictReader(f))
check([(r["samples"], r["interleave"]) for r in rows] ==
      [("8", "1"), ("16", "1"), ("8", "2"), ("16", "2")], "sweep.csv: every setting")
check(all(math.isfinite(float(r["rmse"])) and 0 <= float(r["rmse"]) <= float(r["rmse_raw"])
          for r in rows), "sweep.csv: debiased rmse in [0, raw rmse]")

out = os.path.join(SCRATCH, "error_map")
run("error_map.py", "--set", "toth.samples=16", "--out", out)
img = strahl.read_exr(os.path.join(out, "render.exr"))[0]
check(identical(img, strahl.render(small, size=(16, 16), set={"toth.samples": 16})),
      "error_map's render.exr is strahl.render's image")
err = strahl.read_exr(os.path.join(out, "error.exr"))[0]
ref, se = strahl.read_exr(os.path.join(out, "reference.exr"))
check(se is not None and np.allclose(err[:, :, 0], np.abs(img - ref).mean(axis=2)),
      "error.exr is |render - reference|")
finish()

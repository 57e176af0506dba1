"""strahl.render, reference, compare and modules against the command line:
the same arguments give bit-identical images and the same numbers."""
import json
import os
import subprocess
import sys
import threading

from pytest_support import *

cornell = os.path.join(SRC, "scenes", "cornell.json")
small = scene_variant("small")
bare = scene_variant("bare", drop=("atlas_gi", "toth"))

# The case: every module of cornell, point filter.
a = strahl.render(cornell, size=(64, 64), filter="point")
check(a.shape == (64, 64, 3) and a.dtype == np.float32, "render shape (64, 64, 3) float32")
check(identical(a, cli_render(cornell, "cornell.exr", "--size", "64x64", "--filter", "point")),
      "cornell point: bit-identical to strahl render's EXR")

# The default (box) filter runs to convergence, and an exact frame count.
check(identical(strahl.render(small, size=(64, 64)),
                cli_render(small, "box.exr", "--size", "64x64")), "box: bit-identical")
check(identical(strahl.render(small, size=(64, 64), frames=3),
                cli_render(small, "f3.exr", "--size", "64x64", "--frames", "3")),
      "frames=3: bit-identical to --frames 3")

# set= is --set; enable/disable switch modules in the running world.
p0 = strahl.render(small, size=(64, 64), filter="point")
p1 = strahl.render(small, size=(64, 64), filter="point", set={"shadow_map.pcf": True})
check(not identical(p0, p1), "set shadow_map.pcf=True changes the image")
check(identical(p1, cli_render(small, "pcf.exr", "--size", "64x64", "--filter", "point",
                               "--set", "shadow_map.pcf=true")), "set: bit-identical to --set")
d = strahl.render(small, size=(64, 64), filter="point", disable=["toth"])
check(identical(d, cli_render(bare, "bare.exr", "--size", "64x64", "--filter", "point")),
      "disable=['toth'] equals the scene without toth")
e = strahl.render(bare, size=(64, 64), filter="point", enable=["toth"])
check(identical(e, p0), "enable=['toth'] equals the scene with toth")

# The GIL is released while rendering: another thread keeps running.
count, done = 0, threading.Event()
t = threading.Thread(target=lambda: (strahl.render(small, size=(64, 64), filter="point"),
                                     done.set()))
t.start()
while not done.is_set():
    count += 1
t.join()
check(count > 1000, f"another thread ran during render ({count} iterations)")

# Nothing is printed from inside.
code = f"import strahl; strahl.render({small!r}, size=(16, 16), filter='point')"
p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
check(p.returncode == 0 and p.stdout == "" and p.stderr == "",
      f"render prints nothing (stdout {p.stdout!r}, stderr {p.stderr[:200]!r})")

# reference: image and standard error as `strahl reference` writes them.
img, se = strahl.reference(small, size=(16, 16), spp=4, seed=3)
ref = os.path.join(SCRATCH, "ref.exr")
subprocess.run([CLI, "reference", small, "--size", "16x16", "--spp", "4", "--seed", "3", "-o",
                ref], check=True, stdout=subprocess.DEVNULL)
r_img, r_se = strahl.read_exr(ref)
check(identical(img, r_img) and identical(se, r_se), "reference: image and stderr bit-identical")

# compare: the numbers `strahl compare --json` prints (psnr inf is its null).
lo = os.path.join(SCRATCH, "lo.exr")
subprocess.run([CLI, "render", small, "-o", lo, "--size", "16x16", "--filter", "box"],
               check=True, stdout=subprocess.DEVNULL)
cli = json.loads(subprocess.run([CLI, "compare", lo, ref, "--json"], capture_output=True,
                                text=True, check=True).stdout)


def close(x, y):  # the JSON has 9 significant digits
    return x == y if isinstance(y, (bool, int)) else abs(x - y) <= 1e-8 * abs(y)


for m in (strahl.compare(lo, ref), strahl.compare(strahl.read_exr(lo)[0], r_img, stderr=r_se)):
    same = all(close(m[k], v) if not isinstance(v, dict) else
               all(close(m[k][c], x) for c, x in v.items() if x is not None)
               for k, v in cli.items())
    check(same and set(m) == set(cli), "compare: the same metrics as strahl compare --json")

# bench: the rows `strahl bench` writes (its timings aside).
ref16 = os.path.join(SCRATCH, "ref16.exr")
subprocess.run([CLI, "reference", small, "--size", "16x16", "--spp", "2", "-o", ref16],
               check=True, stdout=subprocess.DEVNULL)
csv_path = os.path.join(SCRATCH, "bench.csv")
subprocess.run([CLI, "bench", small, "--reference", ref16, "--sweep", "toth.samples=8,16",
                "--size", "16x16", "--frames", "1", "--warmup", "0", "--csv", csv_path],
               check=True, capture_output=True)
rows = strahl.bench(small, ref16, {"toth.samples": [8, 16]}, size=(16, 16), frames=1, warmup=0)
with open(csv_path) as f:
    import csv
    cli_rows = list(csv.DictReader(f))
timing = {"frame_ms_median", "module_gpu_ms_median", "module_cpu_ms_median", "pass_gpu_ms",
          "peak_rss_kb"}
check(len(rows) == 2 and all(set(r) == set(c) and all(str(r[k]) == c[k] or float(r[k]) ==
                                                      float(c[k]) for k in c if k not in timing)
                             for r, c in zip(rows, cli_rows)),
      "bench: the CSV's columns and values (timings aside)")

# modules: the descriptors `strahl modules --json` lists.
cli = json.loads(subprocess.run([CLI, "modules", "--json"], capture_output=True, text=True,
                                check=True).stdout)
mods = strahl.modules()
check([m["name"] for m in mods] == [m["name"] for m in cli], "modules: the same plugins")
ok = True
for m, c in zip(mods, cli):
    ok &= all(m[k] == c[k] for k in ("description", "requires", "provides", "lights", "abi"))
    for p, q in zip(m["params"], c["params"]):
        ok &= p["name"] == q["name"] and p["type"] == q["type"] and p["help"] == q["help"]
        ok &= p["default"] == q["default"] and (p["range"] is None) == ("min" not in q)
        ok &= p["range"] is None or p["range"] == (q["min"], q["max"])
        ok &= p["choices"] is None or "|".join(p["choices"]) == q["choices"]
check(ok, "modules: every parameter's type, default, range, choices and help")
finish()

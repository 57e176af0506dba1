"""strahl.World: camera and light moves equal the command line's render of
the moved scene; parameters, modules, stats, closing; no leak over frames."""
from pytest_support import *

small = scene_variant("small")
moved_cam = {"position": [0.3, 1.1, 3.2], "target": [0.05, 0.95, 0], "fov_y": 45}
moved = scene_variant("moved", camera=moved_cam)
size = ["--size", "64x64"]

# Camera: moved after frames at the old pose, point and box filter.
for flt in ("point", "box"):
    with strahl.World(small, size=(64, 64), filter=flt) as w:
        w.frame()
        w.frame()
        w.camera(position=moved_cam["position"], target=moved_cam["target"], fov_y=45)
        img = w.still()
    cli = cli_render(moved, f"moved_{flt}.exr", *size, "--filter", flt)
    check(identical(img, cli), f"World camera move ({flt}): bit-identical to the CLI's render")

# Light: position and intensity of light 0.
import json, os  # noqa: E401 (only here)
with open(small) as f:
    s = json.load(f)
s["lights"][0].update(position=[0.2, 1.7, 0.1], intensity=[2, 3, 4])
lit = os.path.join(SCRATCH, "lit.json")
with open(lit, "w") as f:
    json.dump(s, f)
with strahl.World(small, size=(64, 64), filter="point") as w:
    w.frame()
    w.light(0, position=(0.2, 1.7, 0.1), intensity=(2, 3, 4))
    img = w.still()
check(identical(img, cli_render(lit, "lit.exr", *size, "--filter", "point")),
      "World light move: bit-identical to the CLI's render of the moved light")

# Parameters and modules in a running world, stats.
with strahl.World(small, size=(64, 64), filter="point") as w:
    base = w.still()
    w.set("shadow_map.pcf", True)
    pcf = w.still()
    check(identical(pcf, cli_render(small, "pcf.exr", *size, "--filter", "point", "--set",
                                    "shadow_map.pcf=true")), "World.set: equals --set")
    w.set("shadow_map.pcf", False)
    check(identical(w.still(), base), "World.set back: the first image again")
    w.disable("toth")
    no_toth = w.still()
    w.enable("toth")
    check(identical(w.still(), base) and not identical(no_toth, base),
          "World.disable/enable toth: changes the image, and back")
    st = w.stats()
    passes = {(p["module"], p["pass"]): p for p in st["passes"]}
    check(("toth", "march") in passes and passes[("world", "regular")]["runs"] >= 5,
          f"stats: per-pass runs ({len(passes)} passes)")
    check(st["gpu_bytes"] > 64 * 64 * 16 and st["converged"] and st["error"] >= 0,
          f"stats: GPU bytes {st['gpu_bytes']}, error {st['error']}")
try:
    w.frame()
    check(False, "the World is closed after the with block")
except strahl.Error:
    check(True, "the World is closed after the with block")


# Frames in a loop do not leak: RSS after 200 frames within 10 % of that
# after 20 (toth off so that frames are cheap; the camera moves every frame
# so the regular pass reruns).
def rss_kb():
    with open("/proc/self/status") as f:
        return next(int(l.split()[1]) for l in f if l.startswith("VmRSS"))


with strahl.World(small, size=(64, 64), filter="point", disable=["toth"]) as w:
    for i in range(200):
        w.camera(position=(0.001 * (i % 7), 1, 3.4))
        w.frame()
        if i == 19:
            r20 = rss_kb()
    r200 = rss_kb()
check(r200 <= 1.1 * r20, f"RSS after 200 frames {r200} kB, after 20 {r20} kB (<= +10 %)")
finish()

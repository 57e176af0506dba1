"""`cmake --install` into a fresh prefix: the module lands in the prefix's
site directory and, with no build-tree paths in the environment, finds
libstrahl, the plugins and the shaders of the prefix; its image equals the
build tree's."""
import glob
import os
import shutil
import subprocess
import sys

from pytest_support import *

build = os.path.dirname(os.path.dirname(strahl.__file__))  # build/python/.. = build
prefix = os.path.join(SCRATCH, "prefix")
shutil.rmtree(prefix, ignore_errors=True)
p = subprocess.run(["cmake", "--install", build, "--prefix", prefix], capture_output=True,
                   text=True)
check(p.returncode == 0, f"cmake --install (stderr {p.stderr[-300:]!r})")
found = glob.glob(os.path.join(prefix, "lib", "python3*", "*-packages", "strahl.*.so"))
check(len(found) == 1, f"the module is in the prefix's site directory ({found})")
bare = scene_variant("bare", drop=("atlas_gi",))
out = os.path.join(SCRATCH, "installed.exr")
env = {k: v for k, v in os.environ.items() if not k.startswith("STRAHL_") and k != "PYTHONPATH"}
env["PYTHONPATH"] = os.path.dirname(found[0]) if found else ""
code = ("import strahl, sys\n"
        f"img = strahl.render({bare!r}, size=(16, 16), filter='point')\n"
        f"strahl.write_exr({out!r}, img)\nprint(strahl.__file__)\n")
p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                   cwd=SCRATCH)
check(p.returncode == 0 and p.stdout.startswith(prefix),
      f"the installed module imports and renders ({p.stdout.strip()!r} {p.stderr[-300:]!r})")
if p.returncode == 0:
    check(identical(strahl.read_exr(out)[0],
                    strahl.render(bare, size=(16, 16), filter="point")),
          "its image equals the build tree's")
finish()

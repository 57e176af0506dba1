"""Each error path: bad input raises strahl.Error (a ValueError) with the
command line's one-line message, runtime failures strahl.RenderError (a
RuntimeError); nothing crashes."""
import os
import shutil
import subprocess
import sys

from pytest_support import *

small = scene_variant("small")
out = os.path.join(SCRATCH, "x.exr")


def raises(kind, fn, *args, **kw):
    """The message of the exception fn raises (None if it raised none or another kind)."""
    try:
        fn(*args, **kw)
    except kind as e:
        return str(e)
    except Exception as e:  # noqa: BLE001 (the wrong kind is the failure reported)
        print(f"      raised {type(e).__name__}: {e}")
    return None


check(issubclass(strahl.Error, ValueError), "strahl.Error is a ValueError")
check(issubclass(strahl.RenderError, RuntimeError), "strahl.RenderError is a RuntimeError")

# Render errors with the CLI's message for the same arguments.
cases = [
    ({"set": {"toth.no_such_param": 1}}, ["--set", "toth.no_such_param=1"]),
    ({"set": {"nomod.x": 1}}, ["--set", "nomod.x=1"]),
    ({"set": {"toth.samples": -3}}, ["--set", "toth.samples=-3"]),
    ({"set": {"shadow_map.pcf": "maybe"}}, ["--set", "shadow_map.pcf=maybe"]),
]
for kw, flags in cases:
    msg = raises(strahl.Error, strahl.render, small, size=(16, 16), **kw)
    want, rc = cli_error("render", small, "-o", out, "--size", "16x16", *flags)
    check(msg == want and rc == 2, f"render {kw}: strahl.Error {msg!r} (CLI: {want!r})")
msg = raises(strahl.Error, strahl.render, small, size=(16, 16), set={"toth.no_such_param": 1})
check(msg is not None and "no_such_param" in msg, "the message names the parameter")
missing = os.path.join(SCRATCH, "no_such_scene.json")
msg = raises(strahl.Error, strahl.render, missing)
check(msg == cli_error("render", missing, "-o", out)[0], f"missing scene: {msg!r}")
broken = os.path.join(SCRATCH, "broken.json")
with open(broken, "w") as f:
    f.write('{"camera": [1, 2')
msg = raises(strahl.Error, strahl.render, broken)
check(msg == cli_error("render", broken, "-o", out)[0], f"broken scene: {msg!r}")

# Arguments the module checks itself.
for kw in ({"size": (0, 16)}, {"size": (16,)}, {"size": "16x16"}, {"filter": "gauss"},
           {"frames": 0}, {"set": {"toth.samples": [1, 2]}}, {"enable": ["no_such_module"]},
           {"disable": ["no_such_module"]}):
    msg = raises(strahl.Error, strahl.render, small, **kw)
    check(msg is not None, f"render {kw}: strahl.Error {msg!r}")
check(raises(TypeError, strahl.render, small, set=[1]) is not None, "set= not a dict: TypeError")
check(raises(strahl.Error, strahl.reference, small, spp=0) is not None, "reference spp=0")
check(raises(strahl.Error, strahl.reference, small, aov="x") is not None, "reference aov='x'")
check(raises(strahl.Error, strahl.reference, small, bounces=17) is not None, "reference bounces")

# compare: sizes that differ, a file that is not there.
a, b = np.zeros((4, 4, 3), np.float32), np.zeros((4, 5, 3), np.float32)
msg = raises(strahl.Error, strahl.compare, a, b)
check(msg is not None and msg.startswith("a vs b: "), f"compare sizes: {msg!r}")
msg = raises(strahl.Error, strahl.compare, missing, missing)
check(msg == cli_error("compare", missing, missing)[0], f"compare missing file: {msg!r}")
check(raises(strahl.Error, strahl.compare, np.zeros((4, 4)), a) is not None, "compare 2-D array")

# World: parameters, lights, camera, filters, a closed world.
w = strahl.World(small, size=(16, 16), filter="point")
check(raises(strahl.Error, w.set, "toth.no_such_param", 1) is not None, "World.set unknown")
check(raises(strahl.Error, w.set, "toth.samples", -3) is not None, "World.set out of range")
check(raises(strahl.Error, w.set, "nomod.x", 1) is not None, "World.set unknown module")
check(raises(strahl.Error, w.light, 7, position=(0, 1, 0)) is not None, "World.light index")
check(raises(strahl.Error, w.camera, fov_y=0) is not None, "World.camera fov_y=0")
check(raises(strahl.Error, w.camera, position=(0, 1)) is not None, "World.camera 2-vector")
check(raises(strahl.Error, w.still, filter="box") is not None, "World.still other filter")
check(raises(strahl.Error, w.enable, "no_such_module") is not None, "World.enable unknown")
w.close()
check(raises(strahl.Error, w.frame) is not None, "frame() of a closed World")
check(raises(strahl.Error, strahl.World, missing) is not None, "World of a missing scene")

# In a child process: a shader that does not compile (input, as the CLI
# says) and no GL context at all (runtime).
bad = os.path.join(SCRATCH, "bad_shaders")
shutil.rmtree(bad, ignore_errors=True)
shutil.copytree(os.path.join(SRC, "shaders"), bad)
with open(os.path.join(bad, "common", "lighting.glsl"), "a") as f:
    f.write("this is not glsl\n")
for env, kind, code in ((("STRAHL_SHADER_PATH", bad), "Error", 2),
                        (("__EGL_VENDOR_LIBRARY_FILENAMES", "/nonexistent.json"), "RenderError",
                         1)):
    e = dict(os.environ, **{env[0]: env[1]})
    prog = (f"import strahl\ntry:\n    strahl.render({small!r}, size=(16, 16))\n"
            f"except strahl.{kind} as e:\n    print(e)\n")
    p = subprocess.run([sys.executable, "-c", prog], capture_output=True, text=True, env=e)
    c = subprocess.run([CLI, "render", small, "-o", out, "--size", "16x16"], capture_output=True,
                       text=True, env=e)
    want = c.stderr.split(": ", 1)[1].strip() if ": " in c.stderr else None
    check(p.returncode == 0 and p.stdout.strip() == want and c.returncode == code,
          f"{env[0]}: strahl.{kind} {p.stdout.strip()[:120]!r} {p.stderr[-300:]!r}")
finish()

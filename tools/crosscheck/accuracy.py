#!/usr/bin/env python3
"""Regenerates docs/accuracy.md: every case of the Cycles cross-check suite
(tests/data/crosscheck/cases.txt) rendered with `strahl reference` and with
each applicable GPU plugin at its default parameters, compared with the
committed Cycles image (relMSE, NRMSE) and timed.

    tools/crosscheck/accuracy.py [--build build] [--out docs/accuracy.md] [CASE...]

Uses only the strahl binaries of a release build and the committed files;
Blender is not needed. Applicable plugins: the scene's own module list, and
for the bounce cases also ssgi in place of atlas_gi (the same bounce from
screen space). The reference's and the modules' errors are those the test
prints (build/tests/crosscheck/test_crosscheck CASE KIND FILTER, each case
with its filter from cases.txt), so the table is what the suite asserts; ssgi
is a `strahl render` still compared by `strahl compare`. Times: the median
frame of a 9-frame `strahl render --stats` at the case's size and filter.
Cases marked `manual` run only when named.

Named cases: only their rows are re-measured; the table's other rows stay as
they are, and a note after the table says which rows which run measured (so
rows can be refreshed one case at a time after a change). The text around
the table is the document's own, hand-written, and is kept as it is."""
import argparse
import json
import os
import platform
import re
import subprocess
import sys
import tempfile
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
DATA = os.path.join(ROOT, "tests", "data", "crosscheck")
# The reference's settings, the same as tests/crosscheck/test_crosscheck.c.
REF_OPTS = {"direct": ["--bounces", "0", "--spp", "1"],
            "bounce": ["--bounces", "1", "--spp", "256"],
            "medium": ["--bounces", "0", "--spp", "64", "--steps", "16"],
            "fog": ["--bounces", "0", "--spp", "64", "--steps", "16"]}
# Box-filtered cases: as the test renders them (stratified over the pixel).
REF_OPTS_BOX = {"direct": ["--bounces", "0", "--spp", "64", "--filter", "box"],
                "bounce": ["--bounces", "1", "--spp", "256", "--filter", "box"],
                "medium": ["--bounces", "0", "--spp", "64", "--steps", "16", "--filter", "box"],
                "fog": ["--bounces", "0", "--spp", "64", "--steps", "16", "--filter", "box"]}
FRAMES = 9


def run(cmd, env):
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if p.returncode != 0:
        sys.exit("accuracy: %s failed (%d):\n%s%s" % (" ".join(cmd), p.returncode, p.stdout, p.stderr))
    return p.stdout


def compare(strahl, a, b, env):
    m = json.loads(run([strahl, "compare", a, b, "--json"], env))
    mean_b = m["mean_b"]["all"]
    return m["relmse"]["all"], (m["rmse"]["all"] / mean_b if mean_b > 0 else float("inf"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "accuracy.md"))
    ap.add_argument("cases", nargs="*", help="only these cases (default: all)")
    args = ap.parse_args()
    strahl = os.path.join(args.build, "bin", "strahl")
    env = dict(os.environ)
    env.setdefault("STRAHL_MODULE_PATH", os.path.join(args.build, "modules"))
    env.setdefault("STRAHL_SHADER_PATH", os.path.join(ROOT, "shaders"))
    cases, all_cases = [], []
    known = set()
    with open(os.path.join(DATA, "cases.txt")) as f:
        for line in f:
            if re.match(r"^[a-z]", line):
                f4 = line.split()
                name, kind = f4[0], f4[1]
                filt = f4[3] if len(f4) > 3 else "point"
                all_cases.append((name, kind, filt))
                known.add(name)
                if len(f4) > 4 and f4[4] == "manual" and name not in args.cases:
                    continue  # too slow for the table's run (see the text below)
                if not args.cases or name in args.cases:
                    cases.append((name, kind, filt))
    unknown = [c for c in args.cases if c not in known]
    if unknown:
        print("accuracy: not in tests/data/crosscheck/cases.txt: %s" % ", ".join(unknown),
              file=sys.stderr)
        sys.exit(2)
    rows = []
    renderer = "?"
    test = os.path.join(args.build, "tests", "crosscheck", "test_crosscheck")
    with tempfile.TemporaryDirectory() as tmp:
        for name, kind, filt in cases:
            scene = os.path.join(DATA, name + ".json")
            cyc = os.path.join(DATA, name + ".cycles.exr")
            with open(os.path.join(DATA, name + ".cycles.json")) as f:
                info = json.load(f)
            cyinfo = "%.0f s (2 seeds x %d spp), noise NRMSE %.2g" % (
                sum(info["render_seconds"]), info["spp"], info["relative_rms_standard_error"])
            with open(scene) as f:
                sc = json.load(f)
            # The reference and the scene's own modules: the test's own
            # numbers (test_crosscheck renders both as the suite asserts them).
            p = subprocess.run([test, name, kind, filt], capture_output=True, text=True, env=env)
            out = p.stdout
            m = re.search(r"crosscheck %s reference: relmse (\S+) nrmse (\S+)" % name, out)
            d = re.search(r"crosscheck %s reference: nrmse-debiased (\S+)" % name, out)
            t = re.search(r"strahl reference: .*?, ([0-9.]+) s\)", out)
            if not m or not d:
                sys.exit("accuracy: %s: no reference line in\n%s%s" % (name, out, p.stderr))
            kind_label = kind + (", box" if filt == "box" else "")
            ref_opts = REF_OPTS_BOX[kind] if filt == "box" else REF_OPTS[kind]
            rows.append((name, kind_label, "strahl reference " + " ".join(ref_opts), float(m.group(1)),
                         float(m.group(2)), float(d.group(1)),
                         float(t.group(1)) * 1000.0 if t else float("nan"), cyinfo))
            # The scene's own technique (fog: toth marching the varying density).
            method = {"direct": "shadow_map", "bounce": "atlas_gi", "medium": "toth",
                      "fog": "toth"}[kind]
            m = re.search(r"crosscheck %s %s: relmse (\S+) nrmse (\S+) nrmse-debiased (\S+)"
                          % (name, method), out)
            if not m:
                sys.exit("accuracy: %s: no %s line in\n%s%s" % (name, method, out, p.stderr))
            img = os.path.join(tmp, name + ".gpu.exr")
            stats = json.loads(run([strahl, "render", scene, "-o", img, "--frames", str(FRAMES),
                                    "--filter", filt, "--stats=json"], env))
            renderer = stats["renderer"]
            rows.append((name, kind_label, " + ".join(x["name"] for x in sc["modules"]),
                         float(m.group(1)), float(m.group(2)), float(m.group(3)),
                         stats["frame_ms_median"], ""))
            if kind in ("medium", "fog"):
                # froxel in toth's place: the test's own numbers (asserted,
                # issue 24) and the frame time of the same swapped scene.
                m = re.search(r"crosscheck %s froxel: relmse (\S+) nrmse (\S+) nrmse-debiased (\S+)"
                              % name, out)
                if not m:
                    sys.exit("accuracy: %s: no froxel line in\n%s%s" % (name, out, p.stderr))
                alt = dict(sc)
                alt["modules"] = [x if x["name"] != "toth" else {"name": "froxel"} for x in sc["modules"]]
                alt["geometry"] = [dict(g, gltf=os.path.join(DATA, g["gltf"])) if "gltf" in g else g
                                   for g in sc.get("geometry", [])]
                if isinstance(sc.get("medium", {}).get("density", {}).get("vdb"), str):
                    alt["medium"] = json.loads(json.dumps(sc["medium"]))
                    alt["medium"]["density"]["vdb"] = os.path.join(DATA, sc["medium"]["density"]["vdb"])
                path = os.path.join(tmp, name + ".froxel.json")
                with open(path, "w") as f:
                    json.dump(alt, f)
                # the copy names its VDB by absolute path, outside its folder
                stats = json.loads(run([strahl, "render", path, "-o", os.path.join(tmp, name + ".froxel.exr"),
                                        "--frames", str(FRAMES), "--filter", filt, "--stats=json",
                                        "--allow-outside-assets"], env))
                rows.append((name, kind_label, " + ".join(x["name"] for x in alt["modules"]),
                             float(m.group(1)), float(m.group(2)), float(m.group(3)),
                             stats["frame_ms_median"], ""))
            if kind == "bounce":
                # ssgi in place of atlas_gi (not asserted by the suite): the
                # error of its still as render makes it, and its frame time.
                alt = dict(sc)
                alt["modules"] = [x if x["name"] != "atlas_gi" else {"name": "ssgi"} for x in sc["modules"]]
                alt["geometry"] = [dict(g, gltf=os.path.join(DATA, g["gltf"])) if "gltf" in g else g
                                   for g in sc["geometry"]]  # the copy lives in tmp
                path = os.path.join(tmp, name + ".ssgi.json")
                with open(path, "w") as f:
                    json.dump(alt, f)
                img = os.path.join(tmp, name + ".ssgi.exr")
                run([strahl, "render", path, "-o", img, "--filter", filt], env)
                rel, nrmse = compare(strahl, img, cyc, env)
                stats = json.loads(run([strahl, "render", path, "-o", img, "--frames", str(FRAMES),
                                        "--filter", filt, "--stats=json"], env))
                rows.append((name, kind_label, " + ".join(x["name"] for x in alt["modules"]), rel, nrmse,
                             float("nan"), stats["frame_ms_median"], ""))
            print("accuracy: %s done" % name, file=sys.stderr)

    write_doc(args.out, rows, [c[0] for c in all_cases], [c[0] for c in cases],
              bool(args.cases), renderer)


TABLE_HEAD = ["| case | kind | method | relMSE | NRMSE | NRMSE debiased | time (ms) | Cycles |",
              "|------|------|--------|-------:|------:|---------------:|----------:|--------|"]


def format_row(row):
    name, kind, label, rel, nrmse, db, ms, cy = row
    dbs = "-" if db != db else "%.3g" % db  # NaN: not measured (ssgi)
    return "| %s | %s | %s | %.3g | %.3g | %s | %.1f | %s |" % (name, kind, label, rel, nrmse, dbs, ms, cy)


def write_doc(path, rows, order, measured, partial, renderer):
    """Rewrites the table of `path`: the rows of the cases just measured
    replace theirs, every other row stays as it was, all in cases.txt order.
    The text around the table is the document's own (hand-written; others
    edit it in place) and is kept; only a new file gets a bare heading. The
    line after the table says which run measured which rows."""
    head, old_rows, tail = ["# Accuracy against Blender Cycles", "", "## Table", ""], [], []
    if os.path.exists(path):
        with open(path) as f:
            text = f.read().split("\n")
        try:
            start = text.index(TABLE_HEAD[0])
        except ValueError:
            sys.exit("accuracy: %s has no table header line %r" % (path, TABLE_HEAD[0]))
        head, end = text[:start], start + 2
        while end < len(text) and text[end].startswith("|"):
            old_rows.append(text[end])
            end += 1
        tail = text[end:]
    kept = [r for r in old_rows if r.split("|")[1].strip() not in measured] if partial else []
    new = [format_row(r) for r in rows]
    rank = {name: i for i, name in enumerate(order)}
    # Stable: a case's rows keep their order (reference, its modules, ssgi).
    table = sorted(kept + new, key=lambda r: rank.get(r.split("|")[1].strip(), len(rank)))
    cmd = "`tools/crosscheck/accuracy.py%s` (%s, %s, %s)" % (
        "".join(" " + m for m in measured) if partial else "", platform.machine(), renderer,
        time.strftime("%Y-%m-%d", time.gmtime()))
    if partial:
        # Earlier runs' lines stay (the full run's Command line, other partial
        # runs' notes), but a note whose rows have all been re-measured goes.
        def superseded(line):
            m = re.match(r"Rows of (.*?) re-measured by ", line)
            return m and all(c in measured for c in m.group(1).split(", "))
        tail = [t for t in tail if not superseded(t)]
        while tail and not tail[0].strip():
            tail = tail[1:]
        tail = ["", "Rows of %s re-measured by %s; the other rows are from earlier runs"
                " (below)." % (", ".join(measured), cmd), ""] + tail
    else:
        tail = ["", "Command: %s, every case." % cmd, ""]
    with open(path, "w") as f:
        f.write("\n".join(head + TABLE_HEAD + table + tail))
    print("accuracy: wrote %s (%d rows measured, %d kept)" % (path, len(new), len(kept)),
          file=sys.stderr)


main()

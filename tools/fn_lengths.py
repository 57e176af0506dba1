#!/usr/bin/env python3
"""Lists C function definitions by length (lines from the signature's first
line to the closing brace), longest first.

    tools/fn_lengths.py [--max N] [--fail] PATH...

PATH is a .c file or a folder (searched for *.c and *.cpp). A definition is a
top-level line (column 0, not a declaration, macro or comment) whose
parenthesised signature is followed by '{'; it ends at the first '}' in
column 0. That is how clang-format lays out this repository's code, which
is all the script has to read. --max N lists only functions over N lines;
--fail exits 1 if any is listed (for a check in CI or by hand).
"""
import argparse
import os
import re
import sys

SKIP_START = re.compile(r"^(#|//|/\*|\*|typedef\b|struct\s+\w+\s*\{|enum\b|union\b|static\s+const\b[^(]*=|}|\s)")


def functions(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        lines = f.read().split("\n")
    out = []
    i = 0
    while i < len(lines):
        line = lines[i]
        if not line or SKIP_START.match(line) or "(" not in line:
            i += 1
            continue
        # The signature may continue on the next lines until '{' or ';'.
        j = i
        sig = line
        while not sig.rstrip().endswith(("{", ";", ")")) and j + 1 < len(lines) and j - i < 8:
            j += 1
            sig += " " + lines[j].strip()
        if sig.rstrip().endswith(")") and j + 1 < len(lines) and lines[j + 1].startswith("{"):
            j += 1
            sig += " {"
        if not sig.rstrip().endswith("{") or "=" in sig.split("(")[0]:
            i = j + 1
            continue
        m = re.search(r"(\w+)\s*\(", sig)
        name = m.group(1) if m else "?"
        k = j + 1
        while k < len(lines) and not lines[k].startswith("}"):
            k += 1
        out.append((k - i + 1, name, path, i + 1))
        i = k + 1
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("paths", nargs="+")
    ap.add_argument("--max", type=int, default=0, help="list only functions longer than this")
    ap.add_argument("--fail", action="store_true", help="exit 1 if any function is listed")
    a = ap.parse_args()
    files = []
    for p in a.paths:
        if os.path.isdir(p):
            for root, _, names in os.walk(p):
                files += [os.path.join(root, n) for n in names if n.endswith((".c", ".cpp"))]
        else:
            files.append(p)
    found = []
    for f in sorted(files):
        found += functions(f)
    found = [x for x in found if x[0] > a.max]
    found.sort(key=lambda x: (-x[0], x[2], x[3]))
    for n, name, path, line in found:
        print(f"{n:5d}  {name}  {path}:{line}")
    return 1 if a.fail and found else 0


if __name__ == "__main__":
    sys.exit(main())

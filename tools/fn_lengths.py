#!/usr/bin/env python3
"""Lengths of C/C++ function bodies in clang-formatted sources.

    tools/fn_lengths.py [--max N] PATH...   (files or folders; default: framework)

Prints every function longer than N lines (default 80), longest first, as
"lines file:line name", and exits 1 if there is one. A function is a line at
column 0 that is not a comment, preprocessor line or declaration of a type and
that ends with '{', up to the next '}' at column 0 (the layout clang-format
gives this repository's code); its length counts the lines from the header's
first line to the closing brace.
"""
import os
import re
import sys

SKIP = re.compile(r"^(#|//|/\*|\*|typedef|struct\s+\w+\s*\{|enum|union|static const|const|extern \"C\")")


def functions(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        lines = f.read().split("\n")
    i = 0
    while i < len(lines):
        line = lines[i]
        if line[:1] in ("", " ", "\t", "}") or SKIP.match(line) or "(" not in line \
                or "=" in line.split("(")[0]:
            i += 1
            continue
        # The header runs to the first line ending with '{' (a definition) or ';'.
        k = i
        while k < len(lines) and not lines[k].rstrip().endswith(("{", ";")):
            k += 1
        if k == len(lines) or lines[k].rstrip().endswith(";"):
            i = k + 1
            continue
        j = k + 1
        while j < len(lines) and not lines[j].startswith("}"):
            j += 1
        m = re.search(r"(\w+)\s*\(", line)
        yield i + 1, j - i + 1, m.group(1) if m else line.strip()
        i = j + 1


def main(argv):
    limit = 80
    paths = []
    it = iter(argv)
    for a in it:
        if a == "--max":
            limit = int(next(it))
        else:
            paths.append(a)
    files = []
    for p in paths or ["framework"]:
        if os.path.isdir(p):
            for root, _, names in os.walk(p):
                files += [os.path.join(root, n) for n in names if n.endswith((".c", ".cpp", ".h"))]
        else:
            files.append(p)
    long = []
    for f in sorted(files):
        for line, n, name in functions(f):
            if n > limit:
                long.append((n, f, line, name))
    for n, f, line, name in sorted(long, reverse=True):
        print("%4d %s:%d %s" % (n, f, line, name))
    return 1 if long else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

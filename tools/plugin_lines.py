#!/usr/bin/env python3
"""C lines of each plugin in modules/, split into declarations and technique.

Declarations: the static tables a plugin declares to the SDK (st_param_def,
st_pass_decl, st_program_decl, st_export_decl, st_uniform arrays) and the
ST_PLUGIN(...) descriptor; technique: every other line of its .c and .h files
(comments and blank lines included, as `wc -l` counts them).

    tools/plugin_lines.py [MODULES_DIR]
"""
import os
import re
import sys

TABLE = re.compile(r'^\s*static const (st_param_def|st_pass_decl|st_program_decl|st_export_decl|st_uniform)\b')


def count(path):
    lines = open(path, encoding='utf-8', errors='replace').read().split('\n')
    if lines and lines[-1] == '':
        lines.pop()
    decl = 0
    i = 0
    while i < len(lines):
        line = lines[i]
        if TABLE.match(line) or line.startswith('ST_PLUGIN('):
            depth = 0
            opened = False
            while i < len(lines):
                s = lines[i]
                depth += s.count('{') + s.count('(') - s.count('}') - s.count(')')
                opened = opened or '{' in s or '(' in s
                decl += 1
                i += 1
                if opened and depth <= 0:
                    break
            continue
        i += 1
    return len(lines), decl


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else 'modules'
    print('%-12s %6s %6s %6s' % ('plugin', 'total', 'decl', 'tech'))
    for name in sorted(os.listdir(root)):
        d = os.path.join(root, name)
        if not os.path.isdir(d) or name == 'common':
            continue
        total = decl = 0
        for f in sorted(os.listdir(d)):
            if f.endswith(('.c', '.h')):
                t, k = count(os.path.join(d, f))
                total += t
                decl += k
        print('%-12s %6d %6d %6d' % (name, total, decl, total - decl))


if __name__ == '__main__':
    main()

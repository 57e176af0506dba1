#!/usr/bin/env python3
"""Writes a scene for atlas_gi's transfer precompute at scale (issue 34): a
2 m closed room (five quads, as scenes/gi_dense.json) cluttered with a grid
of finely tessellated spheres resting on the floor, rows of them on two
shelves (thin quads) along the back wall, the total tessellated to about
TRIANGLES triangles (default 1,000,000). Nothing large is committed: the
scene is a few kB of JSON, and strahl tessellates the spheres on load.

    python3 tools/make_gi_million.py OUT.json [TRIANGLES]
    strahl render OUT.json --size 64x64 --frames 1 --stats   # `transfer precompute`
"""
import json
import math
import sys

RINGS, SEGMENTS = 64, 160  # 2 * SEGMENTS * (RINGS - 1) = 20,160 triangles a sphere


def quad(corner, u, v, albedo):
    return {"quad": {"corner": corner, "u": u, "v": v}, "albedo": albedo}


def sphere(c, r, albedo):
    return {"sphere": {"center": c, "radius": r, "rings": RINGS, "segments": SEGMENTS},
            "albedo": albedo}


def main():
    if len(sys.argv) < 2:
        sys.exit("usage: make_gi_million.py OUT.json [TRIANGLES]")
    target = int(sys.argv[2]) if len(sys.argv) > 2 else 1_000_000
    per = 2 * SEGMENTS * (RINGS - 1)
    grey, red, green = [0.75] * 3, [0.75, 0.1, 0.1], [0.1, 0.75, 0.1]
    geo = [quad([-1, 0, -1], [0, 0, 2], [2, 0, 0], grey),  # floor
           quad([-1, 2, -1], [2, 0, 0], [0, 0, 2], grey),  # ceiling
           quad([-1, 0, -1], [2, 0, 0], [0, 2, 0], grey),  # back
           quad([-1, 0, -1], [0, 2, 0], [0, 0, 2], red),   # left
           quad([1, 0, -1], [0, 0, 2], [0, 2, 0], green)]  # right
    # Two shelves along the back wall, 20 cm deep, seen from above and below.
    for y in (0.7, 1.3):
        geo.append(quad([-0.9, y, -1], [0, 0, 0.2], [1.8, 0, 0], grey))
        geo.append(quad([-0.9, y, -1], [1.8, 0, 0], [0, 0, 0.2], grey))
    spheres = max(1, round((target - 2 * len(geo)) / per))
    palette = [grey, red, [0.2, 0.2, 0.75], [0.75, 0.75, 0.2]]
    shelf = [(x, y) for y in (0.7, 1.3) for x in (-0.7, -0.35, 0.0, 0.35, 0.7)]
    floor_n = spheres - min(spheres, len(shelf))
    cols = max(1, math.ceil(math.sqrt(floor_n * 1.5)))
    for i in range(spheres):
        if i < len(shelf):  # on the shelves, touching them
            x, y = shelf[i]
            geo.append(sphere([x, y + 0.08, -0.9], 0.08, palette[i % 4]))
            continue
        k = i - len(shelf)
        row, col = divmod(k, cols)
        x = -0.85 + 1.7 * (col + 0.5) / cols
        z = -0.55 + 1.3 * (row + 0.5) / max(1, math.ceil(floor_n / cols))
        r = min(0.09, 0.8 / cols)
        geo.append(sphere([x, r, z], r, palette[k % 4]))  # resting on the floor
    scene = {
        "image": {"width": 64, "height": 64},
        "camera": {"position": [0, 1, 3.4], "target": [0, 1, 0], "up": [0, 1, 0],
                   "fov_y": 40, "near": 0.05, "far": 100},
        "lights": [{"type": "point", "position": [0, 1.9, 0], "intensity": [3, 3, 3]}],
        "geometry": geo,
        "modules": [{"name": "shadow_map"}, {"name": "atlas_gi"}],
    }
    with open(sys.argv[1], "w") as f:
        json.dump(scene, f, indent=1)
    print(f"{sys.argv[1]}: {spheres} spheres, {spheres * per + 2 * (len(geo) - spheres)} triangles")


if __name__ == "__main__":
    main()

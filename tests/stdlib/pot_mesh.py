#!/usr/bin/env python3
"""The standard library's bonsai pot is what scripts/make-pot-mesh makes, and a solid the
`obstacles` environment can take: every edge shared by exactly two faces in opposite directions
(closed, consistently wound) and a positive signed volume (faces wound outward)."""
import os
import subprocess
import sys
import tempfile
from collections import Counter


def read(path):
    vs, fs = [], []
    for line in open(path):
        p = line.split()
        if p and p[0] == "v":
            vs.append(tuple(map(float, p[1:4])))
        elif p and p[0] == "f":
            fs.append(tuple(int(x) - 1 for x in p[1:4]))
    return vs, fs


def main():
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    shipped = os.path.join(root, "stdlib", "meshes", "pot.obj")
    with tempfile.TemporaryDirectory() as tmp:
        remade = os.path.join(tmp, "pot.obj")
        subprocess.run([sys.executable, os.path.join(root, "scripts", "make-pot-mesh"), remade], check=True)
        if open(remade).read() != open(shipped).read():
            sys.exit("stdlib/meshes/pot.obj differs from what scripts/make-pot-mesh makes: remake it")
    vs, fs = read(shipped)
    edges = Counter()
    for a, b, c in fs:
        for u, v in ((a, b), (b, c), (c, a)):
            edges[(u, v)] += 1
    open_edges = [e for e in edges if edges[e] != 1 or edges.get((e[1], e[0]), 0) != 1]
    if open_edges:
        sys.exit(f"pot.obj is not closed and consistently wound: {len(open_edges)} bad edges")
    volume = 0.0
    for a, b, c in fs:
        (ax, ay, az), (bx, by, bz), (cx, cy, cz) = vs[a], vs[b], vs[c]
        volume += (ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx)) / 6
    if volume <= 0:
        sys.exit(f"pot.obj is wound inward (signed volume {volume})")
    print(f"pot.obj: {len(fs)} faces, closed, volume {volume:.6f} m^3")


if __name__ == "__main__":
    main()

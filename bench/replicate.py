#!/usr/bin/env python3
"""Writes N copies of an STL surface (ASCII or binary) as one binary STL: the
copies on a near-cubic lattice, 1.5 x the model's largest extent apart (bodies
that never touch), for bench/scale.sh. Prints the bounding-box diagonals of
one copy and of the assembly (JSON) so the caller can keep the dense grid's
resolution per copy fixed.

Usage: bench/replicate.py IN.stl N OUT.stl
"""
import json
import math
import struct
import sys


def read_stl(path):
    data = open(path, "rb").read()
    if len(data) >= 84:
        (n,) = struct.unpack_from("<I", data, 80)
        if 84 + 50 * n == len(data):
            tris = []
            for i in range(n):
                v = struct.unpack_from("<9f", data, 84 + 50 * i + 12)
                tris.append((v[0:3], v[3:6], v[6:9]))
            return tris
    tris, cur = [], []
    for line in data.decode("ascii", "replace").splitlines():
        w = line.split()
        if w and w[0] == "vertex":
            cur.append(tuple(float(x) for x in w[1:4]))
            if len(cur) == 3:
                tris.append(tuple(cur))
                cur = []
    if not tris:
        sys.exit(f"{path}: no triangles")
    return tris


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    src, n, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    if n < 1:
        sys.exit("N must be >= 1")
    tris = read_stl(src)
    lo = [min(v[k] for t in tris for v in t) for k in range(3)]
    hi = [max(v[k] for t in tris for v in t) for k in range(3)]
    ext = [h - l for h, l in zip(hi, lo)]
    step = 1.5 * max(ext)
    side = math.ceil(round(n ** (1.0 / 3.0), 9))
    offsets = [(i % side, (i // side) % side, i // (side * side)) for i in range(n)]
    with open(out, "wb") as f:
        f.write(b"abgs bench/replicate.py".ljust(80, b" "))
        f.write(struct.pack("<I", n * len(tris)))
        for o in offsets:
            d = [step * c for c in o]
            for t in tris:
                f.write(struct.pack("<3f", 0.0, 0.0, 0.0))
                for v in t:
                    f.write(struct.pack("<3f", *(v[k] + d[k] for k in range(3))))
                f.write(b"\0\0")
    span = [ext[k] + step * max(o[k] for o in offsets) for k in range(3)]
    print(json.dumps({"copies": n, "triangles": n * len(tris),
                      "diagonal_one": math.sqrt(sum(e * e for e in ext)),
                      "diagonal": math.sqrt(sum(s * s for s in span))}))


if __name__ == "__main__":
    main()

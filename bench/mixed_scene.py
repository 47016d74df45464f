#!/usr/bin/env python3
"""Writes a mixed-scale scene for bench/ploc.json: shared meshes, each
normalised (centred, largest extent 1) then scaled and placed, merged into
one OBJ. Sizes span three orders of magnitude: a nefertiti 100 units
across, two ogres of 10, six bunnies of 1 and three horses of 0.1, the
small ones spread over the large ones. The meshes are read from
../shared/scenes (never copied into the repository); the output goes
where the first argument says (default results/mixed-scale.obj, ~1.06M
triangles).

Usage: python3 bench/mixed_scene.py [OUT.obj] [SCENES_DIR]
"""
import os
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))

# (file, largest extent, [centre, ...])
LAYOUT = [
    ("nefertiti.obj", 100.0, [(0, 0, 0)]),
    ("ogre.obj", 10.0, [(-30, 10, 20), (25, -15, 30)]),
    ("stanford-bunny.obj", 1.0,
     [(-40 + 16 * k, -30 + 12 * (k % 3), 45 - 9 * k) for k in range(6)]),
    ("horse.ply", 0.1, [(5, 5, 50), (-20, 30, -40), (35, 0, -10)]),
]


def read_obj(path):
    verts, faces = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                verts.append(tuple(float(x) for x in line.split()[1:4]))
            elif line.startswith("f "):
                idx = [int(t.split("/")[0]) for t in line.split()[1:]]
                idx = [i - 1 if i > 0 else len(verts) + i for i in idx]
                for k in range(1, len(idx) - 1):  # fan
                    faces.append((idx[0], idx[k], idx[k + 1]))
    return verts, faces


def read_ply(path):
    """Binary little-endian PLY with float vertex properties and a uchar/int
    face list (horse.ply's layout)."""
    with open(path, "rb") as f:
        header, props = [], []
        while True:
            line = f.readline().decode("ascii").strip()
            header.append(line)
            if line == "end_header":
                break
        nv = nf = 0
        for line in header:
            w = line.split()
            if w[:2] == ["element", "vertex"]:
                nv, current = int(w[2]), "vertex"
            elif w[:2] == ["element", "face"]:
                nf, current = int(w[2]), "face"
            elif w[0] == "property" and current == "vertex":
                props.append(w[2])
        stride = 4 * len(props)
        data = f.read(nv * stride)
        verts = [struct.unpack_from("<3f", data, k * stride) for k in range(nv)]
        faces = []
        for _ in range(nf):
            (n,) = struct.unpack("<B", f.read(1))
            idx = struct.unpack("<%di" % n, f.read(4 * n))
            for k in range(1, n - 1):
                faces.append((idx[0], idx[k], idx[k + 1]))
    return verts, faces


def normalise(verts):
    lo = [min(v[a] for v in verts) for a in range(3)]
    hi = [max(v[a] for v in verts) for a in range(3)]
    centre = [(lo[a] + hi[a]) / 2 for a in range(3)]
    extent = max(hi[a] - lo[a] for a in range(3))
    return [tuple((v[a] - centre[a]) / extent for a in range(3)) for v in verts]


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "..", "results",
                                                             "mixed-scale.obj")
    scenes = sys.argv[2] if len(sys.argv) > 2 else os.path.join(HERE, "..", "..", "shared",
                                                                "scenes")
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    base, triangles = 1, 0
    with open(out, "w") as f:
        f.write("# bvhlab bench/mixed_scene.py: shared meshes at sizes 100, 10, 1, 0.1\n")
        for name, size, centres in LAYOUT:
            path = os.path.join(scenes, name)
            verts, faces = (read_ply if name.endswith(".ply") else read_obj)(path)
            unit = normalise(verts)
            for c in centres:
                for v in unit:
                    f.write("v %.7g %.7g %.7g\n" % tuple(c[a] + size * v[a] for a in range(3)))
                for t in faces:
                    f.write("f %d %d %d\n" % (base + t[0], base + t[1], base + t[2]))
                base += len(unit)
                triangles += len(faces)
    print("%s: %d triangles" % (out, triangles))


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Writes the fuzzers' seed inputs: `seeds.py DIR` makes DIR/obj, DIR/ply and
DIR/config. scripts/fuzz.sh starts libFuzzer from them and test-bad-input
replays them through the loaders (meson generates them into the build), so
the repository holds no mesh files of its own."""
import os
import struct
import sys

# A unit quad of two triangles (vertices x y z, a uchar colour) for the
# binary PLY seeds, in both byte orders, and as one triangle strip with a
# restart (-1).
QUAD_VERTICES = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)]
QUAD_HEADER = (
    "ply\nformat binary_{order}_endian 1.0\nelement vertex 4\n"
    "property float x\nproperty float y\nproperty float z\n"
    "property uchar red\n{faces}end_header\n")


def binary_ply(order, faces_header, faces):
    """faces: (struct format, values) pairs appended after the vertices."""
    e = ">" if order == "big" else "<"
    data = QUAD_HEADER.format(order=order, faces=faces_header).encode()
    for v in QUAD_VERTICES:
        data += struct.pack(e + "fffB", *v, 200)
    for fmt, values in faces:
        data += struct.pack(e + fmt, *values)
    return data


TRIANGLES = "element face 2\nproperty list uchar int vertex_indices\n"
TWO_TRIANGLES = [("B3i", (3, 0, 1, 2)), ("B3i", (3, 1, 3, 2))]
STRIP = "element tristrips 1\nproperty list int int vertex_indices\n"
STRIP_FACES = [("i5i", (5, 0, 1, 2, -1, 3))]

SEEDS = {
    ("config", "errors.json"): (
        b'{ "format_version": 2, "repeat": -1, "threds": [1, 1],\n'
        b'  "scenes": [ { "path": "a.obj", "generator": "soup" }, { "name": "a" '
        b'}, { "name": "a", "generator": "x" } ],\n'
        b'  "builders": [ { "plugin": "" }, { "plugin": "p", "options": { "bins"'
        b': 1e400, "bins": "\\u00e9" } } ] }\n'),
    ("config", "full.json"): (
        b'{ "format_version": 1,\n'
        b'  "output": "results/fuzz",\n'
        b'  "repeat": 3, "warmup": 1,\n'
        b'  "threads": [1, 2, 0],\n'
        b'  "validate": true, "validate_rays": 64,\n'
        b'  "rays": { "width": 64, "height": 32, "diffuse": 2 },\n'
        b'  "images": false,\n'
        b'  "isolate": true, "timeout_s": 60.5, "memory_limit_mb": 512,\n'
        b'  "scenes": [\n'
        b'    { "name": "ico", "generator": "icosphere", "frequency": 10, "subdivide": 1 },\n'
        b'    { "generator": "soup", "count": 100, "seed": 7 },\n'
        b'    { "path": "../meshes/ogre.obj" } ],\n'
        b'  "builders": [\n'
        b'    { "plugin": "sah_seq", "name": "sweep", "options": { "method": "sw'
        b'eep", "bins": 16 } },\n'
        b'    { "plugin": "plugins/x.so", "threads": [4], "timeout_s": 5, "memor'
        b'y_limit_mb": 64,\n'
        b'      "options": { "c_trav": 1.5, "flag": true, "label": "abc" } } ] }\n'),
    ("config", "minimal.json"): b'{"scenes":[{"generator":"soup"}],"builders":[{"plugin":"a"}]}\n',
    ("obj", "errors.obj"): b'v 0 0 0\nv 1 nan 0\nv 0 1e39 0\nf 1 2 0\nf 1 2/a 3\n',
    ("obj", "mixed.obj"): (
        b'# mixed statements\r\n'
        b'mtllib a.mtl\r\n'
        b'o thing\r\n'
        b'v 0.5 -1.25 3\r\n'
        b'v 1e1 0 0 1.0\r\n'
        b'  v\t0 2 0\r\n'
        b'v 1 1 1 0.5 0.5 0.5\r\n'
        b'vt 0 0\r\n'
        b'vn 0 0 1\r\n'
        b'g grp\r\n'
        b's off\r\n'
        b'usemtl red\r\n'
        b'f 1/1 2/1 3/1 4/1 # quad\r\n'
        b'f 1//1 2//1 3//1\r\n'
        b'f 1/1/1 2/1/1 3/1/1\r\n'
        b'curv 0 1 2\r\n'
        b'f 1 2 3 4'),
    ("obj", "relative.obj"): (
        b'v 0 0 0\n'
        b'v 1 0 0\n'
        b'v 0 1 0\n'
        b'f -3 -2 -1\n'
        b'f 4 1 2\n'
        b'v 0 0 1\n'
        b'f -1 -4 -3\n'
        b'f 1 1 2\n'),
    ("obj", "triangle.obj"): b'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n',
    ("ply", "ascii.ply"): (
        b'ply\n'
        b'format ascii 1.0\n'
        b'comment made by hand\n'
        b'obj_info nothing\n'
        b'element material 1\n'
        b'property list uchar float weights\n'
        b'property uchar id\n'
        b'element vertex 5\n'
        b'property float x\n'
        b'property float y\n'
        b'property float z\n'
        b'property list int int tags\n'
        b'element face 2\n'
        b'property uchar flags\n'
        b'property list uchar int vertex_indices\n'
        b'end_header\n'
        b'3 0.5 0.25 1 7\n'
        b'0.5 -1.25 3 0\n'
        b'1 0 0 2 10 11\n'
        b'0 1 0 0\n'
        b'1 1 0 1 -5\n'
        b'2e-3 4 -8 0\n'
        b'0 4 0 1 2 3\n'
        b'9 3 2 3 4\n'),
    ("ply", "strips.ply"): (
        b'ply\n'
        b'format ascii 1.0\n'
        b'element face 1\n'
        b'property list uchar uint vertex_indices\n'
        b'element vertex 4\n'
        b'property double x\n'
        b'property double y\n'
        b'property double z\n'
        b'element tristrips 1\n'
        b'property list int int vertex_indices\n'
        b'end_header\n'
        b'3 2 0 1\n'
        b'0 0 0\n'
        b'1 0 0\n'
        b'0 1 0\n'
        b'1 1 0\n'
        b'6 0 1 2 -1 1 2 3\n'),
    ("ply", "binary-be.ply"): binary_ply("big", TRIANGLES, TWO_TRIANGLES),
    ("ply", "binary-le.ply"): binary_ply("little", TRIANGLES, TWO_TRIANGLES),
    ("ply", "strips-le.ply"): binary_ply("little", STRIP, STRIP_FACES),
}


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: seeds.py DIR")
    for (kind, name), data in SEEDS.items():
        os.makedirs(os.path.join(sys.argv[1], kind), exist_ok=True)
        with open(os.path.join(sys.argv[1], kind, name), "wb") as f:
            f.write(data)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Writes the seed corpora of the fuzz targets into fuzz/corpus/<target>/.

Small valid inputs of every format a target reads (plus a few near misses);
rerun after changing the formats. Each seed stays under a few KB."""
import gzip
import json
import os
import struct
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus")


def write(target, name, data):
    folder = os.path.join(ROOT, target)
    os.makedirs(folder, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(folder, name), "wb") as f:
        f.write(data)


POINTS = [(1.0, 2.0, 3.0), (4.5, -5.25, 6.0), (-7.0, 8.0, 9.125), (0.5, 0.25, -0.75)]
NORMALS = [(0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.6, 0.8, 0.0)]

# ---- PLY ---------------------------------------------------------------------------------------


def ply_header(fmt, props, extra_elements=(), comments=("coordinates LPS, units mm",)):
    lines = ["ply", "format %s 1.0" % fmt]
    lines += ["comment " + c for c in comments]
    for name, count, eprops in extra_elements:
        lines.append("element %s %d" % (name, count))
        lines += ["property " + p for p in eprops]
    lines.append("element vertex %d" % len(POINTS))
    lines += ["property %s %s" % (t, n) for t, n in props]
    lines.append("end_header")
    return "\n".join(lines) + "\n"


def ply_seeds():
    xyz = [("float", "x"), ("float", "y"), ("float", "z")]
    normals = [("float", "nx"), ("float", "ny"), ("float", "nz")]
    text = ply_header("ascii", xyz) + "".join("%g %g %g\n" % p for p in POINTS)
    write("fuzz_ply", "ascii.ply", text)
    text = ply_header("ascii", xyz + normals) + "".join(
        "%g %g %g %g %g %g\n" % (p + n) for p, n in zip(POINTS, NORMALS))
    write("fuzz_ply", "ascii_normals.ply", text)
    # An element before the vertices, with a list, as meshes have them.
    text = ply_header("ascii", [("double", "x"), ("uchar", "red"), ("double", "y"), ("double", "z")],
                      extra_elements=[("face", 1, ["list uchar int vertex_indices"])])
    text += "3 0 1 2\n" + "".join("%g 7 %g %g\n" % p for p in POINTS)
    write("fuzz_ply", "ascii_face_first.ply", text.replace("\n", "\r\n", 3))
    for fmt, order in (("binary_little_endian", "<"), ("binary_big_endian", ">")):
        tag = "le" if order == "<" else "be"
        data = ply_header(fmt, [("double", "x"), ("double", "y"), ("double", "z")]).encode()
        data += b"".join(struct.pack(order + "3d", *p) for p in POINTS)
        write("fuzz_ply", "binary_%s_double.ply" % tag, data)
        data = ply_header(fmt, xyz + normals).encode()
        data += b"".join(struct.pack(order + "6f", *(p + n)) for p, n in zip(POINTS, NORMALS))
        write("fuzz_ply", "binary_%s_normals.ply" % tag, data)
        types = [("char", "b"), ("uchar", "B"), ("short", "h"), ("ushort", "H"), ("int", "i"), ("uint", "I")]
        props = [(t, n) for (t, _), n in zip(types, ["x", "y", "z"])] + [("int16", "s"), ("uint32", "t"), ("int8", "u")]
        data = ply_header(fmt, props, extra_elements=[("face", 2, ["list uchar uint vertex_indices"])]).encode()
        data += struct.pack(order + "B3I", 3, 0, 1, 2) + struct.pack(order + "B2I", 2, 1, 3)
        for p in POINTS:
            data += struct.pack(order + "bBhhIb", int(p[0]), int(abs(p[1])), int(p[2]), 1, 2, 3)
        write("fuzz_ply", "binary_%s_types_lists.ply" % tag, data)


def main():
    ply_seeds()


if __name__ == "__main__":
    sys.exit(main())

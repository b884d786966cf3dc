#!/usr/bin/env python3
"""Writes the small STL files used by tests/unit/geometry (run from any folder; stdlib only).

unit_cube_ascii.stl        closed unit cube [0,1]^3, ASCII, 12 facets (volume 1)
unit_cube_solid_header.stl same cube in binary whose 80-byte header starts with "solid"
open_box_binary.stl        the cube without its top face (10 facets, 4 open edges)
truncated_binary.stl       binary cube cut 30 bytes short
truncated_ascii.stl        ASCII cube that stops inside a facet
nan_ascii.stl              ASCII cube with one 'nan' coordinate
empty_ascii.stl            "solid" ... "endsolid" without facets
"""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))

# Unit cube: 8 corners, 12 counter-clockwise (outward) triangles.
V = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]  # index = x + 2y + 4z
T = [(0, 2, 3), (0, 3, 1),  # z = 0 (normal -z)
     (4, 5, 7), (4, 7, 6),  # z = 1 (normal +z)
     (0, 1, 5), (0, 5, 4),  # y = 0
     (2, 6, 7), (2, 7, 3),  # y = 1
     (0, 4, 6), (0, 6, 2),  # x = 0
     (1, 3, 7), (1, 7, 5)]  # x = 1


def normal(t):
    a, b, c = (V[i] for i in t)
    u = [b[k] - a[k] for k in range(3)]
    w = [c[k] - a[k] for k in range(3)]
    return (u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0])


def ascii_text(tris, nan_at=None):
    out = ["solid unit_cube"]
    for f, t in enumerate(tris):
        out.append("  facet normal %g %g %g" % normal(t))
        out.append("    outer loop")
        for k, i in enumerate(t):
            x, y, z = V[i]
            if nan_at == (f, k):
                out.append("      vertex %g nan %g" % (x, z))
            else:
                out.append("      vertex %g %g %g" % (x, y, z))
        out.append("    endloop")
        out.append("  endfacet")
    out.append("endsolid unit_cube")
    return "\n".join(out) + "\n"


def binary_bytes(tris, header):
    data = header.ljust(80, b" ")[:80] + struct.pack("<I", len(tris))
    for t in tris:
        data += struct.pack("<3f", *normal(t))
        for i in t:
            data += struct.pack("<3f", *V[i])
        data += struct.pack("<H", 0)
    return data


def write(name, content):
    mode = "wb" if isinstance(content, bytes) else "w"
    with open(os.path.join(HERE, name), mode) as f:
        f.write(content)


write("unit_cube_ascii.stl", ascii_text(T))
write("unit_cube_solid_header.stl", binary_bytes(T, b"solid unit_cube written as binary"))
write("open_box_binary.stl", binary_bytes([t for t in T if t not in ((4, 5, 7), (4, 7, 6))], b"open box"))
write("truncated_binary.stl", binary_bytes(T, b"truncated")[:-30])
text = ascii_text(T)
write("truncated_ascii.stl", text[: text.index("endloop", len(text) // 2)])
write("nan_ascii.stl", ascii_text(T, nan_at=(5, 1)))
write("empty_ascii.stl", "solid nothing\nendsolid nothing\n")

#!/usr/bin/env python3
"""Writes the malformed mesh files of this directory and the table bad_meshes.tsv that
tests/cli/test_bad_meshes.sh checks: each file breaks one rule of a supported format
(Wavefront OBJ, PLY ascii / binary little- and big-endian, STL ascii / binary), and
`thzmap validate` of a scene using it must end within 1 s with exit status 2 and a
message containing the given text. The script also writes the good binary PLY
tetrahedra of ../ (tetra_binary_le.ply, tetra_binary_be.ply). Rerun after editing:
    python3 tests/inputs/meshes/bad/make_bad_meshes.py
"""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
GOOD = os.path.dirname(HERE)

# The unit right tetrahedron of ../tetra.obj, outward winding.
V = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
F = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]

XYZ = "property float x\nproperty float y\nproperty float z\n"
FACE = "property list uchar int vertex_indices\n"


def ply_header(fmt, n_vertices=4, n_faces=4, face=FACE, extra=""):
    return (f"ply\nformat {fmt} 1.0\n{extra}element vertex {n_vertices}\n{XYZ}"
            f"element face {n_faces}\n{face}end_header\n").encode()


def ply_binary(endian, verts=V):
    fmt = "binary_little_endian" if endian == "<" else "binary_big_endian"
    body = b"".join(struct.pack(endian + "3f", *v) for v in verts)
    body += b"".join(struct.pack(endian + "B3i", 3, *f) for f in F)
    return ply_header(fmt, extra="comment unit right tetrahedron, outward winding\n") + body


PLY_ASCII_BODY = "".join(f"{x} {y} {z}\n" for x, y, z in V) + \
    "".join(f"3 {a} {b} {c}\n" for a, b, c in F)
PLY_ASCII = ply_header("ascii").decode() + PLY_ASCII_BODY


def stl_ascii(facets):
    out = "solid tetra\n"
    for f in facets:
        out += "  facet normal 0 0 0\n    outer loop\n"
        out += "".join(f"      vertex {x} {y} {z}\n" for x, y, z in f)
        out += "    endloop\n  endfacet\n"
    return out + "endsolid tetra\n"


TRIS = [[V[i] for i in f] for f in F]
STL_ASCII = stl_ascii(TRIS)
STL_BINARY = (b"binary STL: unit right tetrahedron".ljust(80, b" ") + struct.pack("<I", 4) +
              b"".join(struct.pack("<12fH", 0, 0, 0, *[c for v in t for c in v], 0)
                       for t in TRIS))
OBJ = "".join(f"v {x} {y} {z}\n" for x, y, z in V) + \
    "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in F)

# (file name, content, text the message must contain)
CASES = [
    # Wavefront OBJ
    ("obj_empty.obj", b"", "the file is empty"),
    ("obj_truncated_vertex.obj", OBJ[:9].encode(),
     ":2: expected 'v x y z', 'v x y z w' or 'v x y z r g b' (numbers that start with a digit "
     "or a sign, 0.5 not .5; a comment on its own line), found 0 such numbers"),
    ("obj_truncated_faces.obj", (OBJ + "f 1 2 5\n").encode(),
     ":9: index 5, but the file has only 4 'v' lines"),
    # what assimp refused with no line ("vertex index out of range", "Division by zero")
    ("obj_vertex_five_numbers.obj", (OBJ + "v 0 0 0 1 2\n").encode(),
     ":9: expected 'v x y z', 'v x y z w' or 'v x y z r g b'"),
    ("obj_vertex_w_zero.obj", (OBJ + "v 0 1 0 0\n").encode(),
     ":9: a homogeneous w of 0 puts the vertex at infinity"),
    ("obj_no_vertices.obj", b"# faces, no vertices\nf 1 2 3\n",
     ":2: index 3, but the file has only 0 'v' lines"),
    ("obj_huge_index.obj", (OBJ + "f 1 2 99999999999999999999\n").encode(),
     ":9: expected a vertex reference"),
    ("obj_relative_before_start.obj", b"v 0 0 0\nf -1 -2 -3\n",
     ":2: relative index -2 in '-2', but only 1 'v' lines precede it"),
    ("obj_polygon_1025.obj", ("f " + " ".join(str(i + 1) for i in range(1025)) + "\n").encode(),
     ":1: a polygon of 1025 vertices, more than the limit of 1024"),
    ("obj_polygon_continued.obj",
     ("f " + " \\\n".join(" ".join(str(i + 1) for i in range(k, k + 100))
                           for k in range(0, 2000, 100)) + "\n").encode(),
     ":1: a polygon of 2000 vertices, more than the limit of 1024"),
    ("obj_bad_reference.obj", (OBJ + "f 1/2/3/4 2 3\n").encode(),
     ":9: expected at most three indices in '1/2/3/4'"),
    ("obj_texture_index.obj", (OBJ + "vt 0 0\nf 1/1 2/2 3/1\n").encode(),
     ":10: index 2, but the file has only 1 'vt' lines"),
    ("obj_nan_vertex.obj", b"v nan 0 0\n", ":1: expected 'v x y z'"),
    ("obj_inf_vertex.obj", b"v 0 0 1e999\n", ":1: expected 3 finite numbers after 'v'"),
    # a comment after the numbers is read as numbers by the importer ('Cannot parse "#"')
    ("obj_vertex_comment.obj", (OBJ + "v 0 0 0 # from Blender 2\n").encode(),
     ":9: expected 4 finite numbers after 'v'"),
    ("obj_binary.obj", b"v 0 0 0\n\x00\x01\x02garbage", "byte 8: a NUL byte"),
    # PLY
    ("ply_empty.ply", b"", "the file is empty"),
    ("ply_not_ply.ply", b"PLY file\nformat ascii 1.0\n", ":1: expected 'ply' on the first line"),
    ("ply_no_end_header.ply", ply_header("ascii")[:-len(b"end_header\n")],
     "the file ends in the PLY header: expected an 'end_header' line"),
    ("ply_no_end_header_long.ply",
     b"ply\nformat binary_little_endian 1.0\n" + b"comment padding padding padding\n" * 2100,
     "no 'end_header' line in the first 65536 bytes"),
    ("ply_binary_huge_vertex_count.ply",
     ply_header("binary_little_endian", n_vertices=2000000000) + ply_binary("<")[-100:],
     "element 'vertex' declares 2000000000 records of at least 12 bytes"),
    ("ply_ascii_huge_face_count.ply",
     ply_header("ascii", n_faces=4000000000) + PLY_ASCII_BODY.encode(),
     "element 'face' declares 4000000000 records of at least 2 bytes"),
    ("ply_count_too_large.ply", ply_header("ascii", n_vertices=99999999999) +
     PLY_ASCII_BODY.encode(), ":3: expected 'element NAME COUNT' with 0 <= COUNT <= 4294967295"),
    ("ply_binary_huge_list.ply",
     ply_header("binary_little_endian", n_faces=1, face="property list int int vertex_indices\n")
     + b"".join(struct.pack("<3f", *v) for v in V) + struct.pack("<i", 200000000)
     + struct.pack("<3i", 0, 1, 2),
     "a 'vertex_indices' list of 200000000 values in element 'face', expected 0 to 1024"),
    ("ply_ascii_huge_polygon.ply",
     ply_header("ascii", n_faces=1).decode().encode() + PLY_ASCII_BODY.split("3 0")[0].encode()
     + ("2000 " + " ".join("0" for _ in range(2000)) + "\n").encode(),
     "a 'vertex_indices' list of 2000 values in element 'face', expected 0 to 1024"),
    ("ply_binary_truncated.ply", ply_binary("<")[:-7],
     "the file ends inside record 4 of the 4 of element 'face'"),
    ("ply_binary_be_truncated.ply", ply_binary(">")[:-30],
     "the file ends inside record 2 of the 4 of element 'face'"),
    ("ply_ascii_truncated.ply", PLY_ASCII[:-16].encode(),
     ":15: the file ends after 2 of the 4 records of element 'face'"),
    ("ply_ascii_cut_record.ply", PLY_ASCII[:-4].encode(),
     ":17: expected an integer vertex index for 'vertex_indices' of element 'face', the line ends"),
    ("ply_missing_format.ply",
     ply_header("ascii").replace(b"format ascii 1.0\n", b"") + PLY_ASCII_BODY.encode(),
     "the header has no 'format' line"),
    ("ply_unknown_format.ply",
     ply_header("ascii").replace(b"ascii", b"binary_middle_endian") + PLY_ASCII_BODY.encode(),
     ":2: expected 'format ascii|binary_little_endian|binary_big_endian 1.0'"),
    ("ply_missing_vertex.ply",
     b"ply\nformat ascii 1.0\nelement face 1\n" + FACE.encode() + b"end_header\n3 0 1 2\n",
     "no 'vertex' element with properties x, y and z"),
    ("ply_missing_face_list.ply",
     ply_header("ascii", face="property int vertex_indices\n") + PLY_ASCII_BODY.encode(),
     ":8: the face's 'vertex_indices' must be a list of integers"),
    ("ply_element_without_properties.ply",
     ply_header("binary_little_endian", extra="element junk 4000000000\n") + ply_binary("<")[-100:],
     ":3: element 'junk' declares 4000000000 records but no properties"),
    ("ply_bad_type.ply", ply_header("ascii").replace(b"float z", b"flt z") +
     PLY_ASCII_BODY.encode(), ":6: unknown property type 'flt'"),
    ("ply_property_first.ply", b"ply\nformat ascii 1.0\nproperty float x\nend_header\n",
     ":3: a 'property' line before any 'element' line"),
    ("ply_tristrips.ply", b"ply\nformat ascii 1.0\nelement vertex 0\n" + XYZ.encode() +
     b"element tristrips 1\nproperty list int int vertex_indices\nend_header\n",
     ":7: triangle strips ('tristrips') are not supported"),
    ("ply_ascii_index_out_of_range.ply", PLY_ASCII.replace("3 1 2 3", "3 1 2 7").encode(),
     ":17: vertex index 7, expected 0 to 3"),
    ("ply_binary_be_index_out_of_range.ply",
     ply_binary(">")[:-4] + struct.pack(">i", 1000), "vertex index 1000, expected 0 to 3"),
    ("ply_binary_negative_count.ply",
     ply_header("binary_little_endian", n_faces=1, face="property list int int vertex_indices\n")
     + b"".join(struct.pack("<3f", *v) for v in V) + struct.pack("<i", -5) + b"\0" * 12,
     "a 'vertex_indices' list of -5 values"),
    ("ply_binary_empty_faces.ply",  # found by fuzzing: assimp aborts the process on it
     ply_header("binary_little_endian") + b"".join(struct.pack("<3f", *v) for v in V)
     + b"\0" * 4, "byte 217: a face of no vertices in element 'face'"),
    # a binary float that is NaN or infinite, at its byte (the import named a vertex of
    # its own numbering, without the byte)
    ("ply_binary_nan_vertex.ply", ply_binary("<", [V[0], (1, float("nan"), 0)] + V[2:]),
     f"byte {len(ply_binary('<')) - 4 * 13 - 4 * 12 + 12 + 4}: expected a finite number for "
     "'y' of record 2 of element 'vertex', found NaN or infinity"),
    ("ply_binary_be_inf_vertex.ply", ply_binary(">", V[:3] + [(0, 0, float("inf"))]),
     "expected a finite number for 'z' of record 4 of element 'vertex', found NaN or infinity"),
    ("ply_ascii_bad_number.ply", PLY_ASCII.replace("1 0 0\n", "1 zero 0\n").encode(),
     ":11: expected a finite number for 'y' of element 'vertex'"),
    ("ply_ascii_extra_values.ply", PLY_ASCII.replace("0 1 0\n", "0 1 0 5\n").encode(),
     ":12: more values than element 'vertex' declares, from '5'"),
    ("ply_nul_in_header.ply", ply_header("ascii").replace(b"ascii", b"asc\0ii") +
     PLY_ASCII_BODY.encode(), ":2: a NUL byte"),
    # STL
    ("stl_empty.stl", b"", "the file is empty"),
    ("stl_short_garbage.stl", b"not a mesh at all\n",
     "neither an ASCII STL (which starts with 'solid') nor a binary one"),
    ("stl_binary_count_too_large.stl", STL_BINARY[:80] + struct.pack("<I", 1000000000) +
     STL_BINARY[84:], "header counts 1000000000 triangles, which take 84 + 50 x 1000000000"),
    ("stl_binary_truncated.stl", STL_BINARY[:-10], "header counts 4 triangles"),
    ("stl_binary_solid_header_truncated.stl", b"solid" + STL_BINARY[5:-10],
     "header counts 4 triangles"),
    ("stl_binary_nan_vertex.stl", STL_BINARY[:84 + 50 + 12 + 32] + struct.pack("<f", float("nan"))
     + STL_BINARY[84 + 50 + 12 + 36:],
     f"byte {84 + 50 + 12 + 32}: triangle 2: vertex 3 has a coordinate that is not a finite"),
    ("stl_ascii_truncated.stl", STL_ASCII[:150].encode(), "the file ends"),
    ("stl_ascii_no_endsolid.stl", STL_ASCII.replace("endsolid tetra\n", "").encode(),
     "the file ends inside a solid: expected 'endsolid'"),
    ("stl_ascii_four_vertices.stl", stl_ascii([TRIS[0] + [V[3]]] + TRIS[1:]).encode(),
     ":7: expected 'endloop' after a facet's three vertices, found 'vertex'"),
    ("stl_ascii_missing_outer_loop.stl", STL_ASCII.replace("    outer loop\n", "", 1).encode(),
     ":3: expected 'outer' after the facet normal, found 'vertex'"),
    ("stl_ascii_bad_number.stl", STL_ASCII.replace("vertex 0 1 0", "vertex 0 one 0", 1).encode(),
     ":5: expected three finite numbers after 'vertex'"),
    ("stl_ascii_garbage_after_solid.stl", ("solid x\n" + "f" * 100 + "\n").encode(),
     ":2: expected 'facet' or 'endsolid'"),
    # formats the check does not cover
    ("unsupported.xyz9", b"v 0 0 0\n", "unsupported mesh format '.xyz9'"),
    # formats only assimp reads: its own error, from its child process
    ("no_scene.gltf", b'{"asset": {"version": "2.0"}}', "cannot read as a mesh: GLTF: No scene"),
    ("corrupt.3ds", b"\x4d\x4d\x00\x00", "cannot read as a mesh: 3DS file is either empty"),
    ("no_extension", b"v 0 0 0\n", "unsupported mesh format '(no extension)'"),
]


def main():
    for f in os.listdir(HERE):
        if f not in ("make_bad_meshes.py", "bad_meshes.tsv"):
            os.remove(os.path.join(HERE, f))
    with open(os.path.join(HERE, "bad_meshes.tsv"), "w") as table:
        table.write("# file\ttext the message must contain (written by make_bad_meshes.py)\n")
        for name, content, expect in CASES:
            with open(os.path.join(HERE, name), "wb") as f:
                f.write(content)
            table.write(f"{name}\t{expect}\n")
    for endian, name in (("<", "le"), (">", "be")):
        with open(os.path.join(GOOD, f"tetra_binary_{name}.ply"), "wb") as f:
            f.write(ply_binary(endian))
    print(f"{len(CASES)} bad meshes")


if __name__ == "__main__":
    main()

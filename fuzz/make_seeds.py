#!/usr/bin/env python3
"""Writes the seed corpora of the fuzz targets into fuzz/corpus/<target>/.

Small valid inputs of every format a target reads (plus a few near misses);
rerun after changing the formats. Each seed stays under a few KB. The files
named found_* are inputs the fuzzers once failed on, kept as regression
seeds; this script does not write them."""
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

# ---- delimited text (fuzz_point_table: first byte 0 .csv, 1 .xyz, 2 .txt) ----------------------

CSV, XYZ, TXT = b"\x00", b"\x01", b"\x02"


def table_seeds():
    rows = ["%g,%g,%g" % p for p in POINTS]
    write("fuzz_point_table", "header.csv", CSV + ("x_mm,y_mm,z_mm\n" + "\n".join(rows) + "\n").encode())
    text = '"X";"Y";"Z";"nx";"ny";"nz"\n' + "".join("%g;%g;%g;%g;%g;%g\n" % (p + n) for p, n in zip(POINTS, NORMALS))
    write("fuzz_point_table", "semicolon_normals.csv", CSV + text.encode())
    text = "# scanner export\n\n" + "".join("%g\t%g\t%g\r\n" % p for p in POINTS)
    write("fuzz_point_table", "tabs_comments.csv", CSV + text.encode())
    write("fuzz_point_table", "spaces.xyz", XYZ + "".join("  %g %g  %g\n" % p for p in POINTS).encode())
    text = "".join("%.17g %.17g %.17g %g %g %g\n" % (p + n) for p, n in zip(POINTS, NORMALS))
    write("fuzz_point_table", "six_columns.txt", TXT + text.encode())
    text = "id,z,nz,y,ny,x,nx\n" + "".join("%d,%g,%g,%g,%g,%g,%g\n" % (i, p[2], n[2], p[1], n[1], p[0], n[0])
                                           for i, (p, n) in enumerate(zip(POINTS, NORMALS)))
    write("fuzz_point_table", "named_columns.csv", CSV + text.encode())

# ---- meshes (fuzz_mesh: first byte 0 .stl, 1 .obj, 2 .vtp, 3 .vtk, 4 .ply) ---------------------------------

STL, OBJ, VTP, LEGACY, PLY_MESH = b"\x00", b"\x01", b"\x02", b"\x03", b"\x04"
TETRA = [(0, 0, 0), (10, 0, 0), (0, 10, 0), (0, 0, 10)]
FACES = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]


def mesh_seeds():
    text = "solid tetra\n"
    for f in FACES:
        text += " facet normal 0 0 0\n  outer loop\n"
        text += "".join("   vertex %g %g %g\n" % TETRA[i] for i in f)
        text += "  endloop\n endfacet\n"
    write("fuzz_mesh", "ascii.stl", STL + (text + "endsolid tetra\n").encode())
    data = b"binary STL of a tetrahedron".ljust(80, b" ") + struct.pack("<I", len(FACES))
    for f in FACES:
        data += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *TETRA[i]) for i in f) + b"\0\0"
    write("fuzz_mesh", "binary.stl", STL + data)
    text = "# tetrahedron\no tetra\n" + "".join("v %g %g %g\n" % v for v in TETRA)
    text += "vn 0 0 -1\nvn 0 -1 0\nvn -1 0 0\nvn 0.577 0.577 0.577\nvt 0 0\nvt 1 0\nvt 0 1\n"
    text += "".join("f %d/%d/%d %d/%d/%d %d/%d/%d\n" % (f[0] + 1, 1, k + 1, f[1] + 1, 2, k + 1, f[2] + 1, 3, k + 1)
                    for k, f in enumerate(FACES))
    write("fuzz_mesh", "normals.obj", OBJ + text.encode())
    write("fuzz_mesh", "plain.obj", OBJ + ("".join("v %g %g %g\n" % v for v in TETRA) +
                                           "".join("f %d %d %d\n" % tuple(i + 1 for i in f) for f in FACES)).encode())
    points = " ".join("%g %g %g" % v for v in TETRA)
    normals = " ".join("%g %g %g" % n for n in NORMALS)
    polys = " ".join("%d %d %d" % f for f in FACES)
    text = """<?xml version="1.0"?>
<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" header_type="UInt32">
  <PolyData>
    <Piece NumberOfPoints="4" NumberOfVerts="0" NumberOfLines="0" NumberOfStrips="0" NumberOfPolys="4">
      <PointData Normals="Normals">
        <DataArray type="Float32" Name="Normals" NumberOfComponents="3" format="ascii">%s</DataArray>
      </PointData>
      <Points>
        <DataArray type="Float32" Name="Points" NumberOfComponents="3" format="ascii">%s</DataArray>
      </Points>
      <Polys>
        <DataArray type="Int32" Name="connectivity" format="ascii">%s</DataArray>
        <DataArray type="Int32" Name="offsets" format="ascii">3 6 9 12</DataArray>
      </Polys>
    </Piece>
  </PolyData>
</VTKFile>
""" % (normals, points, polys)
    write("fuzz_mesh", "ascii.vtp", VTP + text.encode())
    import base64
    raw = b"".join(struct.pack("<3d", *v) for v in TETRA)
    inline = base64.b64encode(struct.pack("<I", len(raw)) + raw).decode()
    appended = struct.pack("<I", len(raw)) + raw
    text = """<?xml version="1.0"?>
<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" header_type="UInt32">
  <PolyData>
    <Piece NumberOfPoints="4" NumberOfVerts="1" NumberOfPolys="0">
      <Points>
        <DataArray type="Float64" NumberOfComponents="3" format="binary">%s</DataArray>
      </Points>
      <Verts>
        <DataArray type="Int64" Name="connectivity" format="ascii">0 1 2 3</DataArray>
        <DataArray type="Int64" Name="offsets" format="ascii">4</DataArray>
      </Verts>
    </Piece>
  </PolyData>
</VTKFile>
""" % inline
    write("fuzz_mesh", "binary_base64.vtp", VTP + text.encode())
    text = """<?xml version="1.0"?>
<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" header_type="UInt32">
  <PolyData>
    <Piece NumberOfPoints="4">
      <Points>
        <DataArray type="Float64" NumberOfComponents="3" format="appended" offset="0"/>
      </Points>
    </Piece>
  </PolyData>
  <AppendedData encoding="raw">
   _""".encode() + appended + b"\n  </AppendedData>\n</VTKFile>\n"
    write("fuzz_mesh", "appended_raw.vtp", VTP + text)
    header = "# vtk DataFile Version 4.2\ntetrahedron\n"
    text = header + "ASCII\nDATASET POLYDATA\nPOINTS 4 float\n" + "".join("%g %g %g\n" % v for v in TETRA)
    text += "POLYGONS 4 16\n" + "".join("3 %d %d %d\n" % f for f in FACES)
    text += "POINT_DATA 4\nNORMALS Normals float\n" + "".join("%g %g %g\n" % n for n in NORMALS)
    write("fuzz_mesh", "ascii_legacy.vtk", LEGACY + text.encode())
    data = (header + "BINARY\nDATASET POLYDATA\nPOINTS 4 double\n").encode()
    data += b"".join(struct.pack(">3d", *v) for v in TETRA)
    data += b"\nPOLYGONS 4 16\n" + b"".join(struct.pack(">4i", 3, *f) for f in FACES) + b"\n"
    write("fuzz_mesh", "binary_legacy.vtk", LEGACY + data)
    # Version 5.1 as vtkPolyDataWriter writes it: offsets and connectivity, a strip, field and cell
    # data, CutThroughBone as colour scalars, and METADATA after the normals.
    header = "# vtk DataFile Version 5.1\ntetrahedron\n"
    field = "FIELD FieldData 1\nNames 1 2 string\n"
    text = header + "ASCII\nDATASET POLYDATA\n" + field + "left%20hip\n\n"
    text += "POINTS 4 float\n" + "".join("%g %g %g\n" % v for v in TETRA)
    text += "METADATA\nINFORMATION 1\nNAME L2_NORM_RANGE LOCATION vtkDataArray\nDATA 2 0 10\n\n"
    text += "POLYGONS 3 6\nOFFSETS vtktypeint64\n0 3 6\nCONNECTIVITY vtktypeint64\n0 2 1 0 1 3\n"
    text += "TRIANGLE_STRIPS 2 4\nOFFSETS vtktypeint64\n0 4\nCONNECTIVITY vtktypeint64\n0 3 2 1\n"
    text += "CELL_DATA 3\nSCALARS CellId int 1\nLOOKUP_TABLE default\n0 1 2\n"
    text += "POINT_DATA 4\nCOLOR_SCALARS CutThroughBone 1\n0 1 0 0.00392157\n"
    text += "NORMALS Normals float\n" + "".join("%g %g %g\n" % n for n in NORMALS)
    text += "METADATA\nCOMPONENT_NAMES\nx\ny\nz\n\nFIELD FieldData 1\nExtra 2 4 double\n0 1 2 3 4 5 6 7\n"
    write("fuzz_mesh", "ascii_legacy_51.vtk", LEGACY + text.encode())
    data = (header + "BINARY\nDATASET POLYDATA\n" + field).encode() + b"\xc8left hip\xc0\n"
    data += b"POINTS 4 double\n" + b"".join(struct.pack(">3d", *v) for v in TETRA)
    data += b"\nPOLYGONS 3 6\nOFFSETS vtktypeint64\n" + struct.pack(">3q", 0, 3, 6)
    data += b"\nCONNECTIVITY vtktypeint64\n" + struct.pack(">6q", 0, 2, 1, 0, 1, 3)
    data += b"\nTRIANGLE_STRIPS 2 4\nOFFSETS vtktypeint64\n" + struct.pack(">2q", 0, 4)
    data += b"\nCONNECTIVITY vtktypeint64\n" + struct.pack(">4q", 0, 3, 2, 1)
    data += b"\nCELL_DATA 3\nSCALARS CellId int 1\nLOOKUP_TABLE default\n" + struct.pack(">3i", 0, 1, 2)
    data += b"\nPOINT_DATA 4\nCOLOR_SCALARS CutThroughBone 1\n" + bytes([0, 1, 0, 1])
    data += b"\nNORMALS Normals float\n" + b"".join(struct.pack(">3f", *n) for n in NORMALS)
    data += b"\nMETADATA\nCOMPONENT_NAMES\nx\ny\nz\n\nFIELD FieldData 1\nExtra 2 4 double\n"
    data += struct.pack(">8d", *range(8)) + b"\n"
    write("fuzz_mesh", "binary_legacy_51.vtk", LEGACY + data)
    text = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
    text += "element face 4\nproperty list uchar int vertex_indices\nend_header\n"
    text += "".join("%g %g %g\n" % v for v in TETRA) + "".join("3 %d %d %d\n" % f for f in FACES)
    write("fuzz_mesh", "ascii_mesh.ply", PLY_MESH + text.encode())
    data = ("ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
            "property double z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n").encode()
    data += b"".join(struct.pack("<3d", *v) for v in TETRA)
    data += b"".join(struct.pack("<B3i", 3, *f) for f in FACES)
    write("fuzz_mesh", "binary_mesh.ply", PLY_MESH + data)

# ---- fits.json -------------------------------------------------------------------------------------


def fits_seeds():
    def model(name, radii, exponents=(2, 2, 2), cx=(1, 0, 0, 0), cy=(1, 0, 0, 0), angles=(0, 0, 0)):
        return {"model": name, "center_mm": [10.5, -3, 2], "radii_mm": list(radii), "rotation_deg": list(angles),
                "rotation_matrix": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "exponents": list(exponents),
                "cx": list(cx), "cy": list(cy), "rms_mm": 0.12, "converged": True, "termination": "xtol"}
    models = [model("sphere", (24, 24, 24)),
              model("ellipsoid", (24, 22, 20), angles=(10, -20, 90)),
              model("superellipsoid", (24, 22, 20), exponents=(2.5, 3, 2)),
              model("ovoid", (24, 22, 20), cx=(1, 0.2, 0.05, 0.01), cy=(0.9, 0.1, -0.05, 0)),
              model("superovoid", (25, 23, 21), exponents=(2, 2.2, 4), cx=(1, 0.1, 0, 0.02), cy=(1, 0, 0.1, 0))]
    write("fuzz_fits_json", "all_models.json", json.dumps({"best_model": "ovoid", "models": models}, indent=1))
    write("fuzz_fits_json", "sphere_only.json", json.dumps({"models": [model("sphere", (1, 1, 1))]}))
    minimal = {"models": [{"model": "ellipsoid", "center_mm": [0, 0, 0], "radii_mm": [3, 2, 1],
                           "rotation_deg": [0, 0, 0], "exponents": [2, 2, 2], "cx": [1, 0, 0, 0],
                           "cy": [1, 0, 0, 0]}]}
    write("fuzz_fits_json", "minimal.json", json.dumps(minimal))
    with open(os.path.join(os.path.dirname(ROOT), "..", "testdata", "contact", "head_fits.json"), "rb") as f:
        write("fuzz_fits_json", "testdata_head.json", f.read())

# ---- contact pairs -----------------------------------------------------------------------------


def pairs_seeds():
    with open(os.path.join(os.path.dirname(ROOT), "..", "testdata", "contact", "pairs.csv"), "rb") as f:
        full = f.read()
    write("fuzz_contact_pairs", "testdata.csv", full)
    header = full.split(b"\n", 1)[0].decode()
    rows = ["0,0,0,1,0,0,0,2,2,2,2,2,2,Sphere,4,0,0,1,0,0,0,1,1,1,,,,,,",
            "0,0,0,2,0,0,0,2,2,2,2,2,2,ellipsoid,0,5,0,1,0,0,0,1,2,3,,,,,,",
            "0,0,0,1,0,0,0,2,2,2,4,3,2.5,superellipsoid,4,0,0,0.7071067811865476,0,0,0.7071067811865476,1,1,1,2,6,2,,,",
            "0,0,0,1,0,0,0,2,2,2,2,2,2,PLANE,0,0,-3,,,,,,,,,,,0,0,1",
            "0,0,0,0,0,0,0,2,2,2,2,2,2,,4,0,0,1,0,0,0,1,1,1,2,2,2,,,",
            "",
            "1e300,0,0,1,0,0,0,2,2,2,2,2,2,,4,0,0,1,0,0,0,1,1,1,2,2,2,,,"]
    write("fuzz_contact_pairs", "kinds.csv", header + "\n" + "\n".join(rows) + "\n")
    write("fuzz_contact_pairs", "no_shape_b.csv",
          "cx_a,cy_a,cz_a,qw_a,qx_a,qy_a,qz_a,ra_a,rb_a,rc_a,g1_a,g2_a,g3_a,"
          "cx_b,cy_b,cz_b,qw_b,qx_b,qy_b,qz_b,ra_b,rb_b,rc_b,g1_b,g2_b,g3_b\r\n"
          "0,0,0,1,0,0,0,3,2,1,2,2,2,5,0,0,1,0,0,0,1,1,1,2,2,2\r\n"
          " 0 , 0 , 0 ,1,0,0,0,3,2,1,2,2,2,5,0,0,1,0,0,0,1,1,1,2,2\r\n")

# ---- manifests ---------------------------------------------------------------------------------


def manifest_seeds():
    write("fuzz_manifest", "options.csv",
          "subject,input,joint,side,seed_point,max_head_radius_mm\n"
          's1,data/s1.nii.gz,hip,left,"1,2,3",\n'
          "s2,/abs/s2.nrrd,shoulder,right,,30\n"
          "# a comment\n\n"
          "s-3.b,dicom/s3,,,,\n")
    write("fuzz_manifest", "bom_quotes.csv",
          "\ufeffsubject,input,joint,side\r\n"
          '"q1","x, y.nii",hip,left\r\n'
          'b,"multi\nline.nii",hip,right\r\n')
    write("fuzz_manifest", "plain.csv", "subject,input,joint,side\nA01,a01.mha,hip,right\nA02,../a02.nii,hip,left\n")

# ---- NIfTI (fuzz_nifti: first byte even .nii, odd .nii.gz) ------------------------------------


def nifti1(order, datatype, bitpix, fmt, values, qform=True, sform=False):
    h = bytearray(348)
    struct.pack_into(order + "i", h, 0, 348)
    struct.pack_into(order + "8h", h, 40, 3, 4, 4, 4, 1, 1, 1, 1)
    struct.pack_into(order + "hh", h, 70, datatype, bitpix)
    struct.pack_into(order + "8f", h, 76, 1, 0.8, 0.8, 1.25, 1, 1, 1, 1)
    struct.pack_into(order + "f", h, 108, 352)
    struct.pack_into(order + "ff", h, 112, 1, -1024)
    h[123] = 2  # mm
    h[148:148 + 12] = b"fuzz seed   "
    struct.pack_into(order + "hh", h, 252, 1 if qform else 0, 1 if sform else 0)
    struct.pack_into(order + "6f", h, 256, 0, 0, 0, -10, 20, 30)
    struct.pack_into(order + "12f", h, 280, -0.8, 0, 0, 10, 0, -0.8, 0, 20, 0, 0, 1.25, -30)
    h[344:348] = b"n+1\0"
    return bytes(h) + b"\0\0\0\0" + b"".join(struct.pack(order + fmt, v) for v in values)


def nifti2(values):
    h = bytearray(540)
    struct.pack_into("<i", h, 0, 540)
    h[4:12] = b"n+2\0\r\n\x1a\n"
    struct.pack_into("<hh", h, 12, 4, 16)
    struct.pack_into("<8q", h, 16, 3, 4, 4, 4, 1, 1, 1, 1)
    struct.pack_into("<8d", h, 104, 1, 1, 1, 1, 1, 1, 1, 1)
    struct.pack_into("<q", h, 168, 544)
    struct.pack_into("<d", h, 176, 1)
    struct.pack_into("<ii", h, 344, 1, 0)
    struct.pack_into("<ii", h, 500, 0, 2)
    return bytes(h) + b"\0\0\0\0" + b"".join(struct.pack("<h", v) for v in values)


def nifti_seeds():
    ramp = [(i * 37) % 2000 - 1000 for i in range(64)]
    seeds = {
        "int16_le": nifti1("<", 4, 16, "h", ramp),
        "int16_be_sform": nifti1(">", 4, 16, "h", ramp, qform=False, sform=True),
        "float32": nifti1("<", 16, 32, "f", [float(v) for v in ramp]),
        "uint8_no_transform": nifti1("<", 2, 8, "B", [v & 0xFF for v in range(64)], qform=False),
        "nifti2_int16": nifti2(ramp),
    }
    for name, data in seeds.items():
        write("fuzz_nifti", name + ".nii", b"\x00" + data)
        write("fuzz_nifti", name + ".nii.gz", b"\x01" + gzip.compress(data, mtime=0))


# ---- DICOM (fuzz_dicom: two slices, the first's length in two bytes) ---------------------------


def dicom_slice(z, syntax="1.2.840.10008.1.2", preamble=True, rows=4, columns=4, encapsulated=False):
    explicit = syntax != "1.2.840.10008.1.2"
    big = syntax == "1.2.840.10008.1.2.2"
    order = ">" if big else "<"

    def element(group, elem, vr, value, meta=False):
        if isinstance(value, str):
            value = value.encode()
            if len(value) % 2:
                value += b"\0" if vr == "UI" else b" "
        o = "<" if meta else order
        tag = struct.pack(o + "HH", group, elem)
        if meta or explicit:
            if vr in ("OB", "OW", "SQ", "UN", "UT"):
                return tag + vr.encode() + b"\0\0" + struct.pack(o + "I", len(value)) + value
            return tag + vr.encode() + struct.pack(o + "H", len(value)) + value
        return tag + struct.pack(o + "I", len(value)) + value

    def us(v):
        return struct.pack(order + "H", v)

    uid = "1.2.826.0.1.3680043.2.1143.1"
    meta_body = (element(2, 0x1, "OB", b"\0\1", True) + element(2, 0x2, "UI", "1.2.840.10008.5.1.4.1.1.2", True) +
                 element(2, 0x3, "UI", uid + ".%d" % z, True) + element(2, 0x10, "UI", syntax, True))
    meta = element(2, 0, "UL", struct.pack("<I", len(meta_body)), True) + meta_body
    pixels = b"".join(struct.pack(order + "h", (i * 37 + z * 11) % 2000 - 1000) for i in range(rows * columns))
    if encapsulated:  # a basic offset table and one fragment: not a real codestream
        pixel_data = (struct.pack("<HHHHI", 0x7FE0, 0x10, 0x424F, 0, 0xFFFFFFFF) + struct.pack("<HHI", 0xFFFE, 0xE000, 0) +
                      struct.pack("<HHI", 0xFFFE, 0xE000, 8) + b"\xff\x4f\xff\x51\0\0\xff\xd9" +
                      struct.pack("<HHI", 0xFFFE, 0xE0DD, 0))
    else:
        pixel_data = element(0x7FE0, 0x10, "OW", pixels)
    data = (element(8, 0x16, "UI", "1.2.840.10008.5.1.4.1.1.2") + element(8, 0x18, "UI", uid + ".%d" % z) +
            element(8, 0x60, "CS", "CT") + element(0x20, 0xD, "UI", uid + ".7") + element(0x20, 0xE, "UI", uid + ".8") +
            element(0x20, 0x13, "IS", str(z + 1)) + element(0x20, 0x32, "DS", "-10\\20\\%g" % (2.5 * z)) +
            element(0x20, 0x37, "DS", "1\\0\\0\\0\\1\\0") + element(0x28, 0x2, "US", us(1)) +
            element(0x28, 0x4, "CS", "MONOCHROME2") + element(0x28, 0x10, "US", us(rows)) +
            element(0x28, 0x11, "US", us(columns)) + element(0x28, 0x30, "DS", "0.8\\0.8") +
            element(0x28, 0x100, "US", us(16)) + element(0x28, 0x101, "US", us(16)) + element(0x28, 0x102, "US", us(15)) +
            element(0x28, 0x103, "US", us(1)) + element(0x28, 0x1052, "DS", "0") + element(0x28, 0x1053, "DS", "1") +
            pixel_data)
    return (b"\0" * 128 + b"DICM" + meta if preamble else b"") + data


def dicom_seeds():
    variants = {
        "implicit_le": {},
        "explicit_le": {"syntax": "1.2.840.10008.1.2.1"},
        "explicit_be": {"syntax": "1.2.840.10008.1.2.2"},
        "no_preamble": {"preamble": False},
        "jpeg2000_fragment": {"syntax": "1.2.840.10008.1.2.4.90", "encapsulated": True},
    }
    for name, options in variants.items():
        first, second = dicom_slice(0, **options), dicom_slice(1, **options)
        write("fuzz_dicom", name, struct.pack("<H", len(first)) + first + second)


# ---- MetaImage and NRRD (fuzz_image_header: first byte even .mha, odd .nrrd) ---------------------


def image_header_seeds():
    n = 4
    ramp = b"".join(struct.pack("<h", (i * 37) % 2000 - 1000) for i in range(n ** 3))
    mha = ("ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n{}"
           "TransformMatrix = 1 0 0 0 1 0 0 0 1\nOffset = -10 20 30\nDimSize = 4 4 4\n"
           "ElementSpacing = 0.8 0.8 1.25\nElementType = MET_SHORT\nElementDataFile = LOCAL\n")
    write("fuzz_image_header", "raw.mha", b"\0" + mha.format("").encode() + ramp)
    write("fuzz_image_header", "zlib.mha", b"\0" + mha.format("CompressedData = True\n").encode() + __import__("zlib").compress(ramp))
    nrrd = ("NRRD0004\ntype: short\ndimension: 3\nspace: left-posterior-superior\nsizes: 4 4 4\n"
            "space directions: (0.8,0,0) (0,0.8,0) (0,0,1.25)\nspace origin: (-10,20,30)\nendian: little\n"
            "encoding: {}\n\n")
    write("fuzz_image_header", "raw.nrrd", b"\1" + nrrd.format("raw").encode() + ramp)
    write("fuzz_image_header", "gzip.nrrd", b"\1" + nrrd.format("gzip").encode() + gzip.compress(ramp, mtime=0))


def scene_seeds():
    scenes = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes")
    for name in sorted(os.listdir(scenes)):
        with open(os.path.join(scenes, name)) as f:
            scene = json.load(f)
        scene.pop("description", None)
        write("fuzz_scene", name, json.dumps(scene))
    write("fuzz_scene", "superellipsoid_plane.json", json.dumps({
        "duration": 1, "bodies": [{"name": "b", "mass": 1, "inertia": [1, 1, 1]}],
        "contacts": [{"body": "b", "shape": {"model": "superellipsoid", "radii": [1, 1, 2], "exponents": [2, 3, 4]},
                      "against": {"plane": {"normal": [0, 0, 1]}},
                      "normal_law": {"law": "lankarani-nikravesh", "stiffness": 1e6, "restitution": 0.8, "impact_speed": 1},
                      "friction": {"dynamic": 0.2, "static": 0.3, "viscous": 0.1}}]}))


def main():
    ply_seeds()
    table_seeds()
    mesh_seeds()
    fits_seeds()
    pairs_seeds()
    manifest_seeds()
    nifti_seeds()
    dicom_seeds()
    image_header_seeds()
    scene_seeds()


if __name__ == "__main__":
    sys.exit(main())

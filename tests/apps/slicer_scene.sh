#!/usr/bin/env bash
# scene.mrml against what 3D Slicer's readers need: the MRML root and its
# version, node types Slicer registers, unique ids, references that resolve
# to nodes of the right kind, files that exist beside the scene, LPS stated
# in the scene and in every file (VTP field data SPACE, PLY comment), the
# signed distances as a one-component point array shown through the scene's
# own diverging colour table over a symmetric range; and every markups file
# valid under Slicer's markups schema (v1.0.3), one markup per scene node.
# fixtures: demo
# labels: full-size
source "$(dirname "$0")/common.bash"
src=${ARTICULA_SOURCE:?}
/usr/bin/python3 -c "import jsonschema" 2> /dev/null || fail "python3-jsonschema is not installed (scripts/install-deps.sh)"

/usr/bin/python3 - "${ARTICULA_FIXTURES:?}/demo/demo/run" "$src/testdata/slicer/markups-schema-v1.0.3.json" <<'PY'
import base64, json, os, re, sys, zlib
import xml.etree.ElementTree as ET
import jsonschema

run, schema_path = sys.argv[1], sys.argv[2]
root = ET.parse(os.path.join(run, "scene.mrml")).getroot()
assert root.tag == "MRML"
assert re.fullmatch(r"Slicer \d+\.\d+\.\d+ [1-9]\d*", root.get("version", "")), root.get("version")

# Tags Slicer 5 registers (the class name less vtkMRML and Node).
storage_of = {"Model": "ModelStorage", "MarkupsFiducial": "MarkupsJsonStorage", "MarkupsLine": "MarkupsJsonStorage"}
display_of = {"Model": {"ModelDisplay"}, "MarkupsFiducial": {"MarkupsFiducialDisplay"},
              "MarkupsLine": {"MarkupsDisplay", "MarkupsLineDisplay"}}
known = set(storage_of) | set(storage_of.values()) | {d for s in display_of.values() for d in s} | {"ColorTable"}
nodes = {}
for e in root:
    assert e.tag in known, e.tag
    assert e.get("id") and e.get("id") not in nodes, e.get("id")
    nodes[e.get("id")] = e
booleans = ("visibility", "visibility2D", "visibility3D", "scalarVisibility")
for e in root:
    for b in booleans:
        assert e.get(b) in (None, "true", "false"), (e.get("id"), b, e.get(b))

def vtp_field_and_arrays(path):
    text = open(path, "rb").read().decode("latin-1")
    space = re.search(r'<FieldData>.*?<Array type="String" Name="SPACE"([^>]*?)(/>|>\s*(\S+)\s*</Array>)', text, re.S)
    assert space, f"{path}: no SPACE field data"
    attributes, _, payload = space.groups()
    fmt = re.search(r'format="(\w+)"', attributes).group(1)
    if fmt == "ascii":
        value = bytes(int(c) for c in payload.split()).rstrip(b"\0").decode()
    elif fmt == "appended":  # raw bytes after "_": a length header, then the string
        assert 'encoding="raw"' in text and "compressor=" not in text, path
        width = 8 if 'header_type="UInt64"' in text else 4
        start = text.index("_", text.index("<AppendedData")) + 1 + int(re.search(r'offset="(\d+)"', attributes).group(1))
        size = int.from_bytes(text[start:start + width].encode("latin-1"), "little")
        value = text[start + width:start + width + size].rstrip("\0")
    else:  # binary: a zlib header block, then base64 of the compressed string
        header, body = payload.split("==", 1) if "==" in payload else (payload[:24], payload[24:])
        raw = base64.b64decode(header + "==")
        value = zlib.decompress(base64.b64decode(body)).decode().rstrip("\0")
    point_data = re.search(r"<PointData[^>]*>(.*?)</PointData>", text, re.S)
    arrays = dict(re.findall(r'<DataArray[^>]*Name="([^"]+)"[^>]*NumberOfComponents="(\d+)"', point_data.group(1))) if point_data else {}
    for name in re.findall(r'<DataArray[^>]*Name="([^"]+)"', point_data.group(1) if point_data else ""):
        arrays.setdefault(name, "1")
    n_verts = int(re.search(r'NumberOfVerts="(\d+)"', text).group(1))
    return value, arrays, n_verts

schema = json.load(open(schema_path))
shown_points = 0
for e in root:
    refs = dict(part.split(":", 1) for part in e.get("references", "").split(";") if part)
    if e.tag in storage_of:
        assert set(refs) == {"display", "storage"}, (e.get("id"), refs)
        display, storage = nodes[refs["display"]], nodes[refs["storage"]]
        assert display.tag in display_of[e.tag] and storage.tag == storage_of[e.tag], (e.tag, display.tag, storage.tag)
        assert storage.get("coordinateSystem") == "LPS", storage.get("id")
        path = os.path.join(run, storage.get("fileName"))
        assert os.path.isfile(path), path
        if e.tag == "Model":
            if path.endswith(".vtp"):
                space, arrays, n_verts = vtp_field_and_arrays(path)
                assert space == "LPS", (path, space)
            else:
                head = open(path, "rb").read(400).decode("latin-1")
                assert "comment SPACE=LPS" in head, path
                arrays, n_verts = {}, 0
            if display.get("scalarVisibility") == "true":
                name = display.get("activeScalarName")
                assert arrays.get(name) == "1", (path, name, arrays)
                assert display.get("activeAttributeLocation") == "point"
                assert n_verts > 0 and display.get("representation") == "0", path  # drawn as points
                lo, hi = (float(v) for v in display.get("scalarRange").split())
                assert display.get("scalarRangeFlag") == "UseManual" and hi > 0 and abs(lo + hi) < 1e-9, (lo, hi)
                table = nodes[display.get("colorNodeID")]
                assert table.tag == "ColorTable" and table.get("type") == "13"
                attributes = list(table.keys())
                assert attributes.index("type") < attributes.index("numcolors") < attributes.index("colors")
                entries = table.get("colors").split()
                assert len(entries) == 6 * int(table.get("numcolors")) == 6 * 256
                first, middle, last = ([float(v) for v in entries[6 * i + 2:6 * i + 5]] for i in (0, 128, 255))
                assert first[0] > first[2] and last[2] > last[0], (first, last)  # red inside, blue outside
                assert abs(middle[0] - middle[2]) < 0.1, middle                     # grey at 0
                shown_points += display.get("visibility") == "true"
        else:
            doc = json.load(open(path))
            jsonschema.validate(doc, schema)
            assert re.search(r"markups-schema-v1\.\d+\.\d+\.json#?$", doc["@schema"]), doc["@schema"]
            assert len(doc["markups"]) == 1, path  # Slicer reads item 0 into the node
            assert "Markups" + doc["markups"][0]["type"] == e.tag, (path, e.tag)
            assert doc["markups"][0]["coordinateSystem"] == "LPS"
models = [e.get("name") for e in root if e.tag == "Model"]
assert "bone" in models and len([m for m in models if m.endswith(" points")]) == 5 and len([m for m in models if m.endswith(" fitted")]) == 5, models
assert shown_points == 1, shown_points  # the selected model's points
assert sum(e.tag == "MarkupsFiducial" for e in root) == 1 and sum(e.tag == "MarkupsLine" for e in root) == 3
# head.mrk.json (all markups in one file, for drag and drop) is valid too.
jsonschema.validate(json.load(open(os.path.join(run, "head.mrk.json"))), schema)
print("scene ok:", len(nodes), "nodes")
PY

#!/usr/bin/env bash
# The stage table: `articula stages --json` lists the stages in run order with
# their options, inputs and outputs; every listed option is one of run's; the
# report stage runs on its own (articula-report) as run runs it; a stage
# option out of its range stops run before any stage.
# fixtures: sphere
# labels: full-size
source "$(dirname "$0")/common.bash"

expect_rc 0 "$bin/articula" stages --json
cp "$tmp/out" "$tmp/stages.json"
"$bin/articula" run --help > "$tmp/run-help.txt"
python3 - "$tmp/stages.json" "$tmp/run-help.txt" <<'PY'
import json, sys
stages = json.load(open(sys.argv[1]))["stages"]
names = [s["name"] for s in stages]
assert names == ["segment", "mesh", "sample", "fit", "errors", "report"], names
by = {s["name"]: s for s in stages}
options = {s["name"]: [o["name"] for o in s["options"]] for s in stages}
assert "series-uid" in options["segment"] and "series-uid" in options["mesh"]
assert "smoothing" in options["mesh"], by["mesh"]
assert options["report"] == ["series-uid", "selection-alpha", "selection-length"], by["report"]
assert by["report"]["outputs"] == ["results.json", "results.csv", "head.mrk.json", "report.html", "scene.mrml"]
assert "CT" in by["mesh"]["inputs"]
# Every stage's command line names the files it reads and the first it writes
# (the others go beside it: fits.csv beside fits.json); the report reads its folder.
for s in stages:
    line = " ".join(s["arguments"])
    for f in s["inputs"] + s["outputs"][:1]:
        token = "{CT}" if f == "CT" else "{folder}/" + f.split("/")[0]
        assert token in line or (s["name"] == "report" and "{folder}" in line), (s["name"], f, line)
assert by["segment"]["arguments"][:4] == ["-i", "{CT}", "-o", "{folder}/label.nii.gz"], by["segment"]
help_text = open(sys.argv[2]).read()
for s in stages:
    for o in s["options"]:
        assert f"--{o['run_name']}" in help_text, f"run does not take --{o['run_name']}"
PY

# The seed-5 sphere phantom and its run, made once for several tests; the
# run is copied, as the report stage is rerun on it below.
ct="${ARTICULA_FIXTURES:?}/sphere/phantom/phantom.nii.gz"
cp -r "$ARTICULA_FIXTURES/sphere/run" "$tmp/r"
selected=$(python3 -c "import json; print(json.load(open('$tmp/r/results.json'))['selected_model'])")

# The report stage alone: refuses to overwrite, then redoes run's report
# (same numbers), and takes its options.
expect_rc 2 "$bin/articula-report" -i "$tmp/r" --ct "$ct"
grep -q "refusing to overwrite .*results.json" "$tmp/err" || fail "report overwrite message: $(cat "$tmp/err")"
cp "$tmp/r/results.csv" "$tmp/run-results.csv"
expect_rc 0 "$bin/articula-report" -i "$tmp/r" --ct "$ct" --force
cmp "$tmp/r/results.csv" "$tmp/run-results.csv" || fail "articula-report and run's report differ"
python3 - "$tmp/r/results.json" "$selected" "$tmp/r/head.mrk.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
assert r["selected_model"] == sys.argv[2], (r["selected_model"], sys.argv[2])
assert "articula-report -i " in r["provenance"]["command"], r["provenance"]["command"]
assert r["qc"]["status"] in ("pass", "warn"), r["qc"]
# The head's centre and axes are the selected model's, in results.json and
# in the Slicer markups alike.
model = next(m for m in r["models"] if m["model"] == r["selected_model"])
centre = [model["parameters"][k] for k in ("t1_mm", "t2_mm", "t3_mm")]
assert max(abs(a - b) for a, b in zip(r["head_center_mm"], centre)) < 1e-9, (r["head_center_mm"], centre)
markups = json.load(open(sys.argv[3]))["markups"]
points = markups[0]
assert points["controlPoints"][0]["label"] == "head_center", points
assert max(abs(a - b) for a, b in zip(points["controlPoints"][0]["position"], centre)) < 1e-6, points
assert r["selected_model"] + " head" in json.dumps(markups), [m.get("name") for m in markups]
PY
# report.html: self-contained (no script, stylesheet or image from elsewhere;
# a policy that forbids requests),
# its numbers those of results.json, both error figures inline.
python3 - "$tmp/r/report.html" "$tmp/r/results.json" <<'PY'
import json, os, re, sys
html, r = open(sys.argv[1]).read(), json.load(open(sys.argv[2]))
assert html.startswith("<!DOCTYPE html>") and html.rstrip().endswith("</html>")
assert not re.search(r'<(link|img|iframe)\b|<script[^>]*\bsrc\b', html), "external content"
assert "content=\"default-src 'none';" in html, "no content security policy"
assert not re.search(r'\b(src|href)\s*=\s*"(?!#|data:image/png;base64,)', html), "a reference leaves the page"
# Nine CT slices, three per plane (through the centre and half a radius to
# either side), each an embedded PNG with the label's edge and the model's
# outline, orientation letters, a 10 mm scale bar and its position.
import base64, struct
slices = re.findall(r'<svg[^>]*class="slice" data-plane="(\w+)".*?href="data:image/png;base64,([^"]+)".*?'
                    r'class="label-edge" d="([^"]*)".*?class="model-outline" d="([^"]*)"', html, re.S)
assert [s[0] for s in slices] == ["axial"] * 3 + ["coronal"] * 3 + ["sagittal"] * 3, [s[0] for s in slices]
letters = re.findall(r'<g class="orientation"[^>]*>(.*?)</g>', html)
assert len(letters) == 9 and all(re.findall(r">([A-Z])</text>", g) for g in letters), letters[:1]
assert re.findall(r">([A-Z])</text>", letters[0]) == ["R", "L", "A", "P"], letters[0]
assert re.findall(r">([A-Z])</text>", letters[8]) == ["A", "P", "S", "I"], letters[8]
assert html.count('class="scale-bar"') == 9 and ">10 mm</text>" in html
captions = re.findall(r"<figcaption>((?:axial|coronal|sagittal)[^<]*)</figcaption>", html)
assert len(captions) == 9 and captions[1].startswith("axial, z = ") and captions[1].endswith("(centre)"), captions
for plane, png, edge, outline in slices:
    png = base64.b64decode(png)
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and png[12:16] == b"IHDR", plane
    width, height = struct.unpack(">II", png[16:24])
    assert width == height and 32 <= width <= 1024, (plane, width, height)
    assert edge.count("M") > 20 and outline.count("M") > 20, (plane, edge[:80], outline[:80])
assert len(html) < 5e6, len(html)
selected = r["selected_model"]
assert re.search(r'id="selected-model">%s<' % selected, html)
model = next(m for m in r["models"] if m["model"] == selected)
assert re.search(r'id="rms">%.3f<' % model["errors"]["rms_mm"], html), "RMS differs from results.json"
for m in r["models"]:
    assert re.search(r'data-model="%s"><td>%s</td><td>%d</td><td class="rms">%.3f<' % (
        m["model"], m["model"], m["n_parameters"], m["errors"]["rms_mm"]), html), m["model"]
# Semi-axes through the centre: the radii, or an ovoid's a c0x, b c0y, c.
for m in r["models"]:
    p, axes = m["parameters"], m["semi_axes_mm"]
    want = [p["a_mm"] * p.get("c0x", 1), p.get("b_mm", p["a_mm"]) * p.get("c0y", 1), p.get("c_mm", p["a_mm"])]
    assert all(abs(x - y) <= 1e-9 * y for x, y in zip(axes, want)), (m["model"], axes, want)
    if "c0x" in p and m["model"] == selected:
        assert re.search(r'id="semi-axes">' + r'(?: &plusmn; [0-9.]+)?, '.join("%.2f" % x for x in axes), html), "semi-axes not shown"
        assert "An egg's centre and semi-axes lie on its equator" in html, "the egg's intervals are not qualified"
        assert "within the likelihood-ratio bound (%d here)" % m["other_optima_spanned"] in html, "the other optima are not counted"
assert 'class="status %s"' % r["qc"]["status"] in html
# The selection's evidence: the hierarchy's five steps, each a nested F test
# with the points' n_eff at the selection's correlation length, and the tests
# that chose the model; on the page as a table; the least-RMS model named
# only where it is another.
sel = r["selection"]
assert [(st["simpler"], st["richer"]) for st in sel["steps"]] == [
    ("sphere", "ellipsoid"), ("ellipsoid", "superellipsoid"), ("ellipsoid", "ovoid"),
    ("superellipsoid", "superovoid"), ("ovoid", "superovoid")], sel["steps"]
by_model = {m["model"]: m for m in r["models"]}
for st in sel["steps"] + sel["path"]:
    assert 0 <= st["p_value"] <= 1 and st["f"] >= 0 and st["richer_needed"] == (st["p_value"] < st["alpha"]), st
    assert st["n_eff"] == sel["n_eff"], st  # one count of the points for every test
    assert 1 <= st["n_eff"] <= by_model[st["richer"]]["errors"]["n_points"], st
# Errors shared over 4 mm leave a cap of this head (R about 23 mm) some tens
# of independent points: about its area over 2 pi L^2.
assert sel["length_mm"] == 4 and 20 <= sel["n_eff"] <= 150, sel["n_eff"]
assert sel["path"] and sel["path"][0]["simpler"] == "sphere", sel["path"]
# No richer model beats the selected one: its own tests all fail.
assert not any(st["richer_needed"] for st in sel["path"] if st["simpler"] == selected), sel["path"]
assert selected not in sel["undetermined"]
assert html.count('<tr class="step">') == 5 and html.count('<tr class="path">') == len(sel["path"]), "selection table"
assert ('id="least-rms"' in html) == (r["least_rms_model"] != selected)
assert "best" not in re.sub(r"<[^>]+>", "", html.split('id="verdict"')[1].split("</section>")[0]).lower()
assert html.count("<svg") >= 2, "the error figures are not inline"
methods = re.search(r'<p id="methods">(.*?)</p>', html, re.S).group(1)
assert "The %s was selected" % selected in methods and r["provenance"]["git_commit"] in methods, methods
# The methods name the edge model the mesh stage used.
edges = json.load(open(os.path.join(os.path.dirname(sys.argv[2]), "bone.vtp.json")))["ct_edges"]
assert ("blurred-cortex model" in methods) == (edges["edge_model"] == "cortex"), methods
assert "steepest fall" in methods, methods
PY
expect_rc 0 "$bin/articula-report" -i "$tmp/r" --ct "$ct" --force --selection-alpha 0
grep -q '"selected_model": "sphere"' "$tmp/r/results.json" || fail "--selection-alpha 0 should select the sphere"

# With the blurred-cortex edges (the default on voxels up to 0.8 mm; asked
# for here), the methods say so, with the point-spread the mesh stage used.
expect_rc 0 "$bin/articula-mesh" -i "$tmp/r/label.nii.gz" -o "$tmp/r/bone.vtp" --ct "$ct" --edge-model cortex --force
expect_rc 0 "$bin/articula-report" -i "$tmp/r" --ct "$ct" --force
python3 - "$tmp/r/report.html" "$tmp/r/bone.vtp.json" <<'PY'
import json, re, sys
methods = re.search(r'<p id="methods">(.*?)</p>', open(sys.argv[1]).read(), re.S).group(1)
edges = json.load(open(sys.argv[2]))["ct_edges"]
assert edges["edge_model"] == "cortex" and edges["point_spread_estimated"], edges
assert "blurred-cortex model" in methods and "estimated from the CT: %.2f mm within the slices and %.2f mm across" % (
    edges["point_spread_mm"], edges["slice_point_spread_mm"]) in methods, methods
PY

# The mesh stage's fallback from the cortex model (no point-spread estimated:
# the edges on the steepest falls), as its sidecar records it, is a named
# check of the report, not a terminal line only.
python3 - "$tmp/r/bone.vtp.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["ct_edges"]["cortex_model_note"] = "the CT's point-spread could not be estimated from 12 edges; the edges are the steepest falls"
json.dump(d, open(sys.argv[1], "w"), indent=2)
PY
expect_rc 0 "$bin/articula-report" -i "$tmp/r" --ct "$ct" --force
python3 - "$tmp/r/results.json" <<'PY'
import json, sys
check = next(c for c in json.load(open(sys.argv[1]))["qc"]["checks"] if c["name"] == "stage_warnings")
assert check["status"] == "warn" and "mesh: the CT's point-spread could not be estimated" in check["reason"], check
PY
# So is the sample stage's: articular vertices on the label's cut through
# bone kept; two fifths of the points on the cut fail the head.
cp "$tmp/r/points.ply.json" "$tmp/points.ply.json.kept"
python3 - "$tmp/r/points.ply.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
assert d["cut_through_bone_kept"] == 0 and d["cut_through_bone_left_out"] >= 0, d
d["cut_through_bone_kept"] = round(0.4 * d["selected_points"])
d["warnings"] = ["60 of 150 articular vertices lie where the label ends inside bone (no edge in the CT), and without them fewer than 100 would remain: all are kept"]
json.dump(d, open(sys.argv[1], "w"), indent=2)
PY
expect_rc 1 "$bin/articula-report" -i "$tmp/r" --ct "$ct" --force
grep -q "articular points lie where the label was cut" "$tmp/err" || fail "the report's failure: $(cat "$tmp/err")"
python3 - "$tmp/r/results.json" <<'PY'
import json, sys
checks = {c["name"]: c for c in json.load(open(sys.argv[1]))["qc"]["checks"]}
assert "sample: 60 of 150 articular vertices lie where the label ends inside bone" in checks["stage_warnings"]["reason"], checks
assert checks["articular_points_on_cut"]["status"] == "fail" and abs(checks["articular_points_on_cut"]["value"] - 0.4) < 0.01, checks
PY
mv "$tmp/points.ply.json.kept" "$tmp/r/points.ply.json"

# The segmentation's label marks its cut through bone (its sidecar counts
# the voxels), and the mesh stage carries the marks onto the surface; a
# label without articula's sidecar is bone wherever it is not 0.
cuts=$(python3 -c "import json; print(json.load(open('$tmp/r/label.nii.gz.json'))['cut_through_bone_voxels'])")
[ "$cuts" -gt 0 ] || fail "the sphere phantom's label marks no cut through its neck"
mkdir -p "$tmp/own" "$tmp/other"
cp "$tmp/r/label.nii.gz" "$tmp/r/label.nii.gz.json" "$tmp/own/"
cp "$tmp/r/label.nii.gz" "$tmp/other/"
expect_rc 0 "$bin/articula-mesh" -i "$tmp/own/label.nii.gz" -o "$tmp/own/bone.vtp"
expect_rc 0 "$bin/articula-mesh" -i "$tmp/other/label.nii.gz" -o "$tmp/other/bone.vtp"
grep -q 'Name="CutThroughBone"' "$tmp/own/bone.vtp" || fail "the mesh of articula's label carries no cut"
! grep -q 'Name="CutThroughBone"' "$tmp/other/bone.vtp" || fail "a label without articula's sidecar was read as marking its cut"

# A missing stage output: exit 3, named; nothing written.
mkdir -p "$tmp/r2/errors"
cp "$tmp/r/points.ply" "$tmp/r2/"
cp "$tmp/r/errors/summary.json" "$tmp/r2/errors/"
expect_rc 3 "$bin/articula-report" -i "$tmp/r2" --ct "$ct"
grep -q "needs '.*fits.json', which is missing" "$tmp/err" || fail "missing fits.json message: $(cat "$tmp/err")"
[ ! -e "$tmp/r2/results.json" ] || fail "a results.json was written without fits"

# A report option out of range stops run before its first stage.
expect_rc 2 "$bin/articula" run -i "$ct" -o "$tmp/r3" --selection-alpha 5
grep -q "the report stage: --selection-alpha" "$tmp/err" || fail "run names the stage: $(cat "$tmp/err")"
[ ! -e "$tmp/r3/label.nii.gz" ] || fail "run segmented before refusing the option"
echo "stages: ok"

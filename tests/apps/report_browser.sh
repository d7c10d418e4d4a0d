#!/usr/bin/env bash
# The pages in a real browser (Debian's Chromium, headless, software WebGL)
# with the network off: each subject's report.html and the study's
# study.html open without a console message or a blocked request, the 3-D
# view draws a picture that is not blank (the page's own count of drawn
# pixels, and a screenshot's), every link of study.html resolves, and the
# report's numbers are results.json's.
# fixtures: demo
# labels: full-size
source "$(dirname "$0")/common.bash"
command -v chromium > /dev/null || fail "chromium is not installed (scripts/install-deps.sh installs it)"

# browse URL ARGS...: Chromium headless, no network (every host unresolvable,
# a dead proxy), its console on stderr.
browse() {
  local url=$1; shift
  timeout 180 chromium --headless=new --no-sandbox --disable-gpu --use-angle=swiftshader --enable-unsafe-swiftshader \
    --no-first-run --user-data-dir="$tmp/chromium-profile" --host-resolver-rules="MAP * ~NOTFOUND" \
    --proxy-server="127.0.0.1:9" --enable-logging=stderr --v=0 --virtual-time-budget=10000 "$@" "$url"
}

# check_console FILE: no console message from the page; the software
# renderer's note that reading pixels back stalls (the view's own pixel
# count) is the one allowed.
check_console() {
  if grep ':CONSOLE' "$1" | grep -v 'GL Driver Message (OpenGL, Performance' > /dev/null; then
    grep ':CONSOLE' "$1" >&2
    fail "console messages on $2"
  fi
}

# The demo's full-size run, and a study of a small phantom (its edges on the
# steepest fall: a quarter of the time) with a missing subject.
"$bin/articula" phantom -o "$tmp/data/p1" --seed 4 --model ovoid --side left --spacing 1.2,1.2,1.5 --no-dicom --quiet
cat > "$tmp/study.csv" <<CSV
subject,input,joint,side,edge_model
p1,data/p1/phantom.nii.gz,hip,left,steepest
missing,data/nowhere.nii.gz,hip,right,steepest
CSV
set +e
"$bin/articula" batch "$tmp/study.csv" -o "$tmp/study" --quiet 2> /dev/null
rc=$?
set -e
[ "$rc" -eq 1 ] || fail "the batch with a missing input exited $rc, expected 1"

for run in "${ARTICULA_FIXTURES:?}/demo/demo/run" "$tmp/study/subjects/p1"; do
  page="file://$run/report.html"
  size=$(stat -c %s "$run/report.html")
  [ "$size" -le 5000000 ] || fail "$run/report.html is $size bytes (at most 5 MB)"
  # One start of the browser for the page's DOM and its screenshot (each
  # start takes about 6 s here).
  rm -f "$tmp/shot.png"
  browse "$page" --window-size=1100,1400 --dump-dom --screenshot="$tmp/shot.png" > "$tmp/dom.html" 2> "$tmp/console.err" ||
    { tail "$tmp/console.err" >&2; fail "chromium on $page"; }
  [ -s "$tmp/shot.png" ] || fail "no screenshot of $page"
  check_console "$tmp/console.err" "$page"
  python3 - "$tmp/dom.html" "$run/results.json" "$tmp/shot.png" <<'PY'
import html, json, re, struct, sys, zlib
dom = open(sys.argv[1]).read()
results = json.load(open(sys.argv[2]))

# The page's own record: no script error, no blocked request; the view ready.
head = re.search(r"<html[^>]*>", dom).group(0)
assert "data-page-problems" not in head, html.unescape(head)
assert re.search(r'<section id="view3d"[^>]*data-ready="true"', dom), "the 3-D view did not finish"
drawn = int(re.search(r'data-rendered-pixels="(\d+)"', dom).group(1))
assert drawn > 0.02 * 960 * 600, f"the 3-D view drew {drawn} pixels"
assert not re.search(r'<(script|img|link|iframe)[^>]*\b(src|href)="(https?:)?//', dom), "an external resource"

# The report's numbers are results.json's.
def cell(id_):
    return html.unescape(re.search(r'id="%s">(.*?)</td>' % id_, dom, re.S).group(1))
selected = results["selected_model"]
assert cell("selected-model") == selected
model = next(m for m in results["models"] if m["model"] == selected)
centre = [float(v) for v in re.findall(r"(-?\d+\.\d+) ±", cell("head-centre"))]
for shown, key in zip(centre, ("t1_mm", "t2_mm", "t3_mm")):
    assert abs(shown - model["parameters"][key]) <= 0.005 + 1e-9, (shown, key, model["parameters"][key])
assert abs(float(cell("rms")) - model["errors"]["rms_mm"]) <= 0.0005 + 1e-9
status = re.search(r'<p class="status (\w+)">', dom).group(1)
assert status == results["qc"]["status"], (status, results["qc"]["status"])
for reason in results["qc"].get("reasons", []):
    assert html.escape(reason, quote=True)[:60] in dom or reason[:60] in html.unescape(dom), reason
for m in results["models"]:
    row = re.search(r'<tr data-model="%s">.*?<td class="rms">([-0-9.]+)</td>' % m["model"], dom, re.S)
    assert row and abs(float(row.group(1)) - m["errors"]["rms_mm"]) <= 0.0005 + 1e-9, m["model"]

# The screenshot: the canvas (its dark background) holds a drawing.
def png_rgb(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, width = 8, b"", 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and colour in (2, 6), (depth, colour)
            channels = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw, stride, rows, prev = zlib.decompress(idat), width * channels, [], bytearray(width * channels)
    for y in range(height):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b, c = prev[i], prev[i - channels] if i >= channels else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c; pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line)); prev = line
    return width, height, channels, rows
w, h, ch, rows = png_rgb(sys.argv[3])
background = (0x20, 0x23, 0x2a)
xs, ys = [], []
for y in range(0, h, 2):
    for x in range(0, w, 2):
        p = rows[y][x * ch:x * ch + 3]
        if sum(abs(p[k] - background[k]) for k in range(3)) <= 6:
            xs.append(x); ys.append(y)
assert len(xs) > 1000, "no canvas in the screenshot"
x0, x1, y0, y1 = min(xs), max(xs), min(ys), max(ys)
inside = [rows[y][x * ch:x * ch + 3] for y in range(y0, y1, 2) for x in range(x0, x1, 2)]
drawn = sum(1 for p in inside if sum(abs(p[k] - background[k]) for k in range(3)) > 24)
assert drawn > 0.02 * len(inside), f"the canvas is blank in the screenshot ({drawn} of {len(inside)})"
print(f"report ok: {drawn} of {len(inside)} canvas samples drawn")
PY
done

# study.html: no console message, every link resolves to a file of the study;
# the review desk starts from the study's ratings.csv and writes the same
# file back (the reviewer's "Save ratings.csv").
printf 'subject,decision,note\np1,include,"checked, ""fine"""\n' > "$tmp/study/ratings.csv"
"$bin/articula" batch "$tmp/study.csv" -o "$tmp/study" --gather-only --quiet 2> /dev/null || true
browse "file://$tmp/study/study.html" --dump-dom > "$tmp/study-dom.html" 2> "$tmp/study-console.err"
check_console "$tmp/study-console.err" study.html
python3 - "$tmp/study-dom.html" "$tmp/study" <<'PY'
import html, os, re, sys, urllib.parse
dom, study = open(sys.argv[1]).read(), sys.argv[2]
saved = html.unescape(re.search(r'<textarea id="ratings-csv"[^>]*>(.*?)</textarea>', dom, re.S).group(1))
assert saved == open(os.path.join(study, "ratings.csv")).read(), saved
assert "data-page-problems" not in re.search(r"<html[^>]*>", dom).group(0)
links = re.findall(r'href="([^"#]*)', dom)
assert len(links) >= 5, links
for link in links:
    assert not re.match(r"[a-z]+:", link), link
    assert os.path.isfile(os.path.join(study, urllib.parse.unquote(link))), link
assert "subjects/p1/report.html" in links
print(f"study ok: {len(links)} links")
PY

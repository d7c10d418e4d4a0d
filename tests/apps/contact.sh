#!/usr/bin/env bash
# articula contact end to end: the pairs CSV of testdata/contact (analytic
# answers), per-row statuses for bad rows, exit code 3 when no row is valid,
# and a thesis table 5.3 motion with warm starts.
set -euo pipefail
python3() { /usr/bin/python3 "$@"; }  # Debian's, as common.bash binds it
bin="$ARTICULA_BIN/articula"
mkdir -p "$ARTICULA_TMP"
out="$ARTICULA_TMP/contacts.csv"

"$bin" contact --pairs "$ARTICULA_SOURCE/testdata/contact/pairs.csv" -o "$out" --force --json -q > "$ARTICULA_TMP/summary.json"
grep -q '"ns_per_query"' "$ARTICULA_TMP/summary.json"
grep -q '"valid_rows": 6' "$ARTICULA_TMP/summary.json"
[ "$(wc -l < "$out")" -eq 10 ] || { echo "expected 9 rows + header"; exit 1; }
head -1 "$out" | grep -qx 'distance,pax,pay,paz,pbx,pby,pbz,nx,ny,nz,iterations,status'
# Expected distances per data row (invalid rows: status invalid).
expected=(1 -0.5 4 -0.5 1 invalid invalid invalid 1)
for i in "${!expected[@]}"; do
  row=$(sed -n "$((i + 2))p" "$out")
  want=${expected[$i]}
  if [ "$want" = invalid ]; then
    [ "${row##*,}" = invalid ] || { echo "row $((i + 1)): expected invalid, got $row"; exit 1; }
  else
    awk -F, -v w="$want" '{ d = $1 - w; if (d < 0) d = -d; exit !(d < 1e-12 && $12 == "converged") }' <<< "$row" \
      || { echo "row $((i + 1)): expected distance $want, got $row"; exit 1; }
  fi
done

# Many rows over two threads: the same file as on one, the threads reported.
many="$ARTICULA_TMP/many.csv"
python3 - "$ARTICULA_SOURCE/testdata/contact/pairs.csv" "$many" <<'PY'
import math, random, sys
header = open(sys.argv[1]).readline().strip()
cols = header.split(",")
rng = random.Random(7)
with open(sys.argv[2], "w") as f:
    f.write(header + "\n")
    for _ in range(400):
        row = {c: "" for c in cols}
        for side, dx in (("a", 0.0), ("b", rng.uniform(0.5, 3.0))):
            q = [rng.gauss(0, 1) for _ in range(4)]
            n = math.sqrt(sum(v * v for v in q))
            row.update({f"cx_{side}": dx, f"cy_{side}": rng.uniform(-0.5, 0.5), f"cz_{side}": 0,
                        f"qw_{side}": q[0] / n, f"qx_{side}": q[1] / n, f"qy_{side}": q[2] / n, f"qz_{side}": q[3] / n,
                        f"ra_{side}": rng.uniform(0.5, 1.5), f"rb_{side}": rng.uniform(0.5, 1.5), f"rc_{side}": rng.uniform(0.5, 1.5),
                        f"g1_{side}": 2, f"g2_{side}": 2, f"g3_{side}": 2})
        f.write(",".join(str(row[c]) for c in cols) + "\n")
PY
"$bin" contact --pairs "$many" -o "$ARTICULA_TMP/many1.csv" --force -q --threads 1
"$bin" contact --pairs "$many" -o "$ARTICULA_TMP/many2.csv" --force -q --threads 2 --json > "$ARTICULA_TMP/many2.json"
cmp "$ARTICULA_TMP/many1.csv" "$ARTICULA_TMP/many2.csv" || { echo "two threads wrote another file"; exit 1; }
grep -q '"threads": 2' "$ARTICULA_TMP/many2.json" || { echo "threads not reported"; exit 1; }
grep -q '"valid_rows": 400' "$ARTICULA_TMP/many2.json" || { echo "expected 400 valid rows"; cat "$ARTICULA_TMP/many2.json"; exit 1; }

# shape_b kinds (case-insensitive): a sphere or an ellipsoid may leave its
# exponents empty; a sphere with unequal radii, an ellipsoid with exponent 3,
# an unknown kind and a superellipsoid without exponents are invalid rows.
kinds="$ARTICULA_TMP/kinds.csv"
{ head -1 "$ARTICULA_SOURCE/testdata/contact/pairs.csv"
  echo '0,0,0,1,0,0,0,2,2,2,2,2,2,Sphere,4,0,0,1,0,0,0,1,1,1,,,,,,'
  echo '0,0,0,1,0,0,0,2,2,2,2,2,2,ellipsoid,0,5,0,1,0,0,0,1,2,3,,,,,,'
  echo '0,0,0,1,0,0,0,2,2,2,2,2,2,sphere,4,0,0,1,0,0,0,1,2,3,,,,,,'
  echo '0,0,0,1,0,0,0,2,2,2,2,2,2,ellipsoid,4,0,0,1,0,0,0,1,1,1,3,,,,,'
  echo '0,0,0,1,0,0,0,2,2,2,2,2,2,cube,4,0,0,1,0,0,0,1,1,1,2,2,2,,,'
  echo '0,0,0,1,0,0,0,2,2,2,2,2,2,PLANE,0,0,-3,,,,,,,,,,,0,0,1'
  echo '0,0,0,1,0,0,0,2,2,2,2,2,2,superellipsoid,4,0,0,1,0,0,0,1,1,1,,,,,,'; } > "$kinds"
"$bin" contact --pairs "$kinds" -o "$ARTICULA_TMP/kinds_out.csv" --force 2> "$ARTICULA_TMP/kinds.err"
awk -F, 'NR > 1 { s = s $1 ":" $12 " " } END { if (s != "1:converged 1:converged nan:invalid nan:invalid nan:invalid 1:converged nan:invalid ") { print "kinds: " s; exit 1 } }' \
  "$ARTICULA_TMP/kinds_out.csv"
grep -q 'kinds.csv:4: shape_b is sphere: expected ra_b = rb_b = rc_b, found 1, 2, 3' "$ARTICULA_TMP/kinds.err"
grep -q "kinds.csv:6: shape_b: expected plane, sphere, ellipsoid, superellipsoid or empty, found 'cube'" "$ARTICULA_TMP/kinds.err"

# Only bad rows: exit code 3 and no output file.
bad="$ARTICULA_TMP/bad.csv"
{ head -1 "$ARTICULA_SOURCE/testdata/contact/pairs.csv"; sed -n '7,9p' "$ARTICULA_SOURCE/testdata/contact/pairs.csv"; } > "$bad"
set +e
"$bin" contact --pairs "$bad" -o "$ARTICULA_TMP/bad_out.csv" --force 2> "$ARTICULA_TMP/bad.err"
rc=$?
set -e
[ "$rc" -eq 3 ] || { echo "expected exit code 3, got $rc"; exit 1; }
grep -q 'bad.csv:2:' "$ARTICULA_TMP/bad.err"
[ ! -e "$ARTICULA_TMP/bad_out.csv" ]

# Table 5.3-3 motion: 200 warm-started steps, all converged, few iterations each.
"$bin" contact --scenario table5.3-3 -o "$ARTICULA_TMP/motion.csv" --force --json -q > "$ARTICULA_TMP/motion.json"
grep -q '"converged_steps": 200' "$ARTICULA_TMP/motion.json"
[ "$(wc -l < "$ARTICULA_TMP/motion.csv")" -eq 201 ]
awk -F'[:,]' '/iterations_per_warm_step/ { exit !($2 < 8) }' "$ARTICULA_TMP/motion.json"
# The same motion with the thesis' common-normal solver: same distances.
"$bin" contact --scenario table5.3-3 --solver common-normal -o "$ARTICULA_TMP/motion_cn.csv" --force --json -q \
  > "$ARTICULA_TMP/motion_cn.json"
grep -q '"converged_steps": 200' "$ARTICULA_TMP/motion_cn.json"
paste -d, "$ARTICULA_TMP/motion.csv" "$ARTICULA_TMP/motion_cn.csv" | awk -F, -v n="$(head -1 "$ARTICULA_TMP/motion.csv" | tr , '\n' | wc -l)" \
  'NR > 1 { d = $2 - $(n + 2); if (d < 0) d = -d; if (d > 1e-10) { print "step " $1 ": " $2 " vs " $(n + 2); bad = 1 } } END { exit bad }'
echo "contact app: OK"

# Two fitted surfaces: the head ellipsoid (rotated 90 deg about z: extent 22 mm
# along x) at x = 10 and the superellipsoid (exponent 4, radius 25) at x = 70,
# moved -5 mm by --pose-b: gap (65 - 25) - (10 + 22) = 8 mm.
"$bin" contact --fits-a "$ARTICULA_SOURCE/testdata/contact/head_fits.json" \
  --fits-b "$ARTICULA_SOURCE/testdata/contact/cup_fits.json" --pose-b -5,0,0,0,0,0 \
  -o "$ARTICULA_TMP/fits.csv" --force -q
awk -F, 'NR == 2 { d = $1 - 8; if (d < 0) d = -d; exit !(d < 1e-9 && $12 == "converged") }' "$ARTICULA_TMP/fits.csv"
set +e
"$bin" contact --fits-a "$ARTICULA_SOURCE/testdata/contact/head_fits.json" \
  --fits-b "$ARTICULA_SOURCE/testdata/contact/cup_fits.json" --model-b superovoid -o "$ARTICULA_TMP/ovoid.csv" --force -q
rc=$?
set -e
[ "$rc" -eq 2 ] || { echo "superovoid: expected usage error 2, got $rc"; exit 1; }
echo "contact fits: OK"

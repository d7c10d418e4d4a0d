#!/usr/bin/env bash
# The driver's shared conventions: --version, exit codes 0/1/2/3, --config,
# --force, --json, atomic outputs. Run by ctest as app_driver.
source "$(dirname "$0")/common.bash"

expect_rc 0 "$bin/articula" --version
grep -q "articula 0\.[0-9]*\.[0-9]* (commit " "$tmp/out" || fail "--version prints version and commit"
expect_rc 0 "$bin/articula" surface --version

# Usage errors: exit 2.
expect_rc 2 "$bin/articula"
expect_rc 2 "$bin/articula" no-such-command
expect_rc 2 "$bin/articula" surface --model cube -o "$tmp/x.ply"
grep -q "unknown shape model 'cube'" "$tmp/err" || fail "unknown model message"
expect_rc 2 "$bin/articula" surface --resolution 2 -o "$tmp/x.ply"
expect_rc 2 "$bin/articula" surface --radii 1,2 -o "$tmp/x.ply"

# Invalid parameters: exit 3, naming the parameter; no output left behind.
expect_rc 3 "$bin/articula" surface --model superellipsoid --exponents 2,1.5,2 -o "$tmp/bad.ply"
grep -q "'gamma2'" "$tmp/err" || fail "message names gamma2"
expect_rc 3 "$bin/articula" surface --model ellipsoid --radii 20,-1,20 -o "$tmp/bad.ply"
grep -q "'b'" "$tmp/err" || fail "message names b"
[ ! -e "$tmp/bad.ply" ] || fail "no output for invalid parameters"

# A good run: the PLY is complete, no temporary file remains, --json on stdout.
expect_rc 0 "$bin/articula" surface --model ellipsoid --radii 30,24,18 --center 1,2,3 --resolution 32 -o "$tmp/e.ply" --json
python3 - "$tmp/out" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
assert s["vertices"] == 2 + 15 * 32, s["vertices"]
assert s["max_abs_F_at_vertices"] < 1e-12
assert abs(s["curvature_max_per_mm"] - 30 / 18**2) < 1e-9, s["curvature_max_per_mm"]
assert abs(s["curvature_min_per_mm"] - 18 / 30**2) < 1e-9, s["curvature_min_per_mm"]
assert s["provenance"]["coordinate_system"] == "LPS"
PY
head -3 "$tmp/e.ply" | grep -q "LPS" || fail "PLY says LPS"
ls -A "$tmp" | grep -q "tmp-" && fail "temporary file left behind"

# Existing output without --force: exit 2 and the file is untouched.
before=$(sha256sum "$tmp/e.ply")
expect_rc 2 "$bin/articula" surface -o "$tmp/e.ply"
[ "$before" = "$(sha256sum "$tmp/e.ply")" ] || fail "existing output changed"

# --config: option values from a file (CLI11 TOML).
printf 'model = "sphere"\nradii = [21.0]\nresolution = 16\n' > "$tmp/surface.toml"
expect_rc 0 "$bin/articula" surface --config "$tmp/surface.toml" -o "$tmp/s.ply" --json --quiet
python3 -c "import json,sys; s=json.load(open('$tmp/out')); assert abs(s['curvature_max_per_mm']-1/21)<1e-12, s" || fail "--config values used"
[ ! -s "$tmp/err" ] || fail "--quiet prints nothing on stderr"
echo "driver: ok"

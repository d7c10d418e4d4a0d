#!/usr/bin/env bash
# Hostile and careless input: each case exits with its documented code, says
# what was wrong, and leaves nothing behind that looks complete.
source "$(dirname "$0")/common.bash"
A="$bin/articula"

# Points of a 22 mm sphere cap.
python3 - "$tmp/head.csv" <<'PY'
import math, random, sys
random.seed(1)
with open(sys.argv[1], "w") as f:
    f.write("x,y,z\n")
    for _ in range(300):
        t, p = random.uniform(0, 1.2), random.uniform(0, 2 * math.pi)
        f.write(f"{22 * math.sin(t) * math.cos(p)},{22 * math.sin(t) * math.sin(p)},{22 * math.cos(t)}\n")
PY
cp "$tmp/head.csv" "$tmp/head.orig"

# An output that is an input: fit's table beside head.json would be head.csv, the input.
expect_rc 2 "$A" fit -i "$tmp/head.csv" -o "$tmp/head.json" --force
grep -q "would overwrite the input" "$tmp/err" || fail "fit over its input: $(cat "$tmp/err")"
cmp -s "$tmp/head.csv" "$tmp/head.orig" || fail "fit overwrote its input points"
[ ! -e "$tmp/head.json" ] || fail "fit wrote head.json before refusing"
expect_rc 2 "$A" sample -i "$tmp/head.csv" -o "$tmp/head.csv" --force
cmp -s "$tmp/head.csv" "$tmp/head.orig" || fail "sample overwrote its input"

# A fits.json whose models are 10^5 nested arrays: a message, not a stack overflow.
python3 -c "import sys; sys.stdout.write('{\"models\": ' + '[' * 100000 + ']' * 100000 + '}')" > "$tmp/deep.json"
expect_rc 3 "$A" errors -i "$tmp/head.csv" --fits "$tmp/deep.json" -o "$tmp/deep"
grep -q "expected an object, found an array" "$tmp/err" || fail "nested JSON: $(head -c 300 "$tmp/err")"

# A 10^6-character model name with terminal escapes: a short, escaped excerpt.
python3 -c "import sys; sys.stdout.write('{\"models\": [{\"model\": \"\\\\u001b[31m' + 'x' * 1000000 + '\"}]}')" > "$tmp/big.json"
expect_rc 3 "$A" errors -i "$tmp/head.csv" --fits "$tmp/big.json" -o "$tmp/big"
[ "$(wc -c < "$tmp/err")" -lt 400 ] || fail "the message echoes $(wc -c < "$tmp/err") bytes of input"
grep -q 'unknown shape model' "$tmp/err" || fail "big name: $(head -c 300 "$tmp/err")"
if grep -q $'\x1b' "$tmp/err"; then fail "an escape sequence reached stderr raw"; fi
grep -q '\\x1b' "$tmp/err" || fail "the escape is not shown escaped"

# errors -o over a folder holding one of its outputs from another run: refused before any file is written.
"$A" fit -i "$tmp/head.csv" -o "$tmp/fits.json" -q
mkdir -p "$tmp/mixed" && echo old > "$tmp/mixed/points_superovoid.ply"
expect_rc 2 "$A" errors -i "$tmp/head.csv" --fits "$tmp/fits.json" -o "$tmp/mixed"
grep -q "points_superovoid.ply' exists" "$tmp/err" || fail "mixed outputs: $(cat "$tmp/err")"
[ "$(ls "$tmp/mixed")" = "points_superovoid.ply" ] || fail "errors wrote beside an old output: $(ls "$tmp/mixed")"
# Contact pairs far beyond the solver's range (a centre at 1e300, radii of
# 1e300, crossing needles of axes 1e-9 and 1e9): each row refused by line
# (a bad row is skipped and named; only bad rows: exit 3 and no output).
pairs="$tmp/far.csv"
{ head -1 "$ARTICULA_SOURCE/testdata/contact/pairs.csv"
  echo "1e300,0,0,1,0,0,0,2,2,2,2,2,2,,4,0,0,1,0,0,0,1,1,1,2,2,2,,,"
  echo "0,0,0,1,0,0,0,1e300,2,2,2,2,2,,4,0,0,1,0,0,0,1,1,1,2,2,2,,,"
  echo "0,0,0,1,0,0,0,1e9,1e-9,1e-9,2,2,2,,0,0,0,0.7071067811865476,0,0,0.7071067811865476,1e9,1e-9,1e-9,2,2,2,,,"
} > "$pairs"
expect_rc 3 "$A" contact --pairs "$pairs" -o "$tmp/far_out.csv"
for line in 2 3 4; do grep -q "far.csv:$line:" "$tmp/err" || fail "contact row $line not named: $(cat "$tmp/err")"; done
grep -q "1e-06 to 1e+06 mm\|1e-6 to 1e6 mm" "$tmp/err" || fail "contact: the range is not stated: $(cat "$tmp/err")"
[ ! -e "$tmp/far_out.csv" ] || fail "contact wrote an output of refused rows"
echo "bad input: ok"

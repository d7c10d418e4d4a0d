#!/usr/bin/env bash
# articula-fit and articula-errors on a real femoral head: the Visible Human
# Female cartilage shell (../shared/data). All its vertices are fitted (the
# joint surface and the bone side, about 1-2 mm apart), so RMS is about half
# the thickness; the sphere radius must be an adult femoral head's (20-28 mm)
# and RMS ordered as the hierarchy guarantees.
source "$(dirname "$0")/common.bash"
data=${ARTICULA_SHARED_DATA:-}
mesh="$data/meshes/femoral-head-cartilage/VHF_Left_Cartilage_FemurHead_smooth.stl"
[ -f "$mesh" ] || { echo "skipped: $mesh not found"; exit 77; }
csv_value() {
  awk -F, -v m="$2" -v c="$3" 'NR==1{for(i=1;i<=NF;i++) if($i==c) col=i; next} $1==m{print $col}' "$1"
}

"$bin/articula-fit" -i "$mesh" -o "$tmp/fits.json" -q
r=$(csv_value "$tmp/fits.csv" sphere a_mm)
awk -v r="$r" 'BEGIN{exit !(r > 20 && r < 28)}' || fail "sphere radius $r mm outside 20-28"
rms() { csv_value "$tmp/fits.csv" "$1" rms_mm; }
le() { awk -v a="$(rms "$1")" -v b="$(rms "$2")" 'BEGIN{exit !(a <= b + 1e-9)}' || fail "rms $1 > rms $2"; }
le ellipsoid sphere; le superellipsoid ellipsoid; le ovoid ellipsoid; le superovoid superellipsoid; le superovoid ovoid
awk -v a="$(rms sphere)" 'BEGIN{exit !(a > 0.2 && a < 2.0)}' || fail "sphere rms $(rms sphere) mm implausible"

"$bin/articula-errors" -i "$mesh" --fits "$tmp/fits.json" -o "$tmp/err" -q
e=$(csv_value "$tmp/err/summary.csv" superovoid rms_mm)
awk -v a="$e" -v b="$(rms superovoid)" 'BEGIN{d=a-b; if(d<0)d=-d; exit !(d < 1e-6)}' || fail "errors vs fit rms"
echo "fit_real: sphere r = $r mm; rms sphere $(rms sphere), superovoid $(rms superovoid) mm"

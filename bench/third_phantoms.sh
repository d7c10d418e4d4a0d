#!/usr/bin/env bash
# `articula run` on CT phantoms of a third, independent generator
# (bench/third_phantom.py): hips with deep non-congruent sockets, rotated
# femurs and both hips in one field of view; shoulders with small shallow
# glenoids; point-sampled and partial-volume voxels, Gaussian, box and
# Lorentzian blur, correlated noise, cupping, int16 with slope/intercept,
# oblique and RAS storage, cropped fields of view with and without air;
# clinical voxels up to 2 x 2 x 3 mm; a lag screw, flattened domes, low-dose
# noise and heads clipped by the field of view (the K cases).
# Each head is correct (articular points' RMS to the true head <= half the
# in-plane voxel and >= 95 % within 1.5 mm), refused (exit != 0), wrong but
# warned (exit 0, a check of the head or its surface warned: not only the
# side's) or SILENTLY WRONG (exit 0, not correct, no such warning), with the
# qc status beside it. Prints a markdown table; phantoms are cached in WORK.
#   bash bench/third_phantoms.sh [build/bin] [WORK] [case-regex]
set -uo pipefail
bin=$(cd "${1:-build/bin}" && pwd)
work=${2:-$(mktemp -d)}
filter=${3:-.}
here=$(cd "$(dirname "$0")" && pwd)
py=${PYTHON:-/usr/bin/python3}  # Debian's, with python3-numpy and python3-scipy
mkdir -p "$work"
cd "$work"
# NAME | sides run | generator options
cases=(
"H01|right|joint=hip side=right seed=101 R=23 gap=2.5 cover=105 excess=1.5 spacing=0.7,0.7,1.0 sub=2"
"H02|left|joint=hip side=left seed=102 R=17 gap=1.5 cover=110 excess=0.5 cortex=0.6 cort_hu=600 trab_hu=150 spacing=0.5,0.5,0.6 sub=1 noise=25 fov=55,55,55"
"H03|right|joint=hip side=right seed=103 R=30 gap=5 cover=120 excess=0.5 cortex=2.5 cort_hu=1500 trab_hu=400 spacing=1.0,1.0,3.0 blur=box blur_xy=1.0 blur_z=3.0 fov=80,80,80"
"H04|right|joint=hip side=right seed=104 R=26 axes=1.06,0.95,1.0 head_rot=20,10,30 gap=2 cover=110 excess=3 orient=ras spacing=0.7,0.7,1.25"
"H05|left|joint=hip side=left seed=105 R=24 gap=3 femur_rot=30,0,0 av=35 el=30 orient=obl obl=12,-8,15 hdr=qform spacing=0.8,0.8,1.0"
"H06|right|joint=hip side=right seed=106 R=22 gap=2 femur_rot=0,25,0 blur=lorentz blur_xy=0.25 blur_z=0.5 store=int16 slope=0.5 inter=-1024 spacing=0.6,0.6,1.0 fov=65,65,65"
"H07|left|joint=hip side=left seed=107 R=25 gap=2.5 cupping=80 noise=40 noise_corr=0.8 spacing=0.8,0.8,1.25"
"H08|right|joint=hip side=right seed=108 R=23 gap=2 air=0 fov=55,55,40 fov_shift=0,0,12 spacing=0.7,0.7,1.0"
"H09|left|joint=hip side=left seed=109 R=21 gap=2 cortex=0.6 cort_hu=500 trab_hu=100 tex=60 spacing=0.8,0.8,1.25 noise=20"
"H10|right|joint=hip side=right seed=110 R=27 gap=3 cortex=3.0 cort_hu=1500 trab_hu=400 spacing=0.6,0.6,0.6 sub=3 fov=62,62,62"
"H11|right|joint=hip side=right seed=111 R=20 gap=1.5 cover=115 excess=0 spacing=0.7,0.7,1.0 noise=10"
"H12|left|joint=hip side=left seed=112 R=28 gap=4 cover=100 excess=2 store=float32 orient=oblras obl=0,0,20 spacing=0.9,0.9,2.0 blur_z=1.5"
"H13|right|joint=hip side=right seed=113 R=19 gap=1.5 cover=125 excess=1 cortex=0.8 cort_hu=800 trab_hu=200 spacing=1.0,1.0,1.25 sub=1"
"H14|left|joint=hip side=left seed=114 R=29 axes=0.95,1.0,1.07 head_rot=0,30,0 gap=3 cover=110 excess=4 spacing=0.75,0.75,1.5 blur=box blur_xy=0.8 blur_z=1.5"
"H15|right|joint=hip side=right seed=115 R=24 gap=2 femur_rot=-20,0,35 av=-10 el=50 spacing=0.7,0.7,1.0 cupping=50 inter=-1024"
"H16|left|joint=hip side=left seed=116 R=22 gap=2 cortex=1.0 pcortex=2.5 pcort_hu=1500 ptrab_hu=450 cort_hu=700 trab_hu=150 spacing=0.7,0.7,1.0"
"H17|right|joint=hip side=right seed=117 R=25 gap=1.8 air=0 fov=60,60,60 cupping=60 noise=30 store=int16 slope=2 inter=-1000 spacing=0.9,0.9,1.25"
"H18|left|joint=hip side=left seed=118 R=18 gap=2.5 cover=130 excess=2 spacing=0.6,0.6,0.8 sub=1 blur=gauss blur_xy=0.3 blur_z=0.6 fov=50,50,55"
"H19|right|joint=hip side=right seed=119 R=26 gap=3.5 head_rot=45,0,0 axes=1.0,0.93,1.08 spacing=0.8,0.8,1.0 orient=obl obl=0,20,0 hdr=both"
"H20|left|joint=hip side=left seed=120 R=23 gap=2 fov=60,60,45 fov_shift=0,0,18 cortex=0.7 cort_hu=900 spacing=0.7,0.7,2.5 blur_z=2.0"
"B1|right left|joint=hip both=1 side=right seed=201 R=23 gap=2.5 cover=110 excess=1.5 fov=175,75,70 spacing=0.8,0.8,1.5"
"B2|right left|joint=hip both=1 side=left seed=202 R=27 gap=2 cover=105 excess=2.5 femur_rot=20,0,15 fov=175,75,70 spacing=1.0,1.0,2.0 blur=box blur_xy=1.0 blur_z=2.0 sub=1"
"B3|right left|joint=hip both=1 side=right seed=203 R=20 gap=1.5 cover=115 excess=1 air=0 cupping=70 noise=25 fov=160,70,60 spacing=0.9,0.9,1.25"
"B4|right left|joint=hip both=1 side=left seed=204 R=25 gap=3 orient=obl obl=5,5,10 store=int16 slope=0.5 inter=-1024 fov=175,75,70 spacing=0.8,0.8,1.0 cortex=0.8 cort_hu=700"
"S01|right|joint=shoulder side=right seed=301 R=22 gap=3 excess=8 fov=75,75,75 spacing=0.7,0.7,1.0"
"S02|left|joint=shoulder side=left seed=302 R=20 gap=2 excess=6 axes=1.0,1.05,1.08 head_rot=10,0,20 fov=70,70,70 spacing=0.6,0.6,0.8 sub=1"
"S03|right|joint=shoulder side=right seed=303 R=26 gap=5 excess=12 glen_si=28 glen_ap=20 fov=80,80,80 spacing=0.9,0.9,2.0 blur=box blur_xy=0.9 blur_z=2.0"
"S04|left|joint=shoulder side=left seed=304 R=24 gap=3.5 excess=10 orient=ras cortex=0.7 cort_hu=700 trab_hu=150 fov=75,75,75 spacing=0.8,0.8,1.25"
"S05|right|joint=shoulder side=right seed=305 R=23 gap=2.5 excess=5 orient=obl obl=10,0,-15 hdr=qform fov=75,75,75 spacing=0.7,0.7,1.0 noise=30 cupping=60"
"S06|left|joint=shoulder side=left seed=306 R=21 gap=4 excess=15 glen_si=36 glen_ap=25 blur=lorentz blur_xy=0.3 blur_z=0.6 store=int16 slope=0.5 inter=-1024 fov=70,70,70 spacing=0.6,0.6,1.0"
"S07|right|joint=shoulder side=right seed=307 R=25 gap=3 excess=8 femur_rot=0,-20,0 cortex=2.0 cort_hu=1400 trab_hu=350 fov=110,80,80 spacing=0.9,0.9,1.5"
"S08|left|joint=shoulder side=left seed=308 R=22 gap=2 excess=4 air=0 fov=65,65,65 spacing=0.7,0.7,1.0 noise=20"
"S09|right|joint=shoulder side=right seed=309 R=20 gap=3 excess=9 axes=1.0,0.94,1.06 head_rot=0,0,40 cortex=0.6 cort_hu=600 trab_hu=120 tex=60 fov=70,70,70 spacing=0.5,0.5,0.6 sub=1 noise=25"
"S10|left|joint=shoulder side=left seed=310 R=26 gap=2.5 excess=6 fov=80,80,60 fov_shift=0,0,20 spacing=1.0,1.0,1.25 store=float32"
"S11|right|joint=shoulder side=right seed=311 R=24 gap=4 excess=10 femur_rot=25,0,0 orient=oblras obl=0,15,0 fov=75,75,75 spacing=0.8,0.8,1.0"
"S12|left|joint=shoulder side=left seed=312 R=23 gap=3 excess=7 cupping=90 noise=35 noise_corr=1.0 fov=120,80,80 spacing=0.9,0.9,1.25"
"S13|right|joint=shoulder side=right seed=313 R=21 gap=1.5 excess=3 glen_si=38 glen_ap=28 fov=70,70,70 spacing=0.7,0.7,0.7"
"S14|left|joint=shoulder side=left seed=314 R=25 gap=3 excess=8 cortex=1.0 pcortex=2.0 pcort_hu=1300 spacing=1.0,1.0,3.0 blur_z=2.5 fov=80,80,90"
"X01|left|joint=hip side=left seed=109 R=21 gap=2 cortex=0.6 cort_hu=500 trab_hu=100 tex=0 spacing=0.8,0.8,1.25 noise=20"
"X02|left|joint=hip side=left seed=109 R=21 gap=2 cortex=0.8 cort_hu=700 trab_hu=190 tex=60 spacing=0.8,0.8,1.25 noise=20"
"X03|left|joint=hip side=left seed=109 R=21 gap=2 cortex=0.6 cort_hu=800 trab_hu=100 tex=60 spacing=0.8,0.8,1.25 noise=20"
"X04|left|joint=hip side=left seed=109 R=21 gap=4 cortex=0.6 cort_hu=500 trab_hu=100 tex=60 spacing=0.8,0.8,1.25 noise=20"
"X05|right|joint=hip side=right seed=405 R=24 gap=2.5 gap_hu=400 spacing=0.7,0.7,1.0"
"X06|left|joint=shoulder side=left seed=406 R=23 gap=3 excess=8 gap_hu=500 fov=75,75,75 spacing=0.7,0.7,1.0"
"X07|right|joint=hip side=right seed=407 R=24 gap=2.5 fov=65,65,40 fov_shift=0,0,30 spacing=0.7,0.7,1.0"
"X08|left right|joint=hip both=1 side=left seed=408 R=24 gap=2.5 orient=flipx fov=175,75,70 spacing=0.8,0.8,1.5"
"X09|right|joint=hip side=right seed=409 R=23 gap=2 sub=1 blur_xy=0 blur_z=0 noise=0 spacing=1.0,1.0,1.25"
"X10|left right|joint=hip both=1 side=left seed=410 R=24 gap=2.5 air=0 fov=135,70,65 fov_shift=60,0,0 spacing=0.8,0.8,1.5"
"X11|right|joint=shoulder side=right seed=411 R=22 gap=3 excess=8 cortex=0.6 cort_hu=500 trab_hu=100 tex=60 fov=75,75,75 spacing=0.8,0.8,1.25 noise=20"
"X12|right|joint=hip side=right seed=412 R=23 gap=2 pcortex=0.6 pcort_hu=500 ptrab_hu=100 spacing=0.7,0.7,1.0"
"X13|left|joint=hip side=left seed=413 R=22 gap=1.5 cover=140 excess=0 spacing=1.0,1.0,1.25"
"X14|right|joint=hip side=right seed=414 R=30 axes=1.1,0.95,1.0 head_rot=0,0,45 gap=1.5 excess=0.5 spacing=1.0,1.0,1.25 fov=80,80,80"
"X15|left|joint=hip side=left seed=415 R=17 gap=1.5 excess=0.5 cover=120 spacing=1.0,1.0,1.25"
"X16|right|joint=hip side=right seed=416 R=23 gap=2.5 cortex=0.8 cort_hu=700 trab_hu=190 cupping=150 spacing=0.8,0.8,1.0"
"X17|right|joint=shoulder side=right seed=417 R=24 gap=3 excess=8 femur_rot=0,0,40 fov=75,75,50 fov_shift=0,0,15 spacing=0.8,0.8,1.0"
"X18|left|joint=hip side=left seed=418 R=22 gap=2 sub=1 noise=40 cortex=0.8 cort_hu=900 spacing=0.5,0.5,0.6 fov=55,55,55"
"Y01|left right|joint=hip both=1 side=left seed=410 R=24 gap=2.5 air=0 fov=135,70,65 fov_shift=60,0,0 spacing=0.8,0.8,1.25"
"Y02|left right|joint=hip both=1 side=left seed=502 R=24 gap=2.5 air=0 fov=165,70,65 fov_shift=65,0,0 spacing=0.8,0.8,1.25"
"Y03|right|joint=hip side=right seed=503 R=23 gap=2.5 fov=70,70,45 fov_shift=0,0,75 spacing=0.7,0.7,1.0"
"Y04|right left|joint=hip both=1 side=right seed=504 R=23 gap=2.5 fov=175,75,45 fov_shift=0,0,80 spacing=0.8,0.8,1.25"
"Y05|left|joint=hip side=left seed=505 R=21 gap=2 cortex=0.6 cort_hu=500 trab_hu=100 tex=60 spacing=0.8,0.8,1.25 noise=20"
"Y06|left|joint=hip side=left seed=506 R=24 gap=2.5 cortex=0.6 cort_hu=500 trab_hu=150 tex=60 spacing=0.8,0.8,1.25 noise=20"
"Y07|right|joint=hip side=right seed=507 R=21 gap=2 cortex=0.6 cort_hu=500 trab_hu=100 tex=60 spacing=0.7,0.7,1.0 noise=15"
"Y08|right|joint=shoulder side=right seed=508 R=22 gap=3 excess=8 cortex=0.6 cort_hu=500 trab_hu=100 tex=60 fov=75,75,75 spacing=0.7,0.7,1.0 noise=15"
"Y09|left|joint=hip side=left seed=509 R=21 gap=2 cortex=0.7 cort_hu=600 trab_hu=120 tex=50 spacing=0.8,0.8,1.25 noise=20"
"Y10|right|joint=hip side=right seed=510 R=23 gap=2.5 fov=70,70,70 fov_shift=-60,0,0 spacing=0.7,0.7,1.0"
# Clinical coarse voxels (1-2 mm within the slices, 2-3 mm slices): faint and
# thin cortices, narrow gaps, small and large heads, both hips.
"C1|left|joint=hip side=left seed=601 R=23 gap=2.5 cortex=0.8 cort_hu=800 trab_hu=200 spacing=1.5,1.5,3.0 blur_xy=0.8 blur_z=1.5"
"C2|right|joint=hip side=right seed=602 R=25 gap=3 cortex=1.5 spacing=1.5,1.5,3.0 blur_xy=1.0 blur_z=2.0"
"C3|right|joint=shoulder side=right seed=603 R=22 gap=3 excess=8 cortex=0.6 cort_hu=500 trab_hu=100 tex=60 noise=20 fov=80,80,80 spacing=1.5,1.5,3.0 blur_xy=0.7 blur_z=1.3"
"C4|right left|joint=hip both=1 side=right seed=604 R=24 gap=2.5 fov=175,75,70 spacing=1.5,1.5,3.0 blur=box blur_xy=1.5 blur_z=3.0 sub=1"
"C5|left|joint=hip side=left seed=605 R=18 gap=1.5 cover=115 excess=0.5 spacing=1.5,1.5,3.0"
"C6|right|joint=hip side=right seed=606 R=30 gap=4 cortex=2.0 cort_hu=1400 trab_hu=350 spacing=1.5,1.5,3.0 blur=lorentz blur_xy=0.5 blur_z=1.0 fov=80,80,80"
"C7|left|joint=hip side=left seed=607 R=21 gap=2 cortex=0.7 cort_hu=700 trab_hu=150 spacing=1.5,1.5,1.5 blur_xy=1.2 blur_z=1.2"
"C8|right|joint=hip side=right seed=608 R=26 gap=2.5 cortex=1.0 spacing=2.0,2.0,2.0 blur_xy=1.0 blur_z=1.0 fov=75,75,75"
"C9|left|joint=shoulder side=left seed=609 R=24 gap=3 excess=8 cortex=0.8 cort_hu=900 spacing=1.2,1.2,2.5 blur_xy=0.6 blur_z=1.8 fov=80,80,80"
"C10|left|joint=hip side=left seed=610 R=20 gap=2 cortex=0.6 cort_hu=500 trab_hu=100 tex=60 noise=20 spacing=1.5,1.5,3.0 blur_xy=0.7 blur_z=1.3"
"C11|right|joint=hip side=right seed=611 R=24 gap=2.5 cortex=0.7 cort_hu=600 trab_hu=150 tex=40 noise=25 spacing=1.5,1.5,3.0 blur_xy=0.8 blur_z=1.5"
"C12|right|joint=shoulder side=right seed=612 R=24 gap=3 excess=8 cortex=1.0 cort_hu=800 trab_hu=200 fov=80,80,80 spacing=1.5,1.5,3.0 blur_xy=0.8 blur_z=1.5"
"C13|left right|joint=hip both=1 side=left seed=613 R=22 gap=2 cortex=0.8 cort_hu=700 trab_hu=150 tex=50 fov=175,75,70 spacing=1.5,1.5,3.0 blur_xy=0.8 blur_z=1.5"
"C14|left|joint=hip side=left seed=614 R=28 gap=1.5 cover=120 excess=0.5 cortex=1.0 spacing=1.5,1.5,3.0 blur_xy=0.8 blur_z=1.5"
"C15|right|joint=hip side=right seed=615 R=17 gap=2 cortex=0.8 cort_hu=700 trab_hu=150 spacing=1.5,1.5,3.0 blur_xy=0.8 blur_z=1.5"
"C16|left|joint=shoulder side=left seed=616 R=22 gap=3 excess=8 cortex=0.6 cort_hu=600 trab_hu=120 tex=60 noise=20 fov=80,80,80 spacing=1.2,1.2,2.5 blur_xy=0.6 blur_z=1.2"
"C17|right|joint=hip side=right seed=617 R=23 gap=2.5 cortex=0.6 cort_hu=500 trab_hu=100 tex=60 noise=20 spacing=1.0,1.0,2.0 blur_xy=0.5 blur_z=1.0"
"C18|left|joint=hip side=left seed=618 R=24 gap=2.5 cortex=0.8 cort_hu=700 trab_hu=150 spacing=2.0,2.0,3.0 blur_xy=1.0 blur_z=1.5 fov=80,80,80"
"C19|right|joint=shoulder side=right seed=619 R=25 gap=3 excess=8 cortex=0.7 cort_hu=600 trab_hu=100 tex=40 noise=15 fov=80,80,80 spacing=1.5,1.5,3.0 blur_xy=0.8 blur_z=1.5"
# Clinical failure modes made by this generator: a lag screw with its
# streaks, a flattened dome, low-dose noise, heads clipped by the field of
# view (the top of the field 0.75 or 0.9 radii above the centre; fov gives
# half-widths).
"K1|right|joint=hip side=right seed=701 R=24 gap=2.5 metal=screw spacing=0.8,0.8,1.5"
"K2|left|joint=hip side=left seed=702 R=22 gap=2.5 dome_cut=0.12 spacing=0.7,0.7,1.0"
"K3|right|joint=hip side=right seed=703 R=25 gap=3 dome_cut=0.25 spacing=1.0,1.0,2.0"
"K4|left|joint=hip side=left seed=704 R=23 gap=2.5 noise=80 spacing=0.8,0.8,1.25"
"K5|right|joint=hip side=right seed=705 R=23 gap=2.5 fov=70,70,70 fov_shift=0,0,-52.75 spacing=0.7,0.7,1.0"
"K6|left right|joint=hip both=1 side=left seed=706 R=24 gap=2.5 metal=screw fov=175,75,70 spacing=1.0,1.0,2.0"
"K7|right|joint=shoulder side=right seed=707 R=22 gap=3 excess=8 fov=75,75,75 fov_shift=0,0,-55.2 spacing=0.8,0.8,2.0"
"K8|right|joint=hip side=right seed=708 R=20 gap=2 dome_cut=0.12 spacing=0.9,0.9,2.5"
)
echo "| case | side | joint | voxels (mm) | cortex (mm) | gap (mm) | exit | qc | verdict | centre error (mm) | mean signed (mm) | RMS (mm) | within 1.5 mm | message |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for line in "${cases[@]}"; do
  IFS='|' read -r name sides opts <<< "$line"
  [[ "$name" =~ $filter ]] || continue
  [ -e "$name.json" ] || "$py" "$here/third_phantom.py" out="$work/$name" $opts > /dev/null || { echo "| $name | | | | | | generator failed |"; continue; }
  joint=$(sed -n 's/.*joint=\([a-z]*\).*/\1/p' <<< "$opts")
  for side in $sides; do
    out=run-$name-$side
    "$bin/articula" run -i "$name.nii.gz" -o "$out" --joint "$joint" --side "$side" --threads 1 --quiet --force 2> "$out.err"
    rc=$?
    "$py" - "$out" "$name.json" "$side" "$rc" "$name" "$out.err" "$here" <<'PY'
import json, os, sys
import numpy as np
run, truth, side, rc, name, err, here = sys.argv[1:8]
sys.path.insert(0, here)
from third_phantom import head_distances
t = json.load(open(truth)); o = t["options"]; sp = t["spacing_mm"]
h = next(h for h in t["heads"] if h["side"] == side)
qc = verdict = ""
warned = False
cells = [""] * 4
if os.path.exists(f"{run}/results.json") and rc in ("0", "1"):
    try:
        checks = json.load(open(f"{run}/results.json"))["qc"]
        qc = checks["status"]
        warned = any(c["status"] == "warn" and c["name"] != "side_verified" for c in checks["checks"])
    except (ValueError, KeyError):
        pass
if rc == "0":
    r = json.load(open(f"{run}/results.json"))
    sel = next(m for m in r["models"] if m["model"] == r["selected_model"])
    ce = np.linalg.norm(np.array([sel["parameters"][k] for k in ("t1_mm", "t2_mm", "t3_mm")]) - np.array(h["head_center_mm"]))
    d = head_distances(f"{run}/errors/errors.csv", truth, side)
    rms = float(np.sqrt((d ** 2).mean())); within = float((np.abs(d) <= 1.5).mean())
    verdict = "correct" if rms <= 0.5 * sp[0] and within >= 0.95 else "wrong, warned" if warned else "SILENTLY WRONG"
    cells = [f"{ce:.2f}", f"{d.mean():+.3f}", f"{rms:.3f}", f"{100 * within:.0f} %"]
else:
    verdict = "refused"
lines = [l for l in open(err).read().splitlines() if l.strip()]
message = (lines[-1][:120].replace("|", "/") if lines and rc != "0" else "")
print(f"| {name} | {side} | {o['joint']} | {'x'.join(f'{v:g}' for v in sp)} | {o['cortex']} | {o['gap']} | {rc} | {qc} | "
      f"{verdict} | " + " | ".join(cells) + f" | {message} |")
PY
  done
done

#!/usr/bin/env bash
# The real CTs of ../shared/data/ct: segment + mesh + sample of the right
# femoral head (3 mm hip NIfTI) and of the right humeral head (thorax DICOM);
# the articular sphere radius must be that of an adult joint head (18-30 mm).
set -euo pipefail
B=$ARTICULA_BIN
T=$ARTICULA_TMP
D=${ARTICULA_SHARED_DATA:-}
[[ -d "$D/ct/hip-3mm-nifti" && -d "$D/ct/thorax-shoulders-dicom" ]] || { echo "no shared CT data: skipped"; exit 77; }
# Known failure (issue 5, not done): the automatic head search finds no head
# in these real CTs yet; run with ARTICULA_RUN_KNOWN_FAILURES=1 to try.
[[ "${ARTICULA_RUN_KNOWN_FAILURES:-0}" == 1 ]] || { echo "real-CT chain: known failure, skipped"; exit 77; }
rm -rf "$T" && mkdir -p "$T"
run() {  # run NAME INPUT JOINT
  local name=$1 input=$2 joint=$3
  "$B/articula-segment" -i "$input" -o "$T/$name.nii.gz" --joint "$joint" --side right -q
  "$B/articula-mesh" -i "$T/$name.nii.gz" -o "$T/$name.vtp" -q
  "$B/articula-sample" -i "$T/$name.vtp" -o "$T/$name.ply" --json -q > "$T/$name.json"
  python3 - "$T/$name.json" "$name" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
r = s["sphere"]["radius_mm"]
print(f"{sys.argv[2]}: sphere radius {r:.2f} mm, RMS {s['sphere']['rms_mm']:.2f} mm, centre {s['sphere']['center_mm']}, "
      f"{s['reduced_points']} of {s['selected_points']} points")
assert 18 <= r <= 30, r
assert s["sphere"]["center_mm"][0] < 0, "the right side is -x in LPS"
PY
}
run hip "$D/ct/hip-3mm-nifti/example_ct.nii.gz" hip
run shoulder "$D/ct/thorax-shoulders-dicom" shoulder

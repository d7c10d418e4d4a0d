#!/usr/bin/env bash
# The cost of a clinical-size CT: a both-hips phantom at 0.78 x 0.78 x 1 mm
# (397 x 179 x 128 voxels) padded with air to 512 x 512 x 400 voxels, a
# pelvis scan's matrix, through `articula run` on the right hip.
# Target: at most 30 s wall and 2 GB peak on this machine (2 cores).
# Each run REPEATS times (default 3); prints the median wall time, the
# processor time, the peak resident memory, the head's verdict and the
# ratios to the targets (a ratio <= 1 meets the target).
#   bash bench/clinical_size.sh [build/bin] [scratch dir]
set -euo pipefail
bin=$(cd "${1:-build/bin}" && pwd)
work=${2:-$(mktemp -d)}
repeats=${REPEATS:-3}
mkdir -p "$work"
"$bin/articula" phantom -o "$work/phantom" --both-hips --spacing 0.78,0.78,1 --seed 7 --no-dicom --force -q
# The padding: the NIfTI's voxels (int16) copied into a grid of air, the
# affine's offset moved by the padding so that the anatomy keeps its place.
python3 - "$work/phantom/phantom.nii.gz" "$work/big.nii.gz" 512 512 400 <<'PY'
import gzip, struct, sys
source, target, *size = sys.argv[1:]
size = [int(s) for s in size]
raw = gzip.open(source).read()
header = bytearray(raw[:352])
dims = struct.unpack_from("<8h", header, 40)
nx, ny, nz = dims[1:4]
assert struct.unpack_from("<h", header, 70)[0] == 4, "int16 voxels expected"
offset = int(struct.unpack_from("<f", header, 108)[0])
pad = [(size[0] - nx) // 2, (size[1] - ny) // 2, (size[2] - nz) // 2]
assert min(pad) >= 0, f"the phantom ({nx} x {ny} x {nz}) is larger than {size}"
rows = [struct.unpack_from("<4f", header, 280 + 16 * r) for r in range(3)]
shift = [sum(rows[r][c] * pad[c] for c in range(3)) for r in range(3)]
for r in range(3):
    struct.pack_into("<f", header, 280 + 16 * r + 12, rows[r][3] - shift[r])  # srow offset
    q = struct.unpack_from("<f", header, 268 + 4 * r)[0]
    struct.pack_into("<f", header, 268 + 4 * r, q - shift[r])  # qoffset: the same translation
struct.pack_into("<8h", header, 40, 3, size[0], size[1], size[2], 1, 1, 1, 1)
out = bytearray(struct.pack("<h", -1000) * (size[0] * size[1] * size[2]))
row = 2 * nx
for k in range(nz):
    for j in range(ny):
        src = offset + 2 * nx * (j + ny * k)
        dst = 2 * (pad[0] + size[0] * ((j + pad[1]) + size[1] * (k + pad[2])))
        out[dst:dst + row] = raw[src:src + row]
with gzip.open(target, "wb", compresslevel=1) as f:
    f.write(bytes(header) + raw[352:offset] + bytes(out))  # the voxels where vox_offset says
PY
rm -f "$work/times"
for r in $(seq 1 "$repeats"); do
  # Exit 1 would be a failed check, with every output written: its verdict is printed below.
  /usr/bin/time -f "%e %U %S %M" -a -o "$work/times" \
    "$bin/articula" run -i "$work/big.nii.gz" -o "$work/run" --joint hip --side right --force -q || [ $? -eq 1 ]
done
python3 - "$work/times" "$work/run/results.json" "$work/phantom/truth.json" <<'PY'
import json, statistics, sys
rows = [l.split() for l in open(sys.argv[1]) if l.strip() and not l.startswith("Command")]
wall = statistics.median(float(r[0]) for r in rows)
cpu = statistics.median(float(r[1]) + float(r[2]) for r in rows)
peak = max(int(r[3]) for r in rows) / 1024**2
results = json.load(open(sys.argv[2]))
truth = json.load(open(sys.argv[3]))
error = sum((a - b) ** 2 for a, b in zip(results["head_center_mm"], truth["head_center_mm"])) ** 0.5
print(f"articula run on 512 x 512 x 400: median {wall:.2f} s wall over {len(rows)} runs "
      f"(ratio {wall / 30:.2f} of 30 s), {cpu:.1f} s processor, peak {peak:.2f} GB (ratio {peak / 2:.2f} of 2 GB)")
print(f"qc {results['qc']['status']}, selected {results['selected_model']} (true {truth['model']}), "
      f"head centre {error:.2f} mm from the truth")
PY

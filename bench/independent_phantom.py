"""A hip CT phantom made independently of `articula phantom` (other code,
geometry and tissue levels), to check the chain on anatomy it was not
tuned on: a femur (an axis-aligned ellipsoidal head, a neck leaving it
laterally and inferiorly, a rounded greater trochanter, a shaft) in a socket
shell on a pelvic plate, inside an elliptic body of soft tissue under a fat
layer, in air; the field of view is centred on the head (a reconstruction
targeted on one hip), so the body's outline leaves it on both sides. Partial
volume by sub x sub x sub supersampling (2 by default: each voxel the mean of
8 point samples, a narrower partial volume than a voxel's whole extent),
Gaussian blur, Gaussian noise; NIfTI-1 int16 with a RAS sform. Truth (head
centre and radii, LPS mm) in OUT.json.

    python3 bench/independent_phantom.py out=DIR/name [side=right] [R=23]
      [gap=2] [cortex=1.2] [spacing=0.7,0.7,0.9] [blur=0.6] [noise=15]
      [seed=1] [axes=1,1,1] [cort_hu=1100] [trab_hu=280] [socket_hu=900] [sub=2]

Needs numpy and scipy (Debian: python3-numpy, python3-scipy)."""
import gzip, json, struct, sys
import numpy as np
from scipy import ndimage

args = dict(a.split("=") for a in sys.argv[1:])
out = args["out"]
R = float(args.get("R", 23)); gap = float(args.get("gap", 2.0)); cort = float(args.get("cortex", 1.2))
side = args.get("side", "right"); sp = [float(v) for v in args.get("spacing", "0.7,0.7,0.9").split(",")]
blur = float(args.get("blur", 0.6)); noise = float(args.get("noise", 15)); seed = int(args.get("seed", 1))
axes = [float(v) for v in args.get("axes", "1,1,1").split(",")]  # head radii factors
rng = np.random.default_rng(seed)
HU = dict(air=-1000, fat=-90, soft=35, cort=float(args.get("cort_hu", 1100)), trab=float(args.get("trab_hu", 280)),
          socket=float(args.get("socket_hu", 900)))
# LPS frame: head centre at x = -90 (right) or +90 (left), y = 0, z = 0.
s = -1 if side == "right" else 1
centre = np.array([s * 90.0, 10.0, 0.0])
half = np.array([75.0, 60.0, 70.0])  # field half sizes around the head (mm), LPS
lo = centre - half
n = np.ceil(2 * half / sp).astype(int)
sub = int(args.get("sub", 2))  # memory grows as sub^3: about 13 GB at sub=3 for 0.9 mm voxels
def grid():
    idx = [(np.arange(n[k] * sub) + 0.5) / sub - 0.5 for k in range(3)]
    return np.meshgrid(*[lo[k] + idx[k] * sp[k] for k in range(3)], indexing="ij")
X, Y, Z = grid()
# body: elliptic cylinder about the origin (pelvis), axes 170 x 120 mm, fat layer 12 mm
bx, by = 175.0, 125.0
body_r = np.sqrt((X / bx) ** 2 + (Y / by) ** 2)
img = np.full(X.shape, HU["air"], np.float32)
img[body_r <= 1] = HU["fat"]
img[body_r <= 1 - 12 / bx] = HU["soft"]
def ellipsoid_level(x, y, z, c, r):  # < 0 inside; about the distance near the surface
    q = np.sqrt(((x - c[0]) / r[0]) ** 2 + ((y - c[1]) / r[1]) ** 2 + ((z - c[2]) / r[2]) ** 2)
    return (q - 1) * min(r)
rad = np.array(axes) * R
# socket: shell from R+gap to R+gap+5 mm, the lateral-inferior half cut off (opening toward the femur)
dc = np.sqrt((X - centre[0]) ** 2 + (Y - centre[1]) ** 2 + (Z - centre[2]) ** 2)
open_dir = np.array([s * 0.7, 0.0, -0.7]); open_dir /= np.linalg.norm(open_dir)
toward = ((X - centre[0]) * open_dir[0] + (Y - centre[1]) * open_dir[1] + (Z - centre[2]) * open_dir[2]) / np.maximum(dc, 1e-9)
inner = R * max(axes) + gap
shell = (dc >= inner) & (dc <= inner + 5) & (toward < 0.25)
# pelvic plate: a slab medial and superior to the socket, trabecular with cortex
plate = (dc > inner) & (dc < inner + 25) & (toward < -0.2)
img[plate] = HU["trab"] + 60
img[shell] = HU["socket"]
# femur: head ellipsoid, neck cylinder toward lateral-inferior, trochanter, shaft
neck_dir = open_dir
def cylinder(p0, d, r, length):
    v = np.stack([X - p0[0], Y - p0[1], Z - p0[2]])
    t = np.tensordot(d, v, axes=1)
    perp = np.sqrt(np.maximum((v ** 2).sum(0) - t ** 2, 0))
    return (perp - r), t, (t >= 0) & (t <= length)
head = ellipsoid_level(X, Y, Z, centre, rad)
neck_p, neck_t, neck_in = cylinder(centre, neck_dir, 0.62 * R, R + 30)
neck_end = centre + (R + 30) * neck_dir
shaft_p, shaft_t, shaft_in = cylinder(neck_end + np.array([0, 0, 10]), np.array([0, 0, -1.0]), 0.6 * R, 80)
troch = ellipsoid_level(X, Y, Z, neck_end + np.array([s * 8, 5, 12]), np.array([14.0, 16, 18]))
femur_level = np.minimum.reduce([head, np.where(neck_in & (neck_t > 0.4 * R), neck_p, 1e9),
                                 np.where(shaft_in, shaft_p, 1e9), troch])
img[femur_level <= 0] = HU["cort"]
img[femur_level <= -cort] = HU["trab"]
# partial volume, blur, noise
img = img.reshape(n[0], sub, n[1], sub, n[2], sub).mean(axis=(1, 3, 5))
img = ndimage.gaussian_filter(img, [blur / sp[k] for k in range(3)])
img += rng.normal(0, noise, img.shape).astype(np.float32)
vol = np.round(img).astype(np.int16)
# NIfTI-1, RAS sform: stored index i along x, j along y, k along z; RAS = (-x, -y, z)
# voxel centres at lo + i * sp (LPS); RAS = (-x, -y, z)
aff = np.array([[-sp[0], 0, 0, -lo[0]], [0, -sp[1], 0, -lo[1]], [0, 0, sp[2], lo[2]]])
hdr = bytearray(348)
struct.pack_into("<i", hdr, 0, 348)
struct.pack_into("<8h", hdr, 40, 3, n[0], n[1], n[2], 1, 1, 1, 1)
struct.pack_into("<hh", hdr, 70, 4, 16)  # int16
struct.pack_into("<8f", hdr, 76, 1, sp[0], sp[1], sp[2], 1, 1, 1, 1)
struct.pack_into("<f", hdr, 108, 352.0)
struct.pack_into("<ff", hdr, 112, 1.0, 0.0)  # scl_slope, scl_inter
hdr[123] = 10  # xyzt_units mm
struct.pack_into("<hh", hdr, 252, 0, 1)  # qform 0, sform 1 (scanner)
for r in range(3): struct.pack_into("<4f", hdr, 280 + 16 * r, *aff[r])
hdr[344:348] = b"n+1\0"
with gzip.open(out + ".nii.gz", "wb") as f:
    f.write(bytes(hdr) + b"\0" * 4 + vol.transpose(2, 1, 0).tobytes())
json.dump({"head_center_mm": centre.tolist(), "radii_mm": rad.tolist(), "side": side, "gap_mm": gap,
           "cortex_mm": cort, "spacing_mm": sp}, open(out + ".json", "w"))
print("wrote", out, "voxels", n.tolist())

"""A third CT phantom generator, independent of `articula phantom` and of
bench/independent_phantom.py, to check the chain on anatomy and imaging it
was not tuned on.

Hip (femur with an ellipsoidal, possibly rotated head; a deep, non-congruent,
labrum-less acetabulum carved out of a pelvis with ilium/pubis/ischium; one or
both hips; femur rotated/tilted) or shoulder (ellipsoidal humeral head with
neck, tuberosities and shaft; a small shallow pear-shaped glenoid on a
scapular neck and blade; acromion, coracoid, clavicle, ribs, lungs).
Everything is built from signed-distance-like level functions evaluated at
physical LPS points; imaging: point sampling or sub^3 supersampling, Gaussian /
box / Lorentzian blur (separate in-plane and slice widths), white or
correlated noise, cupping, trabecular texture, int16 with scl_slope/inter or
float32, LPS/RAS/oblique storage, sform and/or qform, cropped fields of view,
with or without air around the body. Clinical additions on a hip: a dome cut
flat (an arthritic head's weight-bearing zone) and a lag screw along the neck
with streaks, made here independently of `articula phantom`'s.

    python3 bench/third_phantom.py out=DIR/name [key=value ...]      (see DEFAULTS below)

Writes name.nii.gz (or .nii with gz=0) and name.json (truth: head centre LPS
mm, radii, axes as columns of a 3x3 matrix in LPS, per head)."""
import gzip, json, struct, sys, time
import numpy as np
from scipy import ndimage
from scipy.spatial.transform import Rotation

DEFAULTS = dict(
    joint="hip", side="right", both="0", seed="1",
    R="23", axes="1,1,1", head_rot="0,0,0",            # head radius, radii factors, head axes rotation (deg, xyz)
    gap="2.5", cover="105", excess="1.5", wall="5",     # socket: half-angle of coverage (deg), non-congruence (mm), wall (mm)
    av="15", el="40", femur_rot="0,0,0",                 # neck anteversion/elevation (deg); whole femur rotation (deg, xyz)
    cortex="1.2", cort_hu="1100", trab_hu="250", pcortex="", pcort_hu="", ptrab_hu="",
    tex="40",                                            # trabecular texture amplitude (HU)
    spacing="0.7,0.7,1.0", sub="2",                      # voxel size, supersampling (1 = point sampled)
    blur="gauss", blur_xy="0.4", blur_z="0.8",           # gauss: sigma mm; box: full width mm; lorentz: HWHM mm
    noise="15", noise_corr="0", cupping="0",
    store="int16", slope="1", inter="0",
    orient="lps", obl="0,0,0", hdr="sform", gz="1",      # lps: direction I; ras: diag(-1,-1,1); obl: rotation (deg xyz) applied to the lps/ras base
    fov="70,70,70", fov_shift="0,0,0", air="1",
    glen_si="32", glen_ap="22",
    dome_cut="0",                                         # hip: the primary head's dome cut flat this far below its top (a fraction of R; new cortex over the cut)
    metal="none",                                         # hip: screw (a lag screw along the primary neck into the head, with radial streaks in its slices)
    gap_hu="",                                            # fill the joint space (within the socket's cover) with this HU (arthrography contrast, 0-600)                           # shoulder: glenoid half-angles (deg), superior-inferior / anterior-posterior
)


def rot(deg):
    return Rotation.from_euler("xyz", deg, degrees=True).as_matrix()


def unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


# ---------- level functions on (N,3) point arrays ----------
def ell_level(P, c, r, A):
    L = (P - c) @ A
    q = np.sqrt(((L / r) ** 2).sum(1))
    g = np.sqrt(((L / r ** 2) ** 2).sum(1)) / np.maximum(q, 1e-9)
    return (q - 1) / np.maximum(g, 1e-9)


def capsule(P, a, b, r):
    a = np.asarray(a, float); b = np.asarray(b, float)
    ba = b - a
    h = np.clip((P - a) @ ba / (ba @ ba), 0, 1)
    return np.linalg.norm(P - a - h[:, None] * ba, axis=1) - r


def box(P, c, half, A=np.eye(3), rnd=0.0):
    L = (P - np.asarray(c, float)) @ A
    q = np.abs(L) - (np.asarray(half, float) - rnd)
    return np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(1), 0) - rnd


def ball(P, c, r):
    return np.linalg.norm(P - c, axis=1) - r


def cone_level(P, c, u, theta_fn):
    """about the distance outside the cone of directions around u (apex c) whose
    half-angle theta_fn(dirs) may vary with direction (radians)"""
    v = P - c
    d = np.maximum(np.linalg.norm(v, axis=1), 1e-9)
    ang = np.arccos(np.clip(v @ u / d, -1, 1))
    th = theta_fn(v / d[:, None])
    return np.sin(np.clip(ang - th, -np.pi / 2, np.pi / 2)) * d


# ---------- the scene ----------
class Scene:
    def __init__(self, a, rng):
        self.a = a
        self.rng = rng
        self.bones = []   # (name, level_fn, cortex_fn, cort_hu, trab_hu, role)
        self.heads = []
        self.metal = []   # (end, end, radius): screws
        j = a["joint"]
        if j == "hip":
            sides = ["right", "left"] if a["both"] == "1" else [a["side"]]
            for sd in sides:
                self.add_hip(sd, primary=(sd == a["side"]))
            if a["both"] == "1":
                self.add_sacrum()
            self.body = dict(c=np.array([0.0, 15.0]), ax=np.array([185.0, 130.0]), lung=None)
        else:
            self.add_shoulder(a["side"])
            s = -1 if a["side"] == "right" else 1
            self.body = dict(c=np.array([0.0, 30.0]), ax=np.array([150.0, 105.0]), lung=(np.array([0.0, 30.0]), np.array([118.0, 78.0])),
                             extra=(self.heads[0]["center"], self.heads[0]["radii"].max() + 45))
        self.body["ax0"] = self.body["ax"].copy()
        if a["air"] == "0":
            self.body["ax"] = self.body["ax"] * 3  # the body fills the field of view

    def fl(self, k):
        return float(self.a[k])

    def vec(self, k):
        return np.array([float(v) for v in self.a[k].split(",")])

    def add_hip(self, sd, primary):
        a, rng = self.a, self.rng
        s = -1.0 if sd == "right" else 1.0
        jit = rng.uniform(-3, 3, 3)
        R = self.fl("R") * (1 if primary else rng.uniform(0.93, 1.07))
        c = np.array([s * 95.0, 5.0, 0.0]) + jit
        rad = R * self.vec("axes")
        hr = self.vec("head_rot") * (1 if primary else 0.5)
        Rf = rot(self.vec("femur_rot") * np.array([1, s, s]) * (1 if primary else 0.3))  # mirror-symmetric rotation
        A = Rf @ rot(hr * np.array([1, s, s]))  # head axes (columns) in LPS
        gap = self.fl("gap"); exc = self.fl("excess"); wall = self.fl("wall"); cov = np.radians(self.fl("cover"))
        av, el = np.radians(self.fl("av")), np.radians(self.fl("el"))
        n0 = unit([s * np.cos(el) * np.cos(av), -np.cos(el) * np.sin(av), -np.sin(el)])  # neck: lateral, anterior, inferior
        Rmax = rad.max()
        e0 = c + (Rmax + 24) * n0  # neck end (canonical)
        # canonical femur pieces (frame rotated by Rf about c)
        # A flattened dome: the head cut by a plane dome_cut x R below its top
        # along +z (superior), the level's shell giving it new cortex.
        cut = self.fl("dome_cut") * R if primary else 0.0
        top = np.sqrt(((rad * (A.T @ np.array([0, 0, 1.0]))) ** 2).sum())  # the ellipsoid's support height along +z
        def femur_level(P, parts=False):
            Q = c + (P - c) @ Rf
            head = ell_level(P, c, rad, A)
            if cut > 0:
                head = np.maximum(head, (P[:, 2] - c[2]) - (top - cut))
            neck = capsule(Q, c + 0.35 * R * n0, e0, 0.58 * R)
            shaft = capsule(Q, e0 + np.array([0, 0, 6.0]), e0 + np.array([s * 4, 4, -160.0]), 0.6 * R)
            gt = ell_level(Q, e0 + np.array([s * 9, 7, 14]), np.array([12.0, 15, 19]), np.eye(3))
            lt = ell_level(Q, e0 + np.array([-s * 9, 10, -28]), np.array([8.0, 8, 11]), np.eye(3))
            L = np.minimum.reduce([head, neck, shaft, gt, lt])
            return (L, np.where(shaft <= L + 1e-6, 3.5, -1.0)) if parts else L
        # pelvis: dome direction (into the pelvis) u, opening -u facing lateral, anterior, inferior
        u = -unit([s * 0.72, -0.3, -0.62])
        Rs = Rmax + gap + exc
        cs = c - exc * u
        # pear-ish rim: more coverage superiorly, less antero-inferiorly (the acetabular notch)
        notch = unit([s * 0.2, -0.3, -1.0])
        def theta_fn(D):
            return cov - np.radians(18) * np.clip(D @ notch, 0, 1) ** 2
        def pelvis_level(P):
            shell = np.maximum(np.abs(np.linalg.norm(P - cs, axis=1) - (Rs + wall / 2)) - wall / 2,
                               cone_level(P, cs, u, theta_fn))
            ilium = box(P, cs + np.array([-s * 18, 8, Rs + 35]), [7, 38, 40], rot([0, s * 25, 0]), 2)
            ilium_base = capsule(P, cs + (Rs + 4) * u, cs + np.array([-s * 14, 8, Rs + 10]), 13)
            pubis = capsule(P, cs + (Rs + 6) * unit([-s * 0.7, -0.7, 0.1]), np.array([s * 12, c[1] - 55, c[2] - 15]), 9)
            ischium = capsule(P, cs + (Rs + 6) * unit([-s * 0.4, 0.55, -0.75]), cs + np.array([-s * 20, 40, -70]), 11)
            body = np.minimum.reduce([shell, ilium, ilium_base, pubis, ischium])
            return np.maximum(body, -ball(P, cs, Rs))  # carve the socket
        pc = self.fl("pcortex") if self.a["pcortex"] else self.fl("cortex")
        ph = self.fl("pcort_hu") if self.a["pcort_hu"] else self.fl("cort_hu")
        pt = self.fl("ptrab_hu") if self.a["ptrab_hu"] else self.fl("trab_hu")
        self.bones.append(("pelvis_" + sd, pelvis_level, lambda P, L: np.full(len(P), pc), ph, pt, "socket"))
        t = self.fl("cortex")
        self.bones.append(("femur_" + sd, femur_level, None, self.fl("cort_hu"), self.fl("trab_hu"), "head"))
        self._cortex_of = getattr(self, "_cortex_of", {})
        self._cortex_of["femur_" + sd] = t
        self.fills = getattr(self, "fills", [])
        self.fills.append(lambda P: (ball(P, cs, Rs) < 0) & (cone_level(P, cs, u, theta_fn) < 0) & (femur_level(P) > 0))
        if primary and self.a["metal"] == "screw":
            # A 6.5 mm lag screw from the lateral cortex along the neck, its tip half a radius past the centre.
            self.metal.append((c + (Rmax + 60) * (Rf @ n0), c - 0.5 * R * (Rf @ n0), 3.25))
        elif self.a["metal"] not in ("none", "screw"):
            raise SystemExit("metal: none|screw")
        self.heads.append(dict(side=sd, center=c, radii=rad, axes=A, gap=gap, socket_center=cs, socket_radius=Rs,
                               socket_dome=u, cover_deg=self.fl("cover"), neck_dir=Rf @ n0, primary=primary,
                               dome_cut_mm=cut, dome_top_mm=float(c[2] + top)))

    def add_sacrum(self):
        def sac(P):
            return np.minimum(box(P, [0, 75, 25], [35, 18, 45], rot([20, 0, 0]), 5),
                              capsule(P, [-20, -60, -15], [20, -60, -15], 7))
        self.bones.append(("sacrum", sac, lambda P, L: np.full(len(P), 1.0), 900.0, 220.0, "other"))

    def add_shoulder(self, sd):
        rng = self.rng
        s = -1.0 if sd == "right" else 1.0
        R = self.fl("R")
        c = np.array([s * 165.0, 10.0, 0.0]) + rng.uniform(-3, 3, 3)
        rad = R * self.vec("axes")
        Rmax = rad.max()
        A = rot(self.vec("head_rot") * np.array([1, s, s]))
        gap = self.fl("gap"); exc = self.fl("excess")
        # articular axis of the head: medial, superior, posterior (retroversion 25 deg)
        ax = unit([-s * np.cos(np.radians(45)) * np.cos(np.radians(25)), np.cos(np.radians(45)) * np.sin(np.radians(25)), np.sin(np.radians(45))])
        g = unit([-s * 1.0, 0.12, 0.12])   # towards the glenoid centre
        Rf = rot(self.vec("femur_rot") * np.array([1, s, s]))  # humerus rotation about the head centre
        def humerus_level(P, parts=False):
            Q = c + (P - c) @ Rf
            head = ell_level(P, c, rad, A)
            neck = capsule(Q, c - 0.2 * R * ax, c - 0.75 * R * ax + np.array([s * 3, 0, -6]), 0.72 * R)
            shaft_top = c + np.array([s * 7, -2, -0.7 * R])
            shaft = capsule(Q, shaft_top, shaft_top + np.array([s * 6, 3, -170]), 12.5)
            gtub = ell_level(Q, c + np.array([s * (0.8 * R), -4, 0.05 * R]), np.array([8.0, 12, 13]), np.eye(3))
            ltub = ell_level(Q, c + np.array([s * 3, -(0.82 * R), -0.35 * R]), np.array([6.0, 6, 9]), np.eye(3))
            L = np.minimum.reduce([head, neck, shaft, gtub, ltub])
            return (L, np.where(shaft <= L + 1e-6, 3.0, -1.0)) if parts else L
        Rg = Rmax + gap + exc
        cg = c - exc * g
        si_ang, ap_ang = np.radians(self.fl("glen_si")), np.radians(self.fl("glen_ap"))
        up = unit(np.array([0, 0, 1.0]) - g[2] * g)
        ant = np.cross(g, up); ant = ant if ant[1] < 0 else -ant  # anterior = -y
        def theta_fn(D):
            # elliptical, pear-shaped boundary (wider inferiorly)
            du, da = D @ up, D @ ant
            phi = np.arctan2(da, du)
            a_si = np.where(du < 0, si_ang * 1.0, si_ang * 0.9)
            a_ap = np.where(du < 0, ap_ang * 1.1, ap_ang * 0.75)
            return 1.0 / np.sqrt((np.cos(phi) / a_si) ** 2 + (np.sin(phi) / a_ap) ** 2)
        gdepth = 5.0
        blade_dir = unit([-s * 0.78, 0.62, 0.0])
        gneck = cg + (Rg + gdepth + 6) * g
        acro_c = c + np.array([s * 4, 12, Rmax + 13])
        def scapula_level(P):
            glen = np.maximum(np.abs(np.linalg.norm(P - cg, axis=1) - (Rg + gdepth / 2)) - gdepth / 2,
                              cone_level(P, cg, g, theta_fn))
            neckp = capsule(P, cg + (Rg + 2) * g, gneck, 10)
            Bc = gneck + 45 * blade_dir + np.array([0, 0, -25])
            Ab = np.column_stack([blade_dir, unit(np.cross([0, 0, 1.0], blade_dir)), [0, 0, 1.0]])
            blade = box(P, Bc, [48, 2.5, 60], Ab, 1.5)
            acro = box(P, acro_c, [24, 13, 4.0], rot([0, s * 8, 0]), 2)
            spine = capsule(P, acro_c + np.array([-s * 15, 10, 0]), Bc + 30 * blade_dir + np.array([0, 0, 30]), 6)
            cora = capsule(P, gneck + np.array([0, -6, 12]), c + np.array([-s * 6, -(Rmax + 16), 0.5 * Rmax]), 6)
            L = np.minimum.reduce([glen, neckp, blade, acro, spine, cora])
            return np.maximum(L, -ball(P, cg, Rg))
        def clavicle_level(P):
            return capsule(P, acro_c + np.array([-s * 18, -6, 3]), np.array([s * 25, -35, c[2] + Rmax + 35]), 7)
        def ribs_level(P):
            out = np.full(len(P), 1e9)
            for k in range(6):
                zk = c[2] + 25 - 24 * k
                A_e, B_e = 120.0 - 3 * abs(k - 2), 85.0
                x, y = P[:, 0], P[:, 1] - 30
                rho = np.sqrt((x / A_e) ** 2 + (y / B_e) ** 2)
                zr = zk + 0.22 * y  # ribs slope down anteriorly (y<0 anterior)
                dpl = (rho - 1) * B_e
                dd = np.sqrt(dpl ** 2 + (P[:, 2] - zr) ** 2) - 5.5
                dd = np.where(s * x > 15, dd, 1e9)
                out = np.minimum(out, dd)
            return out
        sc = self.fl("pcortex") if self.a["pcortex"] else self.fl("cortex")
        ph = self.fl("pcort_hu") if self.a["pcort_hu"] else self.fl("cort_hu")
        pt = self.fl("ptrab_hu") if self.a["ptrab_hu"] else self.fl("trab_hu")
        self.bones.append(("ribs", ribs_level, lambda P, L: np.full(len(P), 1.0), 800.0, 200.0, "other"))
        self.bones.append(("clavicle", clavicle_level, lambda P, L: np.full(len(P), 1.5), 1000.0, 250.0, "other"))
        self.bones.append(("scapula", scapula_level, lambda P, L: np.full(len(P), sc), ph, pt, "socket"))
        self.bones.append(("humerus", humerus_level, None, self.fl("cort_hu"), self.fl("trab_hu"), "head"))
        self._cortex_of = {"humerus": self.fl("cortex")}
        self.fills = [lambda P: (ball(P, cg, Rg) < 0) & (cone_level(P, cg, g, theta_fn) < 0) & (humerus_level(P) > 0)]
        self.heads.append(dict(side=sd, center=c, radii=rad, axes=A, gap=gap, socket_center=cg, socket_radius=Rg,
                               socket_dome=g, cover_deg=[self.fl("glen_si"), self.fl("glen_ap")], primary=True))

    def evaluate(self, P, tex):
        """HU at physical LPS points P (N,3); also the body's normalised radius"""
        b = self.body
        x, y = P[:, 0] - b["c"][0], P[:, 1] - b["c"][1]
        rho = np.sqrt((x / b["ax"][0]) ** 2 + (y / b["ax"][1]) ** 2)
        inside = rho <= 1
        if "extra" in b:
            ec, er = b["extra"]
            inside |= np.hypot(P[:, 0] - ec[0], P[:, 1] - ec[1]) <= er
        rho0 = np.sqrt((x / b["ax0"][0]) ** 2 + (y / b["ax0"][1]) ** 2)
        hu = np.full(len(P), -1000.0, np.float32)
        hu[inside] = -95.0
        mat = np.where(inside, 1, 0).astype(np.int16)
        fat = 14.0
        inner = rho <= 1 - fat / b["ax"][0]
        if "extra" in b:
            inner |= np.hypot(P[:, 0] - ec[0], P[:, 1] - ec[1]) <= er - fat
        hu[inner] = 45.0
        mat[inner] = 2
        if b.get("lung") is not None:
            lc, la = b["lung"]
            lr = np.sqrt(((P[:, 0] - lc[0]) / la[0]) ** 2 + ((P[:, 1] - lc[1]) / la[1]) ** 2)
            lung = (lr <= 1) & (np.abs(P[:, 0]) > 25)
            hu[lung] = -840.0
            mat[lung] = 3
        if self.a["gap_hu"]:
            for f in self.fills:
                m = f(P)
                hu[m] = float(self.a["gap_hu"])
                mat[m] = 4
        for bi, (name, fn, cfn, chu, thu, role) in enumerate(self.bones):
            if cfn is None:
                L, shaft = fn(P, parts=True)
                t = np.where(shaft > 0, np.maximum(shaft, self._cortex_of[name]), self._cortex_of[name])
            else:
                L = fn(P)
                t = cfn(P, L)
            bone = L <= 0
            hu[bone] = chu
            mat[bone] = 10 + 2 * bi
            trab = L <= -t
            hu[trab] = thu + tex(P[trab])
            mat[trab] = 11 + 2 * bi
        for p0, p1, r in self.metal:
            m = capsule(P, p0, p1, r) <= 0
            hu[m] = METAL_HU
            mat[m] = METAL_MATERIAL
        return hu, rho0, mat


METAL_HU, METAL_MATERIAL = 3000.0, 9


def add_metal_streaks(vol, mat, sp, D, rng):
    """Streaks in each slice (index axis 2) that holds metal: a dark band
    along the metal's longest in-plane extent (photon starvation, beam
    hardening) and bright and dark rays alternating about it, fading over
    about 50 mm."""
    for k in range(vol.shape[2]):
        ii, jj = np.nonzero(mat[:, :, k] == METAL_MATERIAL)
        if len(ii) == 0:
            continue
        xy = np.stack([ii * sp[0], jj * sp[1]], 1)
        mid = xy.mean(0)
        spread = np.cov((xy - mid).T) if len(ii) > 2 else np.eye(2)
        w, v = np.linalg.eigh(spread + 1e-9 * np.eye(2))
        along = np.arctan2(v[1, 1], v[0, 1])  # the longest in-plane extent
        X, Y = np.meshgrid(np.arange(vol.shape[0]) * sp[0] - mid[0], np.arange(vol.shape[1]) * sp[1] - mid[1], indexing="ij")
        d = np.hypot(X, Y)
        th = np.arctan2(Y, X) - along
        off = np.angle(np.exp(2j * th)) / 2  # angle from the band's line, in (-pi/2, pi/2]
        amp = 450.0 * min(1.0, len(ii) / 20.0)
        streak = amp * np.exp(-d / 50.0) * (0.5 * np.cos(10 * th + rng.uniform(0, 2 * np.pi)) - np.exp(-0.5 * (off / 0.12) ** 2))
        streak[d < 4.0] = 0
        vol[:, :, k] += streak.astype(np.float32)


def kernel1d(kind, w_mm, sp):
    """1-D kernel in voxels for a blur of width w_mm along an axis of spacing sp"""
    if w_mm <= 0:
        return None
    if kind == "gauss":
        s = w_mm / sp
        h = max(1, int(np.ceil(4 * s)))
        x = np.arange(-h, h + 1)
        k = np.exp(-0.5 * (x / s) ** 2)
    elif kind == "box":  # box of full width w_mm, the edge voxels partially weighted
        hw = w_mm / sp / 2
        h = int(np.ceil(hw + 0.5))
        x = np.arange(-h, h + 1)
        k = np.clip(hw + 0.5 - np.abs(x), 0, 1)
    elif kind == "lorentz":  # Cauchy of half width at half maximum w_mm, truncated at 8 HWHM
        g = w_mm / sp
        h = max(1, int(np.ceil(8 * g)))
        x = np.arange(-h, h + 1)
        k = 1.0 / (1 + (x / g) ** 2)
    else:
        raise SystemExit("blur: gauss|box|lorentz")
    return k / k.sum()


def main():
    a = dict(DEFAULTS)
    for kv in sys.argv[1:]:
        k, v = kv.split("=", 1)
        if k not in DEFAULTS and k != "out":
            raise SystemExit("unknown option " + k)
        a[k] = v
    out = a["out"]
    rng = np.random.default_rng(int(a["seed"]))
    t0 = time.time()
    sc = Scene(a, rng)
    sp = np.array([float(v) for v in a["spacing"].split(",")])
    # grid direction (LPS): columns are the index axes' directions
    base = np.eye(3) if a["orient"] in ("lps", "obl") else np.diag([-1.0, 1.0, 1.0]) if a["orient"] == "flipx" else np.diag([-1.0, -1.0, 1.0])
    if a["orient"] == "oblras":
        base = np.diag([-1.0, -1.0, 1.0])
    D = rot([float(v) for v in a["obl"].split(",")]) @ base if a["orient"] in ("obl", "oblras") else base
    half = np.array([float(v) for v in a["fov"].split(",")])
    prim = next(h for h in sc.heads if h["primary"])
    if a["joint"] == "hip" and a["both"] == "1":
        centre = np.array([0.0, prim["center"][1], prim["center"][2]])
    else:
        centre = prim["center"].copy()
    centre = centre + np.array([float(v) for v in a["fov_shift"].split(",")])
    n = np.ceil(2 * half / sp).astype(int)
    M = D @ np.diag(sp)
    O = centre - M @ ((n - 1) / 2.0)
    # trabecular texture: a few plane waves of 2.5-4 mm wavelength
    kk = rng.normal(size=(8, 3)); kk /= np.linalg.norm(kk, axis=1)[:, None]
    kk *= (2 * np.pi / rng.uniform(2.5, 4.0, 8))[:, None]
    ph = rng.uniform(0, 2 * np.pi, 8)
    amp = float(a["tex"])
    tex = lambda P: (amp / 2.0) * np.cos(P @ kk.T + ph).sum(1) if len(P) else np.zeros(0)
    sub = int(a["sub"])
    offs = (np.arange(sub) + 0.5) / sub - 0.5
    N = int(np.prod(n))
    grid_idx = lambda flat: np.stack(np.unravel_index(flat, tuple(n)), 1).astype(np.float64)
    vol = np.empty(N, np.float32); mat = np.empty(N, np.int16); rho_map = np.empty(N, np.float32)
    CH = 1 << 20
    for s0 in range(0, N, CH):
        fl = np.arange(s0, min(N, s0 + CH))
        P = O + grid_idx(fl) @ M.T
        vol[fl], rho_map[fl], mat[fl] = sc.evaluate(P, tex)
    vol = vol.reshape(tuple(n)); mat = mat.reshape(tuple(n)); rho_map = rho_map.reshape(tuple(n))
    if sub > 1:  # partial volume: supersample the voxels at a material boundary
        edge = ndimage.maximum_filter(mat, 3) != ndimage.minimum_filter(mat, 3)
        ef = np.flatnonzero(edge)
        so = np.stack(np.meshgrid(offs, offs, offs, indexing="ij"), -1).reshape(-1, 3)
        per = max(1, CH // len(so))
        vflat = vol.reshape(-1)
        for s0 in range(0, len(ef), per):
            fl = ef[s0:s0 + per]
            I = (grid_idx(fl)[:, None, :] + so[None]).reshape(-1, 3)
            hu = sc.evaluate(O + I @ M.T, tex)[0]
            vflat[fl] = hu.reshape(len(fl), len(so)).mean(1)
    # blur (separable, per index axis; axis 2 is the slice direction)
    widths = [float(a["blur_xy"])] * 2 + [float(a["blur_z"])]
    for ax_ in range(3):
        kern = kernel1d(a["blur"], widths[ax_], sp[ax_])
        if kern is not None:
            vol = ndimage.convolve1d(vol, kern.astype(np.float32), axis=ax_, mode="nearest")
    if sc.metal:
        add_metal_streaks(vol, mat, sp, D, rng)
    # cupping: darker in the body's middle
    cup = float(a["cupping"])
    if cup:
        vol -= np.where(rho_map < 1, cup * (1 - rho_map ** 2), 0).astype(np.float32)
    nz = rng.normal(0, 1, vol.shape).astype(np.float32)
    nc = float(a["noise_corr"])
    if nc > 0:
        nz = ndimage.gaussian_filter(nz, [nc / sp[0], nc / sp[1], nc / sp[2]])
        nz /= nz.std()
    vol += float(a["noise"]) * nz
    # storage
    slope, inter = float(a["slope"]), float(a["inter"])
    if a["store"] == "int16":
        data = np.clip(np.round((vol - inter) / slope), -32768, 32767).astype("<i2"); dt, bp = 4, 16
    else:
        data = ((vol - inter) / slope).astype("<f4"); dt, bp = 16, 32
    # NIfTI-1: index -> RAS = diag(-1,-1,1) (O + M idx)
    F = np.diag([-1.0, -1.0, 1.0])
    Mr, Or = F @ M, F @ O
    hdr = bytearray(348)
    struct.pack_into("<i", hdr, 0, 348)
    struct.pack_into("<8h", hdr, 40, 3, n[0], n[1], n[2], 1, 1, 1, 1)
    struct.pack_into("<hhh", hdr, 70, dt, bp, 0)
    Dr = F @ D
    qfac = 1.0
    if np.linalg.det(Dr) < 0:
        qfac = -1.0
        Dr = Dr.copy(); Dr[:, 2] *= -1
    struct.pack_into("<8f", hdr, 76, qfac, sp[0], sp[1], sp[2], 1, 1, 1, 1)
    struct.pack_into("<f", hdr, 108, 352.0)
    struct.pack_into("<ff", hdr, 112, slope, inter)
    hdr[123] = 2  # mm
    qc = 1 if a["hdr"] in ("qform", "both") else 0
    scd = 1 if a["hdr"] in ("sform", "both") else 0
    struct.pack_into("<hh", hdr, 252, qc, scd)
    x, y, z, w = Rotation.from_matrix(Dr).as_quat()
    if w < 0:
        x, y, z = -x, -y, -z
    struct.pack_into("<6f", hdr, 256, x, y, z, Or[0], Or[1], Or[2])
    for r in range(3):
        struct.pack_into("<4f", hdr, 280 + 16 * r, Mr[r, 0], Mr[r, 1], Mr[r, 2], Or[r])
    hdr[344:348] = b"n+1\0"
    payload = bytes(hdr) + b"\0" * 4 + data.transpose(2, 1, 0).tobytes()
    fn = out + (".nii.gz" if a["gz"] == "1" else ".nii")
    if a["gz"] == "1":
        with gzip.open(fn, "wb", compresslevel=3) as f:
            f.write(payload)
    else:
        open(fn, "wb").write(payload)
    # truth, with a check of the least bone-to-bone separation of each head from its socket bone
    heads = []
    dirs = np.random.default_rng(0).normal(size=(6000, 3)); dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    for h in sc.heads:
        Ps = h["center"] + (dirs * h["radii"]) @ h["axes"].T
        own = [b for b in sc.bones if b[5] == "head" and b[0].endswith(h["side"]) or b[0] == "humerus"]
        surf = own[0][1](Ps + 0.05 * (Ps - h["center"]) / np.linalg.norm(Ps - h["center"], axis=1)[:, None]) > 0
        others = [b[1](Ps[surf]) for b in sc.bones if b[5] != "head"]
        h["clearance"] = float(np.min(others)) if others else None
        h["free_share"] = float(surf.mean())
        heads.append(dict(side=h["side"], head_center_mm=h["center"].tolist(), radii_mm=h["radii"].tolist(),
                          axes_lps_columns=h["axes"].tolist(), gap_mm=h["gap"], socket_center_mm=h["socket_center"].tolist(),
                          socket_radius_mm=h["socket_radius"], socket_dome_dir=h["socket_dome"].tolist(),
                          cover_deg=h["cover_deg"], primary=h["primary"],
                          clearance_mm=h["clearance"], head_surface_free_share=h["free_share"],
                          dome_cut_mm=h.get("dome_cut_mm", 0.0), metal=a["metal"] if h["primary"] else "none"))
    truth = dict(generator="third_phantom", coordinate_system="LPS", units="mm", options=a, spacing_mm=sp.tolist(), size=n.tolist(),
                 direction_lps=D.tolist(), origin_lps=O.tolist(), heads=heads,
                 head_center_mm=prim["center"].tolist(), radii_mm=prim["radii"].tolist(), axes_lps_columns=prim["axes"].tolist(),
                 seconds=round(time.time() - t0, 1))
    json.dump(truth, open(out + ".json", "w"), indent=1)
    print("wrote", fn, "voxels", n.tolist(), "in %.0f s" % (time.time() - t0))


def head_distances(errors_csv, truth_json, side):
    """Each articular point of an `articula run` (errors/errors.csv) against
    the true head of `side`: its radial distance (mm, positive outside) to
    the head's ellipsoid, in the head's own frame."""
    import csv
    h = next(h for h in json.load(open(truth_json))["heads"] if h["side"] == side)
    c, rad, A = np.array(h["head_center_mm"]), np.array(h["radii_mm"]), np.array(h["axes_lps_columns"])
    P = np.array([[float(x[k]) for k in ("x_mm", "y_mm", "z_mm")] for x in csv.DictReader(open(errors_csv))])
    L = (P - c) @ A
    n = np.linalg.norm(L, axis=1)
    return n - n / np.sqrt(((L / rad) ** 2).sum(1))


if __name__ == "__main__":
    main()

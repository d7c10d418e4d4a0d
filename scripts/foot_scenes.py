#!/usr/bin/env python3
"""Writes the two foot scenes of `articula simulate` (scenes/foot_surfaces.json
and scenes/foot_points.json): one three-segment foot (rear-, mid- and
forefoot, hinged at the midtarsal and the metatarsophalangeal joints, whose
axes are oblique as in a real foot) landing heel first with forward speed
and rolling to the toes, its sole made either of 6 ellipsoid /
superellipsoid-plane elements or of 31 point-plane elements placed on the
same six surfaces (at each surface's lowest point and on a ring around it),
with the same contact law family, mass, joints and start. Lengths in m,
masses in kg, the foot's x forwards, y to the left, z up; the rearfoot
carries a lumped share of the leg's mass.
    python3 scripts/foot_scenes.py [scenes]"""
import json
import math
import os
import sys

# Segments: centre of mass in the flat foot (sole on z = 0, heel at x = 0).
SEGMENTS = {
    "rearfoot": dict(com=(0.05, 0.0, 0.045), mass=6.0, inertia=(0.03, 0.04, 0.03)),
    "midfoot": dict(com=(0.14, 0.0, 0.03), mass=0.4, inertia=(4e-4, 6e-4, 6e-4)),
    "forefoot": dict(com=(0.22, 0.0, 0.012), mass=0.15, inertia=(8e-5, 1e-4, 1.2e-4)),
}
JOINTS = {  # child: parent, joint centre in the flat foot, axis, stiffness (N m/rad), damping (N m s/rad)
    "midfoot": ("rearfoot", (0.105, 0.0, 0.035), (0.2, 1.0, 0.1), 150.0, 0.5),
    "forefoot": ("midfoot", (0.19, 0.0, 0.018), (0.3, 1.0, 0.0), 20.0, 0.05),
}
# The sole: (segment, model, centre in the flat foot, radii, exponents, points on it).
SOLE = [
    ("rearfoot", "superellipsoid", (0.035, 0.0, 0.025), (0.035, 0.028, 0.025), (2.0, 2.0, 2.5), 8),  # heel
    ("rearfoot", "ellipsoid", (0.085, -0.022, 0.02), (0.03, 0.014, 0.02), (2.0, 2.0, 2.0), 4),  # lateral rearfoot
    ("midfoot", "ellipsoid", (0.13, -0.03, 0.015), (0.03, 0.013, 0.015), (2.0, 2.0, 2.0), 4),  # lateral midfoot
    ("midfoot", "superellipsoid", (0.175, 0.025, 0.014), (0.018, 0.016, 0.014), (2.0, 2.0, 3.0), 5),  # 1st metatarsal head
    ("midfoot", "superellipsoid", (0.165, -0.035, 0.012), (0.015, 0.012, 0.012), (2.0, 2.0, 3.0), 5),  # 5th metatarsal head
    ("forefoot", "ellipsoid", (0.225, 0.022, 0.009), (0.02, 0.013, 0.009), (2.0, 2.0, 2.0), 5),  # hallux
]
SURFACE_STIFFNESS = 3e6  # N/m^1.5 per surface element; a point of a surface with k points gets 1/k of it
DISSIPATION = 1.0  # s/m (Hunt-Crossley)
FRICTION = {"dynamic": 0.6, "static": 0.8, "transition_speed": 0.05}
PITCH_DEG = -15.0  # toes up
START_VELOCITY = (1.2, 0.0, -0.4)
START_SPIN = (0.0, 10.0, 0.0)  # rad/s, pitching forwards (toes down)
CLEARANCE = 0.002  # the lowest point of the sole above the ground at the start


def sub(a, b):
    return [x - y for x, y in zip(a, b)]


def surface_points(centre, radii, exponents, count):
    """The surface's lowest point and count - 1 points on a ring at 0.6 of its radii."""
    out = [(centre[0], centre[1], centre[2] - radii[2])]
    for k in range(count - 1):
        a = 2 * math.pi * k / (count - 1)
        u, v = 0.6 * math.cos(a), 0.6 * math.sin(a)
        w = (1 - abs(u) ** exponents[0] - abs(v) ** exponents[1]) ** (1 / exponents[2])
        out.append((centre[0] + u * radii[0], centre[1] + v * radii[1], centre[2] - w * radii[2]))
    return out


def rotate_y(p, deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return (c * p[0] + s * p[2], p[1], -s * p[0] + c * p[2])


def scene(kind):
    points = [p for seg, _, c, r, e, k in SOLE for p in surface_points(c, r, e, k)]
    assert len(points) == 31
    rear = SEGMENTS["rearfoot"]["com"]
    # Place the pitched foot (turned about the rearfoot's centre) CLEARANCE above the ground.
    lowest = min(rotate_y(sub(p, rear), PITCH_DEG)[2] for p in points)
    bodies = []
    for name, s in SEGMENTS.items():
        b = {"name": name, "mass": s["mass"], "inertia": list(s["inertia"])}
        if name in JOINTS:
            parent, at, axis, k, c = JOINTS[name]
            b["joint"] = {"type": "revolute", "parent": parent, "point_in_parent": sub(at, SEGMENTS[parent]["com"]),
                          "point_in_child": sub(at, s["com"]), "axis": list(axis), "stiffness": k, "damping": c}
        else:
            b.update(position=[0.0, 0.0, CLEARANCE - lowest], angles_deg=[0.0, PITCH_DEG, 0.0],
                     velocity=list(START_VELOCITY), angular_velocity=list(START_SPIN))
        bodies.append(b)
    plane = {"plane": {"point": [0, 0, 0], "normal": [0, 0, 1]}}
    contacts = []
    for seg, model, c, r, e, k in SOLE:
        com = SEGMENTS[seg]["com"]
        if kind == "surfaces":
            shape = {"model": model, "radii": list(r), "center": sub(c, com)}
            if model == "superellipsoid":
                shape["exponents"] = list(e)
            contacts.append({"body": seg, "shape": shape, "against": plane,
                             "normal_law": {"law": "hunt-crossley", "stiffness": SURFACE_STIFFNESS,
                                            "dissipation": DISSIPATION}, "friction": FRICTION})
        else:
            for p in surface_points(c, r, e, k):
                contacts.append({"body": seg, "point": [round(x, 6) for x in sub(p, com)], "against": plane,
                                 "normal_law": {"law": "hunt-crossley", "stiffness": SURFACE_STIFFNESS / k,
                                                "dissipation": DISSIPATION}, "friction": FRICTION})
    what = ("6 ellipsoid / superellipsoid-plane elements" if kind == "surfaces" else
            "31 point-plane elements on the same six surfaces")
    return {
        "description": "A three-segment foot (rear-, mid-, forefoot; oblique midtarsal and metatarsophalangeal "
                       "hinges with passive stiffness and damping) landing heel first with forward speed and "
                       "rolling to the toes, its sole made of " + what + ". Made by scripts/foot_scenes.py.",
        "gravity": [0, 0, -9.81], "duration": 1.0, "output_interval": 0.005,
        "integrator": {"type": "runge-kutta-merson", "accuracy": 1e-4},
        "bodies": bodies, "contacts": contacts}


if __name__ == "__main__":
    folder = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "scenes")
    for kind in ("surfaces", "points"):
        with open(os.path.join(folder, f"foot_{kind}.json"), "w") as f:
            json.dump(scene(kind), f, indent=1)
            f.write("\n")

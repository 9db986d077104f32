# Writes models_real/models_info.json (BOP format, translations in metres as the models): the
# symmetries of the hull models (make_hull_models.py), found on the dataset's own model points
# rather than assumed. Candidates are turns about the axes of the object's bounding box in the
# model's x-y plane (the yaw that minimises the box's area, 0.1 deg steps; YCB-Video's models stand
# on their z axis), through the box's centre: the half turns about the three axes, for a near-square
# cross-section the quarter turns and the half turns about the square's diagonals, for a round one a
# continuous turn about z (checked at 10 deg steps). A candidate is kept when it maps the object
# onto itself: the turned points' mean distance to the hull model's surface [mm] exceeds the
# untouched points' own (the concave parts the hull fills: the can's lid, 1.7 mm) by at most
# KEEP_MM (a printed label has no depth; the points are random surface samples, so they cannot be
# matched one to one). For a convex hull with face planes n.x = d the distance of x is
# |max_i (n_i.x - d_i)|: exact inside, a lower bound outside beyond an edge. Prints each
# candidate's distance and the untouched points' (the points off their own hull). Run from this folder with Python 3 and numpy
# (python3-numpy, one of ./mmh's packages).
import json
import math

import numpy as np

KEEP_MM = 0.5
OBJECTS = {1: "002_master_chef_can", 3: "004_sugar_box", 8: "009_gelatin_box", 21: "061_foam_brick"}
# Objects written with no symmetry and not searched: the mug (make_mug_model.py's mesh, not a hull,
# so hull_planes does not apply) has none, its handle breaking every turn (BOP's YCB-V
# models_info.json gives it none either).
NO_SYMMETRY = {14: "025_mug"}


def rotation(axis, angle):
    x, y, z = np.asarray(axis, float) / np.linalg.norm(axis)
    c, s = math.cos(angle), math.sin(angle)
    C = 1 - c
    return np.array([[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
                     [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
                     [z * x * C - y * s, z * y * C + x * s, c + z * z * C]])


def hull_planes(path):
    vertices, normals, offsets = [], [], []
    for line in open(path):
        f = line.split()
        if f and f[0] == "v":
            vertices.append([float(v) for v in f[1:4]])
        elif f and f[0] == "f":
            a, b, c = (np.array(vertices[int(i) - 1]) for i in f[1:4])
            n = np.cross(b - a, c - a)
            n /= np.linalg.norm(n)
            normals.append(n)
            offsets.append(n @ a)
    return np.array(normals), np.array(offsets)


def mean_hull_distance_mm(points, planes, r, t):
    normals, offsets = planes
    moved = points @ r.T + t
    return 1000 * np.abs((moved @ normals.T - offsets).max(1)).mean()


def symmetry(points, planes, axis, angle, centre):
    r = rotation(axis, angle)
    t = centre - r @ centre
    return r, t, mean_hull_distance_mm(points, planes, r, t)


def as_bop(r, t):
    m = [[round(float(v), 9) for v in list(r[i]) + [t[i]]] for i in range(3)]
    return [0.0 if abs(v) < 1e-12 else v for row in m for v in row] + [0, 0, 0, 1]


info = {}
for obj_id, name in OBJECTS.items():
    points = np.loadtxt("models_real/points/%s.xyz" % name)
    planes = hull_planes("models_real/%s.obj" % name)
    own = mean_hull_distance_mm(points, planes, np.eye(3), np.zeros(3))
    print("%s: the points' own distance to the hull %.2f mm" % (name, own))
    best = None
    for k in range(900):
        a = math.radians(k / 10)
        ex, ey = np.array([math.cos(a), math.sin(a), 0]), np.array([-math.sin(a), math.cos(a), 0])
        u, v = points @ ex, points @ ey
        area = (u.max() - u.min()) * (v.max() - v.min())
        if best is None or area < best[0]:
            best = (area, k / 10, ex, ey)
    _, yaw, ex, ey = best
    ez = np.array([0.0, 0.0, 1.0])
    axes = [ex, ey, ez]
    coords = [points @ e for e in axes]
    mid = [(c.max() + c.min()) / 2 for c in coords]
    extent = [1000 * (c.max() - c.min()) for c in coords]
    centre = sum(m * e for m, e in zip(mid, axes))
    print("%s: yaw %.1f deg, extents %.1f x %.1f x %.1f mm" % (name, yaw, *extent))
    kept, continuous = [], []
    round_z = all(symmetry(points, planes, ez, math.radians(a), centre)[2] - own <= KEEP_MM for a in range(10, 360, 10))
    print("  continuous about z: %s" % round_z)
    candidates = [("half turn about x", ex, math.pi), ("half turn about y", ey, math.pi)]
    if round_z:
        continuous.append({"axis": [0, 0, 1], "offset": [round(float(v), 9) for v in centre]})
    else:
        candidates.append(("half turn about z", ez, math.pi))
        for i, j in ((0, 1), (0, 2), (1, 2)):
            if abs(extent[i] - extent[j]) < 2.0:  # a near-square cross-section
                n = np.cross(axes[i], axes[j])
                candidates += [("quarter turn about the square's normal", n, math.pi / 2),
                               ("three-quarter turn about the square's normal", n, 3 * math.pi / 2),
                               ("half turn about a diagonal", axes[i] + axes[j], math.pi),
                               ("half turn about the other diagonal", axes[i] - axes[j], math.pi)]
    discrete = []
    for label, axis, angle in candidates:
        r, t, d = symmetry(points, planes, axis, angle, centre)
        keep = d - own <= KEEP_MM
        print("  %s: %.2f mm %s" % (label, d, "kept" if keep else "rejected"))
        if keep:
            discrete.append(as_bop(r, t))
    entry = {}
    if discrete:
        entry["symmetries_discrete"] = discrete
    if continuous:
        entry["symmetries_continuous"] = continuous
    info[str(obj_id)] = entry
for obj_id in NO_SYMMETRY:
    info[str(obj_id)] = {}
# One symmetry a line, as models/models_info.json, by object id.
entries = []
for key, entry in sorted(info.items(), key=lambda item: int(item[0])):
    parts = []
    for field, values in entry.items():
        parts.append('"%s": [\n    %s]' % (field, ",\n    ".join(json.dumps(v) for v in values)))
    entries.append('  "%s": {%s}' % (key, ",\n   ".join(parts)))
with open("models_real/models_info.json", "w") as f:
    f.write("{\n" + ",\n".join(entries) + "\n}\n")

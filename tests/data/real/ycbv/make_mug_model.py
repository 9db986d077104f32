# The mug's mesh (models_real/025_mug.obj) in YCB-Video's model frame, from the YCB Object and
# Model Set's own scan of the mug. The mug is not convex (its hollow and its handle), so the hull of
# its points (make_hull_models.py) would not do. Its scan is the YCB set's "google_16k" mesh (CC BY
# 4.0), as re-centred by the source repository (PROVENANCE.md); YCB-Video's models are these scans
# moved into their own frame. This script finds that move from the dataset's own model points
# (models_real/points/025_mug.xyz, the frame the ground-truth poses use) instead of assuming it:
#   1. ICP of the points onto the scan (closest points on the triangles, Kabsch), started from
#      the two bounding boxes' centres at each of 8 turns about z times 2 flips, the best kept;
#   2. the scan moved by the fit's inverse, then decimated (Blender's collapse decimation) to
#      TARGET_FACES triangles to keep the committed file small;
#   3. the points' distance to the full and the decimated mesh printed (the fit's residual and the
#      decimation's error), the figures PROVENANCE.md quotes.
#
# Run from this folder with Blender's Python (Blender is one of ./mmh's packages), giving the
# source repository's mug_visual.obj:
#   blender -b --factory-startup --python make_mug_model.py -- /path/to/mug_visual.obj
# Deterministic: the same inputs give the same file.
import math
import os
import sys

import bmesh
import bpy
import numpy as np
from mathutils import Vector
from mathutils.bvhtree import BVHTree

TARGET_FACES = 4096
ICP_ITERATIONS = 40


def read_obj(path):
    vertices, faces = [], []
    for line in open(path):
        f = line.split()
        if f and f[0] == "v":
            vertices.append([float(v) for v in f[1:4]])
        elif f and f[0] == "f":
            faces.append([int(i.split("/")[0]) - 1 for i in f[1:]])
    return np.array(vertices), faces


def distances(tree, points):
    return np.array([(tree.find_nearest(Vector(p))[0] - Vector(p)).length for p in points])


def closest(tree, points):
    return np.array([tuple(tree.find_nearest(Vector(p))[0]) for p in points])


def kabsch(a, b):
    """The rotation and translation that move points a onto b (least squares)."""
    ca, cb = a.mean(0), b.mean(0)
    u, _, wt = np.linalg.svd((a - ca).T @ (b - cb))
    d = np.diag([1.0, 1.0, np.sign(np.linalg.det(wt.T @ u.T))])
    r = wt.T @ d @ u.T
    return r, cb - r @ ca


def summary(d):
    return "mean %.3f mm, RMS %.3f mm, 99th percentile %.3f mm, max %.3f mm" % (
        1e3 * d.mean(), 1e3 * math.sqrt((d ** 2).mean()), 1e3 * np.percentile(d, 99), 1e3 * d.max())


source = sys.argv[sys.argv.index("--") + 1]
scan_vertices, scan_faces = read_obj(source)
points = np.loadtxt(os.path.join("models_real", "points", "025_mug.xyz"))
scan_tree = BVHTree.FromPolygons([tuple(v) for v in scan_vertices], scan_faces)

# 1. points (YCB-Video frame) -> scan frame: x_scan = r @ x + t.
best = None
scan_mid = (scan_vertices.min(0) + scan_vertices.max(0)) / 2
points_mid = (points.min(0) + points.max(0)) / 2
for flip in (1, -1):
    for k in range(8):
        a = k * math.pi / 4
        r = np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]]) @ np.diag(
            [1, flip, flip])
        t = scan_mid - r @ points_mid
        for _ in range(ICP_ITERATIONS):
            moved = points @ r.T + t
            dr, dt = kabsch(moved, closest(scan_tree, moved))
            r, t = dr @ r, dr @ t + dt
        d = distances(scan_tree, points @ r.T + t)
        if best is None or d.mean() < best[0]:
            best = (d.mean(), r, t, flip, k)
_, r, t, flip, k = best
angle = math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(r) - 1) / 2))))
print("fit from start %d/%d: turn %.4f deg, translation (%.3f, %.3f, %.3f) mm (YCB-Video -> scan)" %
      (flip, k, angle, *(1e3 * t)))

# 2. The scan in the YCB-Video frame (x = r^T (x_scan - t)), decimated.
moved_vertices = (scan_vertices - t) @ r
mesh = bpy.data.meshes.new("mug")
mesh.from_pydata([tuple(v) for v in moved_vertices], [], [tuple(f) for f in scan_faces])
obj = bpy.data.objects.new("mug", mesh)
bpy.context.scene.collection.objects.link(obj)
modifier = obj.modifiers.new("decimate", "DECIMATE")
modifier.ratio = TARGET_FACES / len(scan_faces)
evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
bm = bmesh.new()
bm.from_mesh(evaluated.to_mesh())
bmesh.ops.triangulate(bm, faces=bm.faces[:])
bm.verts.index_update()
out_vertices = [tuple(v.co) for v in bm.verts]
out_faces = [[v.index for v in f.verts] for f in bm.faces]

# 3. The residuals.
full_tree = BVHTree.FromPolygons([tuple(v) for v in moved_vertices], scan_faces)
out_tree = BVHTree.FromPolygons(out_vertices, out_faces)
print("points to the full scan (%d triangles): %s" % (len(scan_faces), summary(distances(full_tree, points))))
print("points to the decimated mesh (%d triangles, %d vertices): %s" %
      (len(out_faces), len(out_vertices), summary(distances(out_tree, points))))
# The decimated surface against the full one, from the full scan's vertices.
print("full scan's vertices to the decimated mesh: %s" % summary(distances(out_tree, moved_vertices)))

with open(os.path.join("models_real", "025_mug.obj"), "w") as f:
    f.write("# YCB 025_mug (YCB Object and Model Set, google_16k scan, CC BY 4.0), moved into YCB-Video's\n"
            "# model frame and decimated to %d triangles by make_mug_model.py; metres\n" % len(out_faces))
    for v in out_vertices:
        f.write("v %.6f %.6f %.6f\n" % v)
    for face in out_faces:
        f.write("f %s\n" % " ".join(str(i + 1) for i in face))
bm.free()

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
import os
import sys

import bmesh
import bpy
import numpy as np
from mathutils.bvhtree import BVHTree

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from scan_fit import distances, fit_points_to_scan, summary

TARGET_FACES = 4096


def read_obj(path):
    vertices, faces = [], []
    for line in open(path):
        f = line.split()
        if f and f[0] == "v":
            vertices.append([float(v) for v in f[1:4]])
        elif f and f[0] == "f":
            faces.append([int(i.split("/")[0]) - 1 for i in f[1:]])
    return np.array(vertices), faces


source = sys.argv[sys.argv.index("--") + 1]
scan_vertices, scan_faces = read_obj(source)
points = np.loadtxt(os.path.join("models_real", "points", "025_mug.xyz"))

# 1. points (YCB-Video frame) -> scan frame: x_scan = r @ x + t.
r, t = fit_points_to_scan(points, scan_vertices, scan_faces)

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

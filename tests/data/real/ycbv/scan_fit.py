# Fitting a YCB Object and Model Set scan into YCB-Video's model frame (make_mug_model.py,
# make_colour_model.py): ICP of the dataset's own model points (models_real/points/NAME.xyz,
# the frame of the ground-truth poses) onto the scan, with Blender's BVH tree for the closest points
# on the triangles. Run inside Blender's Python (numpy and mathutils come with it).
import math

import numpy as np
from mathutils import Vector
from mathutils.bvhtree import BVHTree

ICP_ITERATIONS = 40


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


def fit_points_to_scan(points, scan_vertices, scan_faces):
    """ICP of points (YCB-Video frame) onto the scan, started from the two bounding boxes' centres
    at each of 8 turns about z times 2 flips; the start whose result lies nearest on average wins.
    Returns (r, t) with x_scan = r @ x + t, and prints the move."""
    scan_tree = BVHTree.FromPolygons([tuple(v) for v in scan_vertices], scan_faces)
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
    return r, t

# An object's colour model (models_real/NAME_colour.ply: 009_gelatin_box, 002_master_chef_can) in
# YCB-Video's model frame, from the YCB Object and Model Set's own textured scan of it
# ("google_16k", CC BY 4.0; PROVENANCE.md): the scan's geometry with a colour per vertex, baked
# from its texture. The tracker's appearance check (tracker.appearance, docs/tracker.md) projects
# these colours into the colour image to tell apart the poses the depth cannot (the gelatin box
# turned over); the tracker's geometry stays the hull of the dataset's points
# (models_real/NAME.obj). NAME is the scan's file name without its extension.
#   1. the scan read from MuJoCo's binary .msh (int32 counts of vertices, normals, texture
#      coordinates and faces, then float32 positions, normals, (u, v) and int32 triangles);
#   2. ICP of YCB-Video's own points (models_real/points/NAME.xyz) onto the scan
#      (scan_fit.py), the scan moved by the fit's inverse;
#   3. the texture (4096 x 4096) averaged over 16 x 16 blocks to 256 x 256 (a texel ~0.7 mm on the
#      box: finer than the Xtion's pixel at 0.5-1 m), sampled bilinearly at each vertex's (u, v),
#      with v running down from the image's top row (MuJoCo's convention for this .msh and .png;
#      Blender's pixels start at the bottom row, so the row is 1 - v): checked by projecting the
#      colours at frame 1's true pose into its colour image (the back's white nutrition panel
#      lands on the image's; with v up the chromaticities' correlation is 0.1 or less);
#   4. written as binary little-endian PLY (x y z float, red green blue uchar; triangles), which
#      mmh's PLY reader reads (a face's colour: the mean of its corners').
# Run from this folder with Blender's Python, giving the scan and its texture:
#   blender -b --factory-startup --python make_colour_model.py -- 009_gelatin_box.msh 009_gelatin_box.png
#   blender -b --factory-startup --python make_colour_model.py -- 002_master_chef_can.msh 002_master_chef_can.png
# Deterministic: the same inputs give the same file.
import os
import struct
import sys

import bpy
import numpy as np
from mathutils.bvhtree import BVHTree

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from scan_fit import distances, fit_points_to_scan, summary

TEXTURE_SIZE = 256


def read_msh(path):
    data = open(path, "rb").read()
    nv, nn, nt, nf = struct.unpack("<4i", data[:16])
    offset = 16
    vertices = np.frombuffer(data, "<f4", 3 * nv, offset).reshape(-1, 3).astype(float)
    offset += 12 * nv + 12 * nn
    uv = np.frombuffer(data, "<f4", 2 * nt, offset).reshape(-1, 2).astype(float)
    offset += 8 * nt
    faces = np.frombuffer(data, "<i4", 3 * nf, offset).reshape(-1, 3)
    if offset + 12 * nf != len(data) or nt != nv:
        raise SystemExit("%s: unexpected layout (%d vertices, %d texture coordinates)" % (path, nv, nt))
    return vertices, uv, faces


def read_texture(path):
    image = bpy.data.images.load(path)
    w, h = image.size
    pixels = np.array(image.pixels[:], dtype=np.float32).reshape(h, w, image.channels)[:, :, :3]
    # Blender gives linear floats for an sRGB PNG only in its colour-managed views; pixels[] are
    # the file's values / 255 (sRGB), which is what the tracker compares against.
    block = h // TEXTURE_SIZE
    return pixels.reshape(TEXTURE_SIZE, block, TEXTURE_SIZE, block, 3).mean(axis=(1, 3))


def bilinear(texture, uv):
    size = texture.shape[0]
    x = np.clip(uv[:, 0] * size - 0.5, 0, size - 1)
    y = np.clip(uv[:, 1] * size - 0.5, 0, size - 1)
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    x1, y1 = np.minimum(x0 + 1, size - 1), np.minimum(y0 + 1, size - 1)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    return ((1 - fy) * ((1 - fx) * texture[y0, x0] + fx * texture[y0, x1]) +
            fy * ((1 - fx) * texture[y1, x0] + fx * texture[y1, x1]))


scan_path, texture_path = sys.argv[sys.argv.index("--") + 1:][:2]
name = os.path.splitext(os.path.basename(scan_path))[0]
scan_vertices, uv, faces = read_msh(scan_path)
points = np.loadtxt(os.path.join("models_real", "points", name + ".xyz"))
r, t = fit_points_to_scan(points, scan_vertices, faces.tolist())
moved = (scan_vertices - t) @ r
tree = BVHTree.FromPolygons([tuple(v) for v in moved], faces.tolist())
print("points to the moved scan (%d triangles): %s" % (len(faces), summary(distances(tree, points))))
texture_uv = np.c_[uv[:, 0], 1 - uv[:, 1]]
colours = np.clip(np.rint(bilinear(read_texture(os.path.abspath(texture_path)), texture_uv) * 255), 0, 255)
colours = colours.astype(np.uint8)
print("vertex colours: mean (%.1f, %.1f, %.1f)" % tuple(colours.mean(0)))

out = os.path.join("models_real", name + "_colour.ply")
with open(out, "wb") as f:
    header = ("ply\nformat binary_little_endian 1.0\n"
              "comment YCB %s (YCB Object and Model Set, google_16k scan, CC BY 4.0),\n"
              "comment moved into YCB-Video's model frame and its texture baked to vertex colours\n"
              "comment by make_colour_model.py; metres\n"
              "element vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
              "property uchar red\nproperty uchar green\nproperty uchar blue\n"
              "element face %d\nproperty list uchar int vertex_indices\nend_header\n" %
              (name, len(moved), len(faces)))
    f.write(header.encode("ascii"))
    vertex = np.zeros(len(moved), dtype=[("p", "<f4", 3), ("c", "u1", 3)])
    vertex["p"], vertex["c"] = moved, colours
    f.write(vertex.tobytes())
    face = np.zeros(len(faces), dtype=[("n", "u1"), ("i", "<i4", 3)])
    face["n"], face["i"] = 3, faces
    f.write(face.tobytes())
print("wrote %s (%d bytes)" % (out, os.path.getsize(out)))

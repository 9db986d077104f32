# Meshes of the convex YCB-Video objects from the dataset's own model points: each object's
# models_real/points/NAME.xyz (the 2 621 surface points YCB-Video ships as models/NAME/points.xyz, in
# metres in the model frame the ground-truth poses use) wrapped by its convex hull, written as
# models_real/NAME.obj. For a convex object (a box, a brick, a can) the hull of points sampled on
# its surface is that surface up to the sampling: a flat face is exact, a curved one (the can's
# wall, the brick's rounded edges) lies inside by the sagitta s^2 / (8 r) of the point spacing s,
# about 0.02 mm for the can (r = 51 mm, s = 3 mm). A concave part (the can's recessed lid, a mug)
# is filled: use it only for convex objects.
#
# Run from this folder with Blender's Python (Blender is one of ./mmh's packages):
#   blender -b --factory-startup --python make_hull_models.py
# Deterministic: the same points give the same file.
import os

import bmesh

NAMES = ["009_gelatin_box", "061_foam_brick", "002_master_chef_can", "004_sugar_box"]

for name in NAMES:
    with open(os.path.join("models_real", "points", name + ".xyz")) as f:
        points = [tuple(float(v) for v in line.split()) for line in f if line.strip()]
    bm = bmesh.new()
    for p in points:
        bm.verts.new(p)
    # convex_hull keeps the points inside the hull as loose vertices ("geom_interior"); drop them,
    # and triangulate so the OBJ holds triangles only.
    result = bmesh.ops.convex_hull(bm, input=bm.verts, use_existing_faces=False)
    bmesh.ops.delete(bm, geom=[g for g in result["geom_interior"] if isinstance(g, bmesh.types.BMVert)],
                     context="VERTS")
    bmesh.ops.delete(bm, geom=[v for v in bm.verts if not v.link_faces], context="VERTS")
    bmesh.ops.triangulate(bm, faces=bm.faces[:])
    bmesh.ops.recalc_face_normals(bm, faces=bm.faces[:])
    bm.verts.index_update()
    out = os.path.join("models_real", name + ".obj")
    with open(out, "w") as f:
        f.write("# Convex hull of YCB-Video's %s points.xyz (make_hull_models.py), metres\n" % name)
        for v in bm.verts:
            f.write("v %.6f %.6f %.6f\n" % tuple(v.co))
        for face in bm.faces:
            f.write("f %s\n" % " ".join(str(v.index + 1) for v in face.verts))
    print("%s: %d points, hull %d vertices, %d triangles" % (name, len(points), len(bm.verts), len(bm.faces)))
    bm.free()

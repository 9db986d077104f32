# Imports a .glb with Blender's own glTF importer (io_scene_gltf2, headless) and prints, as JSON,
# each animated object's keyframe range and its world pose at the requested frame indices.
#   blender -b --factory-startup --python-exit-code 2 -P blender_check.py -- FILE.glb FPS K1,K2,...
# Blender's importer converts glTF's +Y up to Blender's +Z up, so world poses are in our table frame
# (docs/notation.md, "glTF export"); frame index k (0-based, one keyframe per frame) is Blender
# frame frame_start + k.
import json
import sys

import addon_utils
import bpy
import numpy

# Debian 12's Blender 3.4 importer uses numpy.bool, an alias NumPy 1.24 (Debian 12's) removed
# (gltf2_blender_mesh.py, set_poly_smoothing); it was always the builtin bool.
if "bool" not in numpy.__dict__:
    numpy.bool = bool

args = sys.argv[sys.argv.index("--") + 1:]
path, fps, frames = args[0], int(args[1]), [int(k) for k in args[2].split(",") if k]
addon_utils.enable("io_scene_gltf2", default_set=True)
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.context.scene.render.fps = fps
bpy.context.scene.render.fps_base = 1.0
bpy.ops.import_scene.gltf(filepath=path)

result = {"objects": {}}
for obj in bpy.context.scene.objects:
    data = obj.animation_data
    if data is None or data.action is None:
        continue
    start, end = data.action.frame_range
    poses = []
    for k in frames:
        bpy.context.scene.frame_set(int(round(start)) + k)
        matrix = obj.matrix_world
        t = matrix.to_translation()
        q = matrix.to_quaternion()
        poses.append({"frame": k, "translation": [t.x, t.y, t.z], "quaternion_wxyz": [q.w, q.x, q.y, q.z]})
    result["objects"][obj.name] = {"frame_start": start, "frame_end": end, "poses": poses}
print("MMH_BLENDER_RESULT " + json.dumps(result))

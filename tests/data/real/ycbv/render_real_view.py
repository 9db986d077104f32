#!/usr/bin/env python3
"""The view of a real YCB-Video recording as a render config for `mmh render` (docs/tracker.md,
"Like for like: the real view rendered"), so that the tracker's error on the real frames can be
compared with its error on rendered frames of the same object, seen from the same place.

Input: the folder of `mmh track --input <YCB-Video folder> ... --set 'track.init="truth"'` on the
real frames (its track_summary.json holds camera_T_table, the tracker's table fit of the first
frame; its groundtruth.tum the recording's camera_T_object per frame) and the object's model.
Output in OUT: render.json (camera placement, proxy model and trajectory; materials left at the
defaults but the proxy's, a matte printed box) and table_T_proxy.tum:
  --motion static  the real frames' poses (camera_T_object through the first frame's table fit;
                   the real camera's small motion becomes the object's), one frame each;
  --motion turn    the first frame's pose turned from -15 to +15 deg about the table's normal
                   through the object's origin and slid 2 cm along the table's x, over --frames
                   frames (0.5 deg and 0.3 mm a frame at 60): more views of the same object, with
                   the speckle pattern moving over it.
  --other TRACK MODEL NAME ALBEDO SPECULARITY (repeatable) places another object of the frame as a static scene
                   object (scene.objects): its first pose from TRACK/groundtruth.tum (`mmh track`
                   on the same recording with that object's label), carried into the table frame
                   through the first track folder's table fit; MODEL is written relative to OUT;
                   ALBEDO and SPECULARITY are its IR material.
The camera is placed at the real camera's position in the table frame, looking at the point where
the real optical axis meets the table; a look-at camera has no roll, so the real camera's roll
about its axis (a few degrees) is not reproduced. Standard library only.
"""
import argparse
import json
import math
import os


def quaternion_to_matrix(x, y, z, w):
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]


def matrix_to_quaternion(r):
    w = math.sqrt(max(0.0, 1 + r[0][0] + r[1][1] + r[2][2])) / 2
    x = math.copysign(math.sqrt(max(0.0, 1 + r[0][0] - r[1][1] - r[2][2])) / 2, r[2][1] - r[1][2])
    y = math.copysign(math.sqrt(max(0.0, 1 - r[0][0] + r[1][1] - r[2][2])) / 2, r[0][2] - r[2][0])
    z = math.copysign(math.sqrt(max(0.0, 1 - r[0][0] - r[1][1] + r[2][2])) / 2, r[1][0] - r[0][1])
    return x, y, z, w


def multiply(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def apply(r, t, p):
    return [sum(r[i][k] * p[k] for k in range(3)) + t[i] for i in range(3)]


def inverse(r, t):
    rt = [[r[j][i] for j in range(3)] for i in range(3)]
    return rt, [-sum(rt[i][k] * t[k] for k in range(3)) for i in range(3)]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("track_folder")
    parser.add_argument("model")
    parser.add_argument("out")
    parser.add_argument("--motion", choices=["static", "turn"], default="turn")
    parser.add_argument("--frames", type=int, default=60)
    parser.add_argument("--ir-albedo", type=float, default=0.6)
    parser.add_argument("--specularity", type=float, default=0.05)
    parser.add_argument("--other", nargs=5, action="append", default=[],
                        metavar=("TRACK", "MODEL", "NAME", "ALBEDO", "SPECULARITY"),
                        help="another object of the frame, static (scene.objects)")
    parser.add_argument("--no-paths", dest="paths", action="store_false",
                        help="leave render.proxy and render.trajectory out of render.json (given "
                             "with --set instead: the committed views/ of the tests)")
    args = parser.parse_args()

    summary = json.load(open(os.path.join(args.track_folder, "track_summary.json")))
    c_T_t = summary["camera_T_table"]
    r_ct = quaternion_to_matrix(*c_T_t["quaternion_xyzw"])
    r_tc, t_tc = inverse(r_ct, c_T_t["translation"])  # table_T_camera
    forward = [r_tc[i][2] for i in range(3)]
    if forward[2] >= 0:
        raise SystemExit(f"{args.track_folder}/track_summary.json: the camera does not look down at the table")
    along = -t_tc[2] / forward[2]
    look_at = [t_tc[i] + along * forward[i] for i in range(3)]

    def table_poses(track_folder):
        poses = []
        for line in open(os.path.join(track_folder, "groundtruth.tum")):
            if line.startswith("#") or not line.strip():
                continue
            v = [float(a) for a in line.split()]
            r_co = quaternion_to_matrix(*v[4:8])
            poses.append((multiply(r_tc, r_co), apply(r_tc, t_tc, v[1:4])))
        if not poses:
            raise SystemExit(f"{track_folder}/groundtruth.tum: no poses")
        return poses

    poses = table_poses(args.track_folder)
    objects = []
    for track, model, name, albedo, specularity in args.other:
        r, t = table_poses(track)[0]
        q = matrix_to_quaternion(r)
        objects.append({"name": name, "mesh": os.path.relpath(model, args.out),
                        "x": t[0], "y": t[1], "z": t[2],
                        "qx": q[0], "qy": q[1], "qz": q[2], "qw": q[3],
                        "material": {"ir_albedo": float(albedo),
                                     "specularity": float(specularity)}})

    os.makedirs(args.out, exist_ok=True)
    # render.json + table_T_proxy.tum, or (--no-paths, several views in one folder) NAME_MOTION.*
    stem = os.path.basename(args.model).rsplit(".", 1)[0] + f"_{args.motion}"
    trajectory = os.path.join(os.path.abspath(args.out),
                              "table_T_proxy.tum" if args.paths else stem + ".tum")
    with open(trajectory, "w") as out:
        out.write(f"# table_T_proxy: {args.motion} view of {os.path.basename(args.model)} from "
                  f"{args.track_folder} (render_real_view.py)\n")
        if args.motion == "static":
            rows = poses
        else:
            r0, t0 = poses[0]
            rows = []
            for k in range(args.frames):
                f = k / max(1, args.frames - 1)
                a = math.radians(-15 + 30 * f)
                yaw = [[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]]
                rows.append((multiply(yaw, r0), [t0[0] - 0.01 + 0.02 * f, t0[1], t0[2]]))
        for k, (r, t) in enumerate(rows):
            q = matrix_to_quaternion(r)
            out.write("%.6f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n" % (k / 30, *t, *q))

    render = {"frames": len(rows), "hand": False, "slider": False, "bop": True}
    if args.paths:
        render.update({"proxy": os.path.abspath(args.model), "trajectory": trajectory})
    config = {
        "render": render,
        "camera": {"x": t_tc[0], "y": t_tc[1], "z": t_tc[2],
                   "look_at_x": look_at[0], "look_at_y": look_at[1], "look_at_z": look_at[2]},
        "scene": {"materials": {"proxy": {"ir_albedo": args.ir_albedo,
                                          "specularity": args.specularity}}},
    }
    if objects:
        config["scene"]["objects"] = objects
    name = "render.json" if args.paths else stem + ".json"
    with open(os.path.join(args.out, name), "w") as out:
        json.dump(config, out, indent=2)
        out.write("\n")
    print(f"camera at {t_tc[0]:.3f} {t_tc[1]:.3f} {t_tc[2]:.3f} m, {along:.3f} m from the table "
          f"along its axis; {len(rows)} frames -> {args.out}/{name}")


if __name__ == "__main__":
    main()

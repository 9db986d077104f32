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
  --desk DEPTH_PNG  fits the desk the objects stand on from that real depth frame (YCB-Video's
                   16-bit depth, 1/10000 m, registered to the colour camera of --intrinsics): its
                   front edge, where the table top's pixels meet the floor's (per image row that
                   crosses it, the top's last pixel; a line through them by total least squares;
                   their depth below the top is the front face's thickness, so that the rendered
                   edge falls on the same pixels), and the floor's height below the top (median); writes scene.table_x, table_y, table_yaw_deg (a top of
                   --desk-size whose front edge is that line), table_height, no tape (the real
                   scene has none: tape_thickness 0, a 0.1 m play area that stays on the desk) and
                   no wall (the floor beyond the desk, as in the real frame). Needs numpy.
The camera is placed at the real camera's position in the table frame, looking at the point where
the real optical axis meets the table, turned about its axis by the real camera's roll
(camera.roll_deg; before 2026-11-30 the roll was left out). Standard library only, but for --desk.
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


def read_depth_png(path):
    """A 16-bit greyscale PNG as a numpy array of rows (PNG's five row filters undone)."""
    import numpy as np
    import struct
    import zlib
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise SystemExit(f"{path}: not a PNG file")
    at, idat, header = 8, [], None
    while at < len(data):
        size, kind = struct.unpack(">I4s", data[at:at + 8])
        chunk = data[at + 8:at + 8 + size]
        at += 12 + size
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", chunk)
        elif kind == b"IDAT":
            idat.append(chunk)
    width, height, bits, colour = header[:4]
    if bits != 16 or colour != 0 or header[6] != 0:
        raise SystemExit(f"{path}: {bits}-bit colour type {colour} (interlace {header[6]}); "
                         "expected a non-interlaced 16-bit greyscale depth image")
    raw = zlib.decompress(b"".join(idat))
    stride = 2 * width
    rows = np.zeros((height, stride), np.int32)
    previous = np.zeros(stride, np.int32)
    for v in range(height):
        kind = raw[v * (stride + 1)]
        line = np.frombuffer(raw, np.uint8, stride, v * (stride + 1) + 1).astype(np.int32)
        if kind == 0:
            row = line
        elif kind == 2:
            row = (line + previous) & 255
        else:  # Sub, Average, Paeth: each byte depends on the one two bytes (one pixel) left
            row = np.zeros(stride, np.int32)
            for u in range(stride):
                a = row[u - 2] if u >= 2 else 0
                b = previous[u]
                c = previous[u - 2] if u >= 2 else 0
                if kind == 1:
                    x = a
                elif kind == 3:
                    x = (a + b) >> 1
                else:
                    p = a + b - c
                    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                    x = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                row[u] = (line[u] + x) & 255
        rows[v] = row
        previous = row
    return (rows[:, 0::2] << 8) | rows[:, 1::2]


def fit_desk(depth_png, intrinsics, r_tc, t_tc, size):
    """The desk's scene keys from a real depth frame (see --desk)."""
    import numpy as np
    depth = read_depth_png(depth_png) / 10000.0
    fx, fy, cx, cy = intrinsics
    v, u = np.mgrid[0:depth.shape[0], 0:depth.shape[1]]
    camera = np.stack([(u - cx) / fx * depth, (v - cy) / fy * depth, depth], -1)
    table = camera @ np.array(r_tc).T + np.array(t_tc)  # table_p = table_R_camera camera_p + t
    valid = depth > 0
    # The top's pixels by its edge see the desk's front face, down to about 1.5 cm below the top:
    # a 5 cm slab, not the table fit's own 1 cm.
    on_top = valid & (np.abs(table[..., 2]) < 0.05)
    on_floor = valid & (table[..., 2] < -0.3)
    # Per image row, the table-top pixel nearest to the floor's pixels on its left or right,
    # where the row crosses the desk's edge (missing pixels between are allowed).
    edge = []
    for row in range(depth.shape[0]):
        floor_u = np.flatnonzero(on_floor[row])
        top_u = np.flatnonzero(on_top[row])
        if len(floor_u) < 5 or len(top_u) < 5:
            continue
        if floor_u.max() < top_u.min():
            edge.append(table[row, top_u.min()])
        elif top_u.max() < floor_u.min():
            edge.append(table[row, top_u.max()])
    if len(edge) < 10:
        raise SystemExit(f"{depth_png}: {len(edge)} image rows cross the desk's edge; "
                         "expected at least 10 (a frame showing the floor beside the desk)")
    # The pixels next to the floor see the desk's front face, whose lower edge is the last thing
    # before the floor: they lie below the top (13.6 mm in frame 1 of video 0000). The rendered
    # desk is given that thickness, so that its front face ends where the real one's pixels do
    # and the two edges fall on the same pixels (with the default 3 cm the rendered edge fell up
    # to 60 px below the real one).
    edge = np.array(edge)
    thickness = max(0.005, -float(np.median(edge[:, 2])))
    edge = edge[:, :2]
    # Total least squares: the edge's direction is the principal axis of its points.
    centre = edge.mean(0)
    direction = np.linalg.svd(edge - centre)[2][0]
    inward = np.array([-direction[1], direction[0]])
    top_centroid = table[on_top][:, :2].mean(0)
    if (top_centroid - centre) @ inward < 0:
        inward = -inward
    residual = (edge - centre) @ inward
    width, depth_m = size
    x_axis = np.array([inward[1], -inward[0]])  # the top's +y is inward, its +x to the right
    middle = centre + 0.5 * depth_m * inward
    floor_z = float(np.median(table[on_floor][:, 2]))
    print(f"desk: its edge pixels {1000 * thickness:.1f} mm below the top (median): the front "
          "face's thickness")
    print(f"desk: front edge through ({centre[0]:.3f}, {centre[1]:.3f}) m along "
          f"({direction[0]:.3f}, {direction[1]:.3f}), {len(edge)} rows, rms "
          f"{1000 * np.sqrt((residual ** 2).mean()):.1f} mm; floor {-floor_z:.3f} m below the top")
    return {"table_x": float(middle[0]), "table_y": float(middle[1]),
            "table_yaw_deg": math.degrees(math.atan2(x_axis[1], x_axis[0])),
            "table_width": width, "table_depth": depth_m, "table_height": -floor_z,
            "table_thickness": thickness,
            "tape_thickness": 0.0, "play_area_width": 0.1, "play_area_depth": 0.1,
            "backdrop": False}


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
    parser.add_argument("--desk", metavar="DEPTH_PNG",
                        help="fit the desk's front edge and the floor from this real depth frame")
    parser.add_argument("--desk-size", nargs=2, type=float, default=[2.0, 1.2],
                        metavar=("WIDTH", "DEPTH"), help="the desk top's size [m]")
    parser.add_argument("--intrinsics", nargs=4, type=float, metavar=("FX", "FY", "CX", "CY"),
                        default=[1066.778, 1067.487, 312.9869, 241.3109],
                        help="the depth frame's pinhole intrinsics (YCB-Video's colour camera)")
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
    # The real camera's roll: its x axis against the look-at camera's (x horizontal, y down; the
    # renderer's CameraPlacement::TableTCamera), turned towards y.
    norm = math.hypot(forward[0], forward[1])
    right = [forward[1] / norm, -forward[0] / norm, 0.0]  # forward x up, normalised
    down = [forward[1] * right[2] - forward[2] * right[1], forward[2] * right[0] - forward[0] * right[2],
            forward[0] * right[1] - forward[1] * right[0]]  # forward x right
    x_axis = [r_tc[i][0] for i in range(3)]
    roll = math.degrees(math.atan2(sum(x_axis[i] * down[i] for i in range(3)),
                                   sum(x_axis[i] * right[i] for i in range(3))))

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
                   "look_at_x": look_at[0], "look_at_y": look_at[1], "look_at_z": look_at[2],
                   "roll_deg": roll},
        "scene": {"materials": {"proxy": {"ir_albedo": args.ir_albedo,
                                          "specularity": args.specularity}}},
    }
    if args.desk:
        config["scene"].update(fit_desk(args.desk, args.intrinsics, r_tc, t_tc, args.desk_size))
    if objects:
        config["scene"]["objects"] = objects
    name = "render.json" if args.paths else stem + ".json"
    with open(os.path.join(args.out, name), "w") as out:
        json.dump(config, out, indent=2)
        out.write("\n")
    print(f"camera at {t_tc[0]:.3f} {t_tc[1]:.3f} {t_tc[2]:.3f} m, {along:.3f} m from the table "
          f"along its axis, roll {roll:.2f} deg; {len(rows)} frames -> {args.out}/{name}")


if __name__ == "__main__":
    main()

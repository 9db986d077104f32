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
  --clutter DEPTH_PNG LABEL_PNG MESH ALBEDO SPECULARITY  meshes what stands on the desk in that real
                   frame besides its labelled objects (a keyboard, a mouse, a monitor's bezel) into
                   MESH (OBJ, table frame) and places it as the static scene object `clutter` with
                   that IR material: the pixels more than 12 mm above the desk (the table fit's
                   top) and off the labels grown by 6 px, their holes closed, parts of 400 pixels
                   or more, grown 4 px into the desk; the 7 x 7 median then the 9 x 9 mean of the
                   depth; a node every --clutter-step pixels; walls down to the desk but along the
                   image border and where the frame sees past them. Needs numpy.
The camera is placed at the real camera's position in the table frame, looking at the point where
the real optical axis meets the table, turned about its axis by the real camera's roll
(camera.roll_deg; before 2026-11-30 the roll was left out). Standard library only, but for --desk
and --clutter.
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


def read_png(path, bits=16):
    """A greyscale PNG of 8 or 16 bits as a numpy array of rows (PNG's five row filters undone)."""
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
    width, height, depth_bits, colour = header[:4]
    if depth_bits != bits or colour != 0 or header[6] != 0:
        raise SystemExit(f"{path}: {depth_bits}-bit colour type {colour} (interlace {header[6]}); "
                         f"expected a non-interlaced {bits}-bit greyscale image")
    raw = zlib.decompress(b"".join(idat))
    step = bits // 8  # bytes a pixel: the Sub, Average and Paeth filters look one pixel left
    stride = step * width
    rows = np.zeros((height, stride), np.int32)
    previous = np.zeros(stride, np.int32)
    for v in range(height):
        kind = raw[v * (stride + 1)]
        line = np.frombuffer(raw, np.uint8, stride, v * (stride + 1) + 1).astype(np.int32)
        if kind == 0:
            row = line
        elif kind == 2:
            row = (line + previous) & 255
        else:
            row = np.zeros(stride, np.int32)
            for u in range(stride):
                a = row[u - step] if u >= step else 0
                b = previous[u]
                c = previous[u - step] if u >= step else 0
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
    return (rows[:, 0::2] << 8) | rows[:, 1::2] if bits == 16 else rows


def read_depth_png(path):
    """A 16-bit greyscale depth PNG as a numpy array of rows."""
    return read_png(path, 16)


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


def box_mean(values, weights, radius):
    """Per pixel, the weighted mean of values over the (2 radius + 1)^2 window (0 where no weight)."""
    import numpy as np
    size = 2 * radius + 1

    def box(a):
        padded = np.pad(a, radius)
        s = np.cumsum(np.cumsum(np.pad(padded, ((1, 0), (1, 0))), 0), 1)
        return s[size:, size:] - s[:-size, size:] - s[size:, :-size] + s[:-size, :-size]
    total = box(weights)
    return np.where(total > 0, box(values * weights) / np.maximum(total, 1e-12), 0.0), total


def grow(mask, radius):
    """The mask grown by radius pixels (a square)."""
    import numpy as np
    return box_mean(mask.astype(float), np.ones(mask.shape), radius)[0] > 0


def fit_clutter(depth_png, label_png, intrinsics, r_tc, t_tc, mesh_path, step, min_height,
                min_pixels):
    """What stands on the desk besides the labelled objects (see --clutter), as a mesh in the table
    frame: its visible top from the real frame's depth, walled down to the desk."""
    import numpy as np
    depth = read_depth_png(depth_png) / 10000.0
    label = read_png(label_png, 8)
    if label.shape != depth.shape:
        raise SystemExit(f"{label_png}: {label.shape[1]}x{label.shape[0]} pixels; expected the "
                         f"depth frame's {depth.shape[1]}x{depth.shape[0]}")
    fx, fy, cx, cy = intrinsics
    height, width = depth.shape
    v, u = np.mgrid[0:height, 0:width]
    rays = np.stack([(u - cx) / fx, (v - cy) / fy, np.ones(depth.shape)], -1)
    r = np.array(r_tc)
    up = (rays * depth[..., None]) @ r.T + np.array(t_tc)
    valid = depth > 0
    # Above the desk by more than its unevenness (up to 7 mm beside the keyboard in frame 1 of
    # video 0000), below a monitor's height, off the labelled objects and their mixed edge pixels.
    objects = grow(label > 0, 6)
    seen = valid & (up[..., 2] > min_height) & (up[..., 2] < 0.5) & ~objects
    # The clutter's own missing pixels (dark keys, its edges) closed over: a pixel belongs if it is
    # missing and most of its 7 x 7 neighbourhood is clutter.
    share = box_mean(seen.astype(float), np.ones(depth.shape), 3)[0]
    region = seen | (~valid & ~objects & (share > 0.5))
    # Connected parts (4-neighbours); parts below min_pixels (a cable's few raised pixels) dropped.
    parent = np.arange(height * width)

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a
    flat = region.ravel()
    for a in np.flatnonzero(flat):
        for b in (a - 1 if a % width else -1, a - width):
            if b >= 0 and flat[b]:
                ra, rb = find(a), find(b)
                if ra != rb:
                    parent[max(ra, rb)] = min(ra, rb)
    roots = np.array([find(a) if flat[a] else -1 for a in range(height * width)])
    ids, counts = np.unique(roots[roots >= 0], return_counts=True)
    kept = set(ids[counts >= min_pixels].tolist())
    region = np.isin(roots, list(kept)).reshape(depth.shape)
    # The parts run down to the desk as the real surface does (a keyboard's front slopes): the
    # region grown by 4 pixels into the desk's pixels beside it, so that a wall stands only where
    # the real depth steps.
    region |= grow(region, 4) & valid & ~objects
    known = valid & region
    # Each node's depth: the median of the region's depths over a 7 x 7 window (a median keeps the
    # surface's steps), then their mean over 9 x 9 (the real frame's own noise and lattice terraces
    # are not the scene's: rendered again through the sensor model they would count its errors
    # twice; with the median alone the view's missing share near the gelatin box rose from 1.09 to
    # 1.15 of the real frames'); the mean over a wider window where the 7 x 7 holds no depth.
    windows = np.lib.stride_tricks.sliding_window_view(
        np.pad(np.where(known, depth, np.nan).astype(np.float32), 3, constant_values=np.nan),
        (7, 7))
    weight = np.isfinite(windows).sum((2, 3))
    smooth = np.zeros(depth.shape)
    smooth[weight > 0] = np.nanmedian(windows[weight > 0], (1, 2))
    smooth = np.where(weight > 0, box_mean(smooth, (weight > 0).astype(float), 4)[0], 0.0)
    for radius in (6, 12, 24):
        wider, wider_weight = box_mean(depth, known.astype(float), radius)
        smooth = np.where(weight > 0, smooth, wider)
        weight = np.where(weight > 0, weight, wider_weight)
    points = (rays * smooth[..., None]) @ r.T + np.array(t_tc)
    # The grid of every step-th pixel; a cell of four nodes in the region makes two triangles,
    # unless it spans a depth step (two parts seen one behind the other).
    node = region & (weight > 0)
    node[v % step != 0] = False
    node[u % step != 0] = False
    index = -np.ones(depth.shape, np.int64)
    index[node] = np.arange(node.sum())
    vertices = [points[node]]
    corner = index[:-step:step, :-step:step], index[:-step:step, step::step], \
        index[step::step, step::step], index[step::step, :-step:step]
    d = smooth[::step, ::step]
    ds = [d[:-1, :-1], d[:-1, 1:], d[1:, 1:], d[1:, :-1]]
    cell = np.all([c >= 0 for c in corner], 0) & \
        (np.max(ds, 0) - np.min(ds, 0) < 0.02)
    faces = []
    a, b, c, e = (x[cell] for x in corner)  # clockwise in the image: top left, top right, ...
    faces += list(zip(a, b, c)) + list(zip(a, c, e))
    # Walls: every cell side that borders no other cell, carried straight down to the desk; not
    # along the image's border, beyond which the clutter goes on unseen, and not where the real
    # frame sees past the wall (a monitor's bezel floats above the desk: the desk is seen below it).
    def seen_past(i, j):
        for a in (0.25, 0.5, 0.75):
            for b in (0.25, 0.75):
                top = (1 - a) * vertices[0][i] + a * vertices[0][j]
                point = np.array([top[0], top[1], b * top[2]])
                x, y, z = (point - np.array(t_tc)) @ r  # camera_p = table_R_camera^T (p - t)
                col, row = int(round(fx * x / z + cx)), int(round(fy * y / z + cy))
                if 0 <= row < height and 0 <= col < width and depth[row, col] > z + 0.01:
                    return True
        return False
    count = len(vertices[0])
    feet = {}

    def foot(i):
        nonlocal count
        if i not in feet:
            p = vertices[0][i]
            feet[i] = count
            extra.append([p[0], p[1], 0.0])
            count += 1
        return feet[i]
    extra = []
    rows, cols = cell.shape
    padded = np.pad(cell, 1, constant_values=True)
    for (dr, dc, first, second) in ((-1, 0, 0, 1), (0, 1, 1, 2), (1, 0, 2, 3), (0, -1, 3, 0)):
        border = cell & ~padded[1 + dr:1 + dr + rows, 1 + dc:1 + dc + cols]
        for i, j in zip(corner[first][border], corner[second][border]):
            if not seen_past(i, j):
                faces += [(i, j, foot(j)), (i, foot(j), foot(i))]
    vertices = np.concatenate([vertices[0], np.array(extra).reshape(-1, 3)])
    with open(mesh_path, "w") as out:
        out.write(f"# What stands on the desk in {os.path.basename(depth_png)} besides the objects "
                  f"of {os.path.basename(label_png)} (render_real_view.py --clutter: "
                  f"a node every {step} pixels, above {1000 * min_height:.0f} mm, parts of {min_pixels} pixels "
                  "or more, walled down to the desk), table frame, metres\n")
        for p in vertices:
            out.write("v %.5f %.5f %.5f\n" % tuple(p))
        for f in faces:
            out.write("f %d %d %d\n" % (f[0] + 1, f[1] + 1, f[2] + 1))
    print(f"clutter: {len(kept)} parts, {int(region.sum())} pixels ({int(seen.sum())} seen); "
          f"{len(vertices)} vertices, {len(faces)} triangles -> {mesh_path}")


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
    parser.add_argument("--clutter", nargs=5,
                        metavar=("DEPTH_PNG", "LABEL_PNG", "MESH", "ALBEDO", "SPECULARITY"),
                        help="mesh what stands on the desk in that real frame besides its labelled "
                             "objects into MESH (OBJ) and place it as a static scene object")
    parser.add_argument("--clutter-step", type=int, default=3,
                        help="the clutter mesh's grid spacing [pixels of the real frame]")
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
    if args.clutter:
        depth_png, label_png, mesh, albedo, specularity = args.clutter
        fit_clutter(depth_png, label_png, args.intrinsics, r_tc, t_tc, mesh, args.clutter_step,
                    min_height=0.012, min_pixels=400)
        objects.append({"name": "clutter", "mesh": os.path.relpath(mesh, args.out),
                        "x": 0.0, "y": 0.0, "z": 0.0, "qx": 0.0, "qy": 0.0, "qz": 0.0, "qw": 1.0,
                        "material": {"ir_albedo": float(albedo),
                                     "specularity": float(specularity)}})
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

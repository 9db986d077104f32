# Writes models/models_info.json (BOP format, translations in the models' unit, metres): the
# symmetries of the two cuboids fitted by fit_box_models.py (the box() numbers there), turns about
# the cuboid's own axes through its centre. Gelatin box (71.2 x 87.2 x 26.9 mm, three different
# extents): the three half turns. Foam brick (75.4 x 50.8 x 50.2 mm, a square prism to 0.6 mm,
# as YCB's 50 x 75 x 50 mm brick is): the square's symmetries about the long axis (quarter, half
# and three-quarter turns) and the half turns about the other two axes and the square's two
# diagonals. Depth alone cannot tell these poses apart (the brick's texture can, the tracker does
# not use it). Run from this folder with Python 3.
import json, math

def rotation(axis, angle):
    n = math.sqrt(sum(a * a for a in axis)); x, y, z = (a / n for a in axis)
    c, s = math.cos(angle), math.sin(angle); C = 1 - c
    return [[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
            [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
            [z * x * C - y * s, z * y * C + x * s, c + z * z * C]]

def symmetry(axis, angle, centre):
    r = rotation(axis, angle)
    t = [centre[i] - sum(r[i][j] * centre[j] for j in range(3)) for i in range(3)]
    m = []
    for i in range(3):
        m += [round(r[i][0], 9), round(r[i][1], 9), round(r[i][2], 9), round(t[i], 9)]
    return [0.0 if abs(v) < 1e-12 else v for v in m] + [0, 0, 0, 1]

def cuboid_frame(yaw_deg, x0, x1, y0, y1, z0, z1):
    a = math.radians(yaw_deg); c, s = math.cos(a), math.sin(a)
    xc, yc, zc = (x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2
    return [c, s, 0], [-s, c, 0], [0, 0, 1], [c * xc - s * yc, s * xc + c * yc, zc]

pi = math.pi
ex, ey, ez, c = cuboid_frame(13.4, -0.037488, 0.033736, -0.043788, 0.043377, -0.018596, 0.008330)
box = [symmetry(ex, pi, c), symmetry(ey, pi, c), symmetry(ez, pi, c)]
ex, ey, ez, c = cuboid_frame(89.1, -0.036940, 0.038496, -0.025746, 0.025068, -0.017212, 0.032983)
diagonals = [[ey[i] + ez[i] for i in range(3)], [ey[i] - ez[i] for i in range(3)]]
brick = [symmetry(ex, k * pi / 2, c) for k in (1, 2, 3)] + [symmetry(ey, pi, c), symmetry(ez, pi, c)]
brick += [symmetry(d, pi, c) for d in diagonals]
lines = ['{']
for key, syms in (('8', box), ('21', brick)):
    rows = ',\n    '.join(json.dumps(m) for m in syms)
    lines.append('  "%s": {"symmetries_discrete": [\n    %s]}%s' % (key, rows, ',' if key == '8' else ''))
lines.append('}')
open('models/models_info.json', 'w').write('\n'.join(lines) + '\n')

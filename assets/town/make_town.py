#!/usr/bin/env python3
"""Writes the town of scenes/town.toml: its meshes and where they stand.

The town lines the four-way junction of assets/roads/intersection.xodr (the map placed as
scenes/intersection.toml places it: the junction's centre at world (0, 0, -10), the south arm
running to +z, the north arm to -z, east to +x, west to -x; 3.5 m lanes, 2 m sidewalks).

  tree.obj, tree.mtl          a trunk and a crown of three noisy spheres (bark, foliage)
  house.obj, house.mtl        a 14 x 10 m block of three storeys, windows standing out 3 cm
  trees.csv                   a tree every 9 m on every sidewalk
  houses.csv                  blocks behind the sidewalks, 16 m apart, gaps for car parks
  cars.csv                    rows of parked cars (assets/car.obj) in those car parks

Placement rows are x,y,z,yaw_deg (metres, world frame; degrees about +y). With --grid
COLUMNS ROWS it writes instead, to standard output, a car park of COLUMNS x ROWS cars 6 m
apart north of the junction: COLUMNS x ROWS x 11 504 triangles (68 x 128 is 100 million).

Written by seethru, dedicated to the public domain (CC0 1.0): copy it, change it, ship it.
Run it with the machine's Python (no packages), from anywhere:
    python3 assets/town/make_town.py
"""

import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
LANE = 3.5
WALK = 2.0
CENTRE_Z = -10.0  # the junction's centre, world z
J = 10.0  # the junction's half size
# arm: direction out of the junction (world x, z), length from its edge
ARMS = [((0.0, 1.0), 150.0), ((0.0, -1.0), 100.0), ((1.0, 0.0), 100.0), ((-1.0, 0.0), 100.0)]


def noise(*v):
    """A deterministic number in [-1, 1] from numbers (no random module: the same bytes on
    every Python)."""
    s = math.sin(sum(x * k for x, k in zip(v, (12.9898, 78.233, 37.719, 4.581)))) * 43758.5453
    return 2.0 * (s - math.floor(s)) - 1.0


class Mesh:
    def __init__(self):
        self.v, self.faces = [], []  # faces: (material, (i, j, k))

    def vertex(self, p):
        self.v.append(p)
        return len(self.v)

    def tri(self, material, a, b, c):
        self.faces.append((material, (a, b, c)))

    def quad(self, material, a, b, c, d):
        self.tri(material, a, b, c)
        self.tri(material, a, c, d)

    def box(self, material, lo, hi):
        """An axis-aligned box, faces outwards (counter-clockwise seen from outside)."""
        x0, y0, z0 = lo
        x1, y1, z1 = hi
        c = [self.vertex((x, y, z)) for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)]
        # corner index: x + 2y + 4z
        for q in [(0, 4, 6, 2), (1, 3, 7, 5), (0, 1, 5, 4), (2, 6, 7, 3), (0, 2, 3, 1), (4, 5, 7, 6)]:
            self.quad(material, *[c[i] for i in q])

    def write(self, name, mtl, colours):
        with open(os.path.join(HERE, name + ".mtl"), "w") as f:
            f.write(f"# {name}.mtl, written by make_town.py (CC0)\n")
            for m, rgb in colours.items():
                f.write(f"newmtl {m}\nKd {rgb[0]:.3f} {rgb[1]:.3f} {rgb[2]:.3f}\n")
        with open(os.path.join(HERE, name + ".obj"), "w") as f:
            f.write(f"# {name}.obj, written by make_town.py (CC0): {len(self.faces)} triangles\n")
            f.write(f"mtllib {name}.mtl\n")
            for p in self.v:
                f.write("v {:.4f} {:.4f} {:.4f}\n".format(*p))
            current = None
            for m, (a, b, c) in self.faces:
                if m != current:
                    f.write(f"usemtl {m}\n")
                    current = m
                f.write(f"f {a} {b} {c}\n")


def icosphere(levels):
    t = (1.0 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t),
         (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    v = [tuple(c / math.sqrt(sum(x * x for x in p)) for c in p) for p in v]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(levels):
        cache, out = {}, []

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                p = [(x + y) / 2 for x, y in zip(v[a], v[b])]
                n = math.sqrt(sum(x * x for x in p))
                v.append(tuple(x / n for x in p))
                cache[key] = len(v) - 1
            return cache[key]

        for a, b, c in f:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            out += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        f = out
    return v, f


def tree():
    m = Mesh()
    seg, r, h = 12, 0.16, 2.6
    ring = lambda y, rr: [m.vertex((rr * math.cos(2 * math.pi * i / seg), y, -rr * math.sin(2 * math.pi * i / seg))) for i in range(seg)]
    lo, hi = ring(0.0, r), ring(h, r * 0.7)
    for i in range(seg):
        j = (i + 1) % seg
        m.quad("bark", lo[i], lo[j], hi[j], hi[i])
    v, f = icosphere(3)
    for k, (cx, cy, cz, rad) in enumerate([(0.0, 3.6, 0.0, 1.7), (0.5, 4.6, 0.3, 1.3), (-0.4, 5.3, -0.2, 1.0)]):
        base = len(m.v)
        for p in v:
            s = rad * (1.0 + 0.12 * noise(p[0] * 3, p[1] * 3, p[2] * 3, k))
            m.vertex((cx + s * p[0], cy + 1.15 * s * p[1], cz + s * p[2]))
        for a, b, c in f:
            m.tri("foliage", base + a + 1, base + b + 1, base + c + 1)
    m.write("tree", "tree", {"bark": (0.36, 0.25, 0.16), "foliage": (0.2, 0.45, 0.16)})
    return len(m.faces)


def house():
    """14 m along x, 10 m deep (z), three 3 m storeys; its front faces +z."""
    m = Mesh()
    w, d, storey, floors = 14.0, 10.0, 3.0, 3
    m.box("wall", (-w / 2, 0.0, -d / 2), (w / 2, storey * floors, d / 2))
    m.box("roof", (-w / 2 - 0.3, storey * floors, -d / 2 - 0.3), (w / 2 + 0.3, storey * floors + 0.4, d / 2 + 0.3))
    for floor in range(floors):
        y0 = floor * storey + 0.9
        for i in range(6):  # front and back: 6 windows
            x = -w / 2 + (i + 0.5) * w / 6
            m.box("glass", (x - 0.6, y0, d / 2), (x + 0.6, y0 + 1.4, d / 2 + 0.03))
            m.box("glass", (x - 0.6, y0, -d / 2 - 0.03), (x + 0.6, y0 + 1.4, -d / 2))
        for i in range(4):  # the sides: 4 windows
            z = -d / 2 + (i + 0.5) * d / 4
            m.box("glass", (w / 2, y0, z - 0.6), (w / 2 + 0.03, y0 + 1.4, z + 0.6))
            m.box("glass", (-w / 2 - 0.03, y0, z - 0.6), (-w / 2, y0 + 1.4, z + 0.6))
    m.box("door", (-0.8, 0.0, d / 2), (0.8, 2.2, d / 2 + 0.05))
    m.write("house", "house", {"wall": (0.78, 0.72, 0.62), "roof": (0.45, 0.2, 0.16), "glass": (0.18, 0.24, 0.3), "door": (0.35, 0.22, 0.12)})
    return len(m.faces)


def world(along, side, arm):
    """World (x, z) at `along` metres out from the junction's edge on arm `arm`, `side`
    metres to the arm's right (+) or left (-), and the yaw (degrees) that faces the road."""
    (dx, dz), _ = ARMS[arm]
    nx, nz = -dz, dx  # to the left of the outward direction
    s = J + along
    x = dx * s - nx * side
    z = CENTRE_Z + dz * s - nz * side
    # Face the road: the house's +z towards the centre line.
    fx, fz = (nx, nz) if side > 0 else (-nx, -nz)
    yaw = math.degrees(math.atan2(fx, fz))
    return x, z, yaw


def rows(path, rows):
    with open(os.path.join(HERE, path), "w") as f:
        f.write("x,y,z,yaw_deg\n")
        for x, y, z, yaw in rows:
            f.write(f"{x:.3f},{y:.3f},{z:.3f},{yaw:.2f}\n")
    return len(rows)


def town():
    trees, houses, cars = [], [], []
    edge = LANE + WALK
    for arm, (_, length) in enumerate(ARMS):
        for side in (-1.0, 1.0):
            a = 6.0
            while a < length - 2:
                x, z, yaw = world(a, side * (LANE + 1.2), arm)
                trees.append((x, 0.12, z, 37.0 * len(trees) % 360))
                a += 9.0
            block = 0
            a = 2.0
            while a + 14 < length:
                if block % 4 == 3:
                    # A car park: two rows of four cars, nose to the road and away from it.
                    for row, off in enumerate((edge + 4.0, edge + 10.0)):
                        for k in range(4):
                            x, z, yaw = world(a + 1.5 + k * 3.0, side * off, arm)
                            cars.append((x, 0.0, z, yaw + (90.0 if row == 0 else -90.0)))
                else:
                    x, z, yaw = world(a + 7.0, side * (edge + 2.0 + 5.0), arm)
                    houses.append((x, 0.0, z, yaw))
                block += 1
                a += 16.0
    return rows("trees.csv", trees), rows("houses.csv", houses), rows("cars.csv", cars)


def grid(columns, rows_):
    print("x,y,z,yaw_deg")
    for r in range(rows_):
        for c in range(columns):
            print(f"{-3.0 * columns + 6.0 * c:.1f},0,{-40.0 - 6.0 * r:.1f},{(r * columns + c) % 360}")


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "--grid":
        grid(int(sys.argv[2]), int(sys.argv[3]))
    else:
        t, h = tree(), house()
        n = town()
        print(f"tree {t} triangles, house {h}; {n[0]} trees, {n[1]} houses, {n[2]} cars", file=sys.stderr)

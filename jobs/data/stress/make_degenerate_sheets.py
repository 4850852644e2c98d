#!/usr/bin/env python3
"""Writes the stress suite's badly shaped input meshes (docs/stress.md), 0.2 m squares in z = 0:

needle_sheet.obj     a structured 10 x 10 grid with two extra vertex columns just right of x = 0,
                     at 2e-6 m and 2e-5 m from it: the cells between are needles (one short edge
                     against two 2 cm ones) of shape quality (height over longest edge) 1e-4
                     and 1e-3.
cap_sheet.obj        a structured 10 x 10 grid with a row of caps: above the row y = 0 a vertex is
                     inserted in every cell, 2e-6 m (cells 0..4) or 2e-5 m (cells 5..9) above the
                     middle of its bottom edge, so that triangle is a cap (an angle near 180
                     degrees) of quality 1e-4 or 1e-3.
sliver_sheet.obj     the needle sheet with its needle column 2e-8 m wide: quality 1e-6, below the
                     floor of shell triangles (engine/mesh/triangle_shape.hpp), refused.

Rerun from this directory to regenerate: python3 make_degenerate_sheets.py
"""

SIZE = 0.2
CELLS = 10


def grid_lines():
    return [-SIZE / 2 + SIZE * i / CELLS for i in range(CELLS + 1)]


def write(name, vertices, triangles, comment):
    with open(name, "w") as out:
        out.write(f"# {comment}\n# written by make_degenerate_sheets.py\n")
        for x, y in vertices:
            out.write(f"v {x:.17g} {y:.17g} 0\n")
        for a, b, c in triangles:
            out.write(f"f {a + 1} {b + 1} {c + 1}\n")


def needle_sheet(name, widths, comment):
    xs = sorted(grid_lines() + widths)
    ys = grid_lines()
    vertices = [(x, y) for y in ys for x in xs]
    columns = len(xs)
    triangles = []
    for j in range(len(ys) - 1):
        for i in range(columns - 1):
            a, b = j * columns + i, j * columns + i + 1
            c, d = a + columns, b + columns
            triangles += [(a, b, d), (a, d, c)]
    write(name, vertices, triangles, comment)


def cap_sheet(name, heights, comment):
    xs = ys = grid_lines()
    vertices = [(x, y) for y in ys for x in xs]
    row = CELLS // 2  # the caps sit on the row of vertices y = 0
    columns = len(xs)
    middles = {}
    for i, height in enumerate(heights):
        middles[i] = len(vertices)
        vertices.append(((xs[i] + xs[i + 1]) / 2, ys[row] + height))
    triangles = []
    for j in range(len(ys) - 1):
        for i in range(columns - 1):
            a, b = j * columns + i, j * columns + i + 1
            c, d = a + columns, b + columns
            if j == row:
                m = middles[i]
                triangles += [(a, b, m), (a, m, c), (m, b, d), (m, d, c)]
            else:
                triangles += [(a, b, d), (a, d, c)]
    write(name, vertices, triangles, comment)


needle_sheet("needle_sheet.obj", [2e-6, 2e-5],
             "0.2 m sheet with needle cells of quality 1e-4 and 1e-3 (docs/stress.md)")
cap_sheet("cap_sheet.obj", [2e-6] * 5 + [2e-5] * 5,
          "0.2 m sheet with a row of caps of quality 1e-4 and 1e-3 (docs/stress.md)")
needle_sheet("sliver_sheet.obj", [2e-8],
             "0.2 m sheet with a column of needle cells of quality 1e-6 (docs/stress.md)")

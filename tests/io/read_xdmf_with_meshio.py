"""Reads a job's XDMF sidecars with meshio, a reader independent of PSQ, for the C++ tests.

Usage: read_xdmf_with_meshio.py JOB_XDMF PART_XDMF...

Prints one JSON object on stdout:
  "parts": one entry per PART_XDMF, in order, as meshio's TimeSeriesReader reads it:
      {"steps": number of time steps,
       "frames": [{"time", "points" (n×3), "triangles" (m×3), "point_data": {name: n×3}}]}
  "blocks": the blocks of JOB_XDMF (the file ParaView opens), per time step:
      [{"name", "time", "grids": [grid names]}]
  "mismatches": every block of JOB_XDMF whose mesh and node arrays are not the very XML of the
      same step in the part's own file (so that what meshio checked is what ParaView shows).

Exits non-zero with a message on stderr if meshio or h5py cannot be imported or a file cannot
be read.
"""

import json
import sys
import xml.etree.ElementTree as ET

import meshio


def read_part_series(path):
    with meshio.xdmf.TimeSeriesReader(path) as reader:
        frames = []
        for k in range(reader.num_steps):
            # TimeSeriesReader reads one mesh for the whole series (that of the first step), but
            # the levels of a progressive job have different meshes: it is pointed at each
            # step's own grid before reading the mesh.
            reader.mesh_grid = reader.collection[k]
            points, cells = reader.read_points_cells()
            time, point_data, _ = reader.read_data(k)
            triangles = [block.data.tolist() for block in cells if block.type == "triangle"]
            frames.append(
                {
                    "time": time,
                    "points": points.tolist(),
                    "triangles": triangles[0] if len(triangles) == 1 else None,
                    "cell_types": [block.type for block in cells],
                    "point_data": {name: data.tolist() for name, data in point_data.items()},
                }
            )
        return {"steps": reader.num_steps, "frames": frames}


def mesh_xml(grid):
    """The grid's topology, geometry and node attributes as canonical XML text."""
    kept = [
        child
        for child in grid
        if child.tag in ("Topology", "Geometry")
        or (child.tag == "Attribute" and child.get("Center") == "Node")
    ]
    return [ET.canonicalize(ET.tostring(child), strip_text=True) for child in kept]


def temporal_steps(path):
    collection = ET.parse(path).getroot().find("Domain/Grid[@CollectionType='Temporal']")
    if collection is None:
        raise SystemExit(f"{path}: no temporal collection")
    return list(collection)


def read_blocks(job_path, part_paths):
    part_steps = [temporal_steps(path) for path in part_paths]
    blocks, mismatches = [], []
    for k, step in enumerate(temporal_steps(job_path)):
        grids = step.findall("Grid")
        blocks.append(
            {
                "name": step.get("Name"),
                "time": float(step.find("Time").get("Value")),
                "grids": [grid.get("Name") for grid in grids],
            }
        )
        for p, grid in enumerate(grids):
            if p >= len(part_steps) or k >= len(part_steps[p]):
                mismatches.append(f"step {k} block {grid.get('Name')}: no such part step")
            elif mesh_xml(grid) != mesh_xml(part_steps[p][k]):
                mismatches.append(f"step {k} block {grid.get('Name')}: differs from {part_paths[p]}")
    return blocks, mismatches


def main():
    if len(sys.argv) < 2:
        raise SystemExit(__doc__)
    job_path, part_paths = sys.argv[1], sys.argv[2:]
    blocks, mismatches = read_blocks(job_path, part_paths)
    result = {
        "parts": [read_part_series(path) for path in part_paths],
        "blocks": blocks,
        "mismatches": mismatches,
    }
    json.dump(result, sys.stdout)


if __name__ == "__main__":
    main()

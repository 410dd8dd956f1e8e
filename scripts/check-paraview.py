#!/usr/bin/env pvpython
"""Opens rcfd's HDF5 outputs in ParaView through their XDMF sidecars and checks what ParaView shows
against the HDF5 file read independently with h5py.

    pvpython scripts/check-paraview.py --grid DIR/database.h5 DIR/database.xmf OUT/result.xmf ...
    (or python3, when paraview.simple and h5py are importable)

For every sidecar, with ParaView's Xdmf3 reader ("Xdmf3ReaderS"):
  - every cell field of the .h5 beside it (a dataset of shape [nz][ny][nx] or [nz][ny][nx][3] of the
    grid, a frame of such a dataset in a database's /frames, a layer map named by --layer-map) is an
    array of that name in ParaView, once; a dataset linked under several names counts once;
  - every array ParaView shows holds the dataset's values at the right place: each cell's centre, as
    ParaView places it, falls in the cell (i, j, k) of the --grid database whose value the dataset
    holds at [k][j][i] (so an array in the wrong order or a mesh shifted or swapped in its axes fails);
  - a database's time steps are n * dt_rec for its complete frames n, and each step shows frame n.
--expect NAME requires that array in some sidecar (the test names the fields its jobs must produce).

Exit 0: all checks pass; 1: a check failed (each failure printed); 77: ParaView's Python modules or
h5py cannot be imported (the test reports a skip).
"""

import argparse
import os
import sys

try:
    import h5py
    import numpy as np
    from paraview import simple
    from paraview import servermanager
    from vtkmodules.numpy_interface import dataset_adapter as dsa
    from vtkmodules.vtkFiltersCore import vtkCellCenters
except ImportError as missing:  # not an error of rcfd: the test reports a skip
    print(f"check-paraview: cannot import {missing.name}: install paraview, python3-paraview and "
          "python3-h5py (scripts/install-deps.sh) and run with pvpython", file=sys.stderr)
    sys.exit(77)


class Grid:
    """The Cartesian grid of a field database (docs/formats.md): origin, spacing, shape (x, y, z)."""

    def __init__(self, database):
        with h5py.File(database, "r") as f:
            g = f["grid"]
            self.origin = np.asarray(g.attrs["origin"], dtype=float)
            self.spacing = np.asarray(g.attrs["spacing"], dtype=float)
            self.shape = tuple(int(v) for v in g.attrs["shape"])  # nx, ny, nz
        self.cells = (self.shape[2], self.shape[1], self.shape[0])  # the datasets' [nz][ny][nx]

    def cell_of(self, centres):
        """(i, j, k) of the cells holding each point, -1 outside."""
        ijk = np.floor((centres - self.origin) / self.spacing).astype(int)
        outside = np.any((ijk < 0) | (ijk >= np.array(self.shape)), axis=1)
        ijk[outside] = -1
        return ijk


def cell_type(shape, cells):
    """'scalar' or 'vector' for a dataset of the grid's cell shape, else None."""
    if tuple(shape) == cells:
        return "scalar"
    if len(shape) == 4 and tuple(shape[:3]) == cells and shape[3] == 3:
        return "vector"
    return None


def all_links(f):
    """Every link name of every numeric dataset (visititems follows each object only once)."""
    out = []

    def walk(group, prefix):
        for key in group:
            link = group.get(key, getlink=True)
            if not isinstance(link, h5py.HardLink):
                continue
            obj = group[key]
            path = prefix + key
            if isinstance(obj, h5py.Group):
                walk(obj, path + "/")
            elif obj.dtype.kind in "fiu":
                out.append((path, obj))

    walk(f, "")
    return out


def expected_arrays(h5path, grid, layer_maps):
    """What ParaView must show: {array name: (kind, values or a function of the frame)} and the times."""
    expected, times = {}, None
    with h5py.File(h5path, "r") as f:
        is_database = f.attrs.get("format", b"") in ("rcfd-field-database", b"rcfd-field-database")
        frames = None
        if is_database:
            firsts = [f["frames"][n].shape[0] for n in ("alpha_p", "u_p", "u_g")]
            frames = min(firsts)
            if "frame_count" in f["frames"].attrs:
                frames = min(frames, int(f["frames"].attrs["frame_count"]))
            times = [n * float(f.attrs["dt_rec"]) for n in range(frames)]
        # One name per object: the shortest of its links.
        objects = {}
        for path, ds in all_links(f):
            objects.setdefault(ds.id, []).append(path)
        for paths in objects.values():
            path = min(paths, key=lambda p: (p.count("/"), p))
            ds = f[path]
            if is_database and path.startswith("frames/") and path.count("/") == 1:
                kind = cell_type(ds.shape[1:], grid.cells)
                if kind and ds.shape[0] >= frames:
                    expected[path[len("frames/"):]] = (kind, ds[:frames].astype(float))
            elif kind := cell_type(ds.shape, grid.cells):
                expected[path] = (kind, ds[()].astype(float))
            elif "/" + path in layer_maps:
                expected[path] = ("layer", ds[()].astype(float))
    return expected, times


def blocks_of(data):
    if data.IsA("vtkCompositeDataSet"):
        it = data.NewIterator()
        it.InitTraversal()
        while not it.IsDoneWithTraversal():
            yield it.GetCurrentDataObject()
            it.GoToNextItem()
    else:
        yield data


def check_block(block, grid, expected, frame, label, failures, seen):
    centres_filter = vtkCellCenters()
    centres_filter.SetInputData(block)
    centres_filter.Update()
    centres = np.asarray(dsa.WrapDataObject(centres_filter.GetOutput()).Points)
    ijk = grid.cell_of(centres)
    if np.any(ijk[:, 0] < 0):
        failures.append(f"{label}: {int(np.sum(ijk[:, 0] < 0))} cells lie outside the database's grid")
        return
    cells = dsa.WrapDataObject(block).CellData
    for name in cells.keys():
        seen.add(name)
        if name not in expected:
            failures.append(f"{label}: array {name!r} is no cell field of the file")
            continue
        kind, values = expected[name]
        shown = np.asarray(cells[name], dtype=float)
        if kind == "layer":
            layers = set(ijk[:, 2])
            if len(layers) != 1:
                failures.append(f"{label}: layer map {name!r} spans {len(layers)} cell layers, not one")
                continue
            stored = values[ijk[:, 1], ijk[:, 0]]
        else:
            if frame is not None and values.ndim == (5 if kind == "vector" else 4):
                values = values[frame]
            stored = values[ijk[:, 2], ijk[:, 1], ijk[:, 0]]
        if shown.shape != stored.shape:
            failures.append(f"{label}: {name!r} has shape {shown.shape} in ParaView, {stored.shape} in the file")
            continue
        if not np.array_equal(shown, stored, equal_nan=True):
            wrong = int(np.sum(~np.isclose(shown, stored, rtol=0, atol=0, equal_nan=True)))
            failures.append(f"{label}: {name!r} differs from the file in {wrong} values at the cells ParaView "
                            "places them in")
            continue
        print(f"  {label}: {name} [{np.nanmin(shown):.6g}, {np.nanmax(shown):.6g}] on {len(shown)} cells: as stored")


def check_sidecar(xmf, grid, layer_maps, failures):
    h5path = os.path.splitext(xmf)[0] + ".h5"
    expected, times = expected_arrays(h5path, grid, layer_maps)
    print(f"{xmf}: expecting {sorted(expected)}" + (f", {len(times)} time steps" if times is not None else ""))
    # An absolute path: Xdmf3 resolves the .h5 against the sidecar's directory and fails on a bare name.
    reader = simple.Xdmf3ReaderS(FileName=[os.path.abspath(xmf)])
    reader.UpdatePipelineInformation()
    shown_times = list(reader.TimestepValues or [])
    if times is not None:
        if len(shown_times) != len(times) or not np.allclose(shown_times, times, rtol=1e-12, atol=0):
            failures.append(f"{xmf}: time steps {shown_times}, expected {times}")
            return set()
    elif shown_times:
        failures.append(f"{xmf}: time steps {shown_times} in a file without frames")
    seen = set()
    for frame, t in (enumerate(times) if times is not None else [(None, None)]):
        if t is None:
            reader.UpdatePipeline()
        else:
            reader.UpdatePipeline(t)
        data = servermanager.Fetch(reader)
        label = os.path.basename(xmf) + ("" if t is None else f" t = {t:g} s")
        for block in blocks_of(data):
            check_block(block, grid, expected, frame, label, failures, seen)
    for name in sorted(set(expected) - seen):
        failures.append(f"{xmf}: cell field {name!r} of {os.path.basename(h5path)} is not shown")
    simple.Delete(reader)
    return seen


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("sidecars", nargs="+", help="NAME.xmf files (NAME.h5 beside each)")
    parser.add_argument("--grid", required=True, help="the field database whose /grid the files are on")
    parser.add_argument("--layer-map", action="append", default=[], help="dataset of a [ny][nx] layer map")
    parser.add_argument("--expect", action="append", default=[], help="an array some sidecar must show")
    args = parser.parse_args()
    grid = Grid(args.grid)
    failures, shown = [], set()
    for xmf in args.sidecars:
        if not os.path.exists(xmf):
            failures.append(f"{xmf} does not exist")
            continue
        shown |= check_sidecar(xmf, grid, set(args.layer_map), failures)
    for name in args.expect:
        if name not in shown:
            failures.append(f"array {name!r} is in none of the sidecars")
    for f in failures:
        print("FAIL " + f, file=sys.stderr)
    print(f"check-paraview: {len(args.sidecars)} sidecar(s), {len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Copies Debian's MPPICFoam `column` tutorial (package openfoam-examples) into DIR, turned into rcfd's
coordinates (x lateral, y up, z depth: the column axis becomes +y, the column x in [-w/2, w/2],
y in [0, H], z in [0, w]) and written every --write-interval seconds up to --end-time, in ASCII or
binary, compressed or not. The rotation (x, y, z) -> (x, z, w/2 - y) keeps the mesh right-handed, so
blockMesh's cell counts along the block's own axes stay as they are."""
import argparse, gzip, pathlib, re, shutil

TUTORIAL = pathlib.Path("/usr/share/doc/openfoam-examples/examples/lagrangian/MPPICFoam/column")
HALF_WIDTH = 0.0092  # m, the tutorial column's half-width
TRIPLE = re.compile(r"\(\s*(-?[\d.eE+-]+)\s+(-?[\d.eE+-]+)\s+(-?[\d.eE+-]+)\s*\)")


def rotate(x, y, z, half_width):
    return x, z, half_width - y


def main():
    a = argparse.ArgumentParser()
    a.add_argument("dir")
    a.add_argument("--end-time", default="0.1")
    a.add_argument("--write-interval", default="0.01")
    a.add_argument("--format", choices=["ascii", "binary"], default="ascii")
    a.add_argument("--compress", action="store_true")
    o = a.parse_args()
    out = pathlib.Path(o.dir)
    if out.exists():
        shutil.rmtree(out)
    shutil.copytree(TUTORIAL, out)

    block = out / "system/blockMeshDict"  # vertices in mm (scale 0.001)
    text = block.read_text()
    start = text.index("vertices")
    end = text.index(");", start)
    turned = TRIPLE.sub(lambda m: "(%.9g %.9g %.9g)" % rotate(*(float(v) for v in m.groups()), HALF_WIDTH * 1000),
                        text[start:end])
    block.write_text(text[:start] + turned + text[end:])

    g = out / "constant/g"
    g.write_text(g.read_text().replace("(0 0 -9.81)", "(0 -9.81 0)"))

    positions = out / "constant/kinematicCloudPositions.gz"  # injection positions [m]
    lines = gzip.open(positions, "rt").read().splitlines()
    lines = [TRIPLE.sub(lambda m: "(%.9g %.9g %.9g)" % rotate(*(float(v) for v in m.groups()), HALF_WIDTH), l)
             if TRIPLE.fullmatch(l.strip()) else l for l in lines]
    with gzip.open(positions, "wt") as f:
        f.write("\n".join(lines) + "\n")

    control = out / "system/controlDict"
    c = control.read_text()
    for key, value in (("endTime", o.end_time), ("writeInterval", o.write_interval), ("writeFormat", o.format),
                       ("writeCompression", "on" if o.compress else "off")):
        c = re.sub(r"^%s .*$" % key, "%s %s;" % (key, value), c, flags=re.M)
    control.write_text(c)


if __name__ == "__main__":
    main()

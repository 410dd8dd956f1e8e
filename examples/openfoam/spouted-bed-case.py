#!/usr/bin/env python3
"""Writes a small pseudo-2D MPPICFoam spouted bed into DIR, in rcfd's coordinates (x across the width,
x = 0 on the jet's axis; y up, y = 0 at the bottom; z along the depth, one cell deep), for Debian's
OpenFOAM (v1912, package openfoam): examples/openfoam/spouted-bed-scene.json is the matching rcfd scene.

The case: a flat-bottomed box --width wide, --height high and one cell (--cell) deep, meshed with cubic
cells of --cell. A gas jet enters through the patch `inlet`, the --inlet-cells central cells of the
bottom (a fixedValue velocity --jet-velocity upwards); the rest of the bottom and the two side faces are
walls, the top is the outlet (fixed pressure), the front and back faces are symmetry planes. Particles of
--diameter and --density (one particle per parcel by default) start as a packed layer: positions drawn
uniformly (seeded) over the bottom --bed-height at solid fraction --packing, injected at t = 0 from
constant/kinematicCloudPositions as Debian's MPPICFoam tutorials do. The Lagrangian cloud writes its
parcels' identities (origId, origProcId) and legacy positions, which the import turns into the
spray-zone reference (docs/import.md). Written every --write-interval s up to --end-time (ASCII or
binary). Only the Python standard library is used."""
import argparse, math, pathlib, random, shutil

HEADER = """FoamFile
{
    version     2.0;
    format      %s;
    class       %s;
    location    "%s";
    object      %s;
}
"""


def write(case, rel, cls, body, fmt="ascii"):
    path = case / rel
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(HEADER % (fmt, cls, str(pathlib.Path(rel).parent), pathlib.Path(rel).name) + "\n" + body)


def cells_across(length, cell, what):
    n = round(length / cell)
    if n < 1 or abs(n * cell - length) > 1e-9 * max(1.0, length / cell):
        raise SystemExit("%s %.6g m is not a whole number of cells of %.6g m" % (what, length, cell))
    return n


def main():
    a = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    a.add_argument("dir")
    a.add_argument("--width", type=float, default=0.1, help="bed width (x) [m], default 0.1")
    a.add_argument("--height", type=float, default=0.3, help="bed height (y) [m], default 0.3")
    a.add_argument("--cell", type=float, default=0.005, help="cubic cell edge and bed depth [m], default 0.005")
    a.add_argument("--inlet-cells", type=int, default=2, help="cells across the jet inlet, default 2 (10 mm)")
    a.add_argument("--jet-velocity", type=float, default=30.0, help="gas velocity through the inlet [m/s], default 30")
    a.add_argument("--diameter", type=float, default=0.0018, help="particle diameter [m]")
    a.add_argument("--density", type=float, default=1040.0, help="particle density [kg/m3]")
    a.add_argument("--bed-height", type=float, default=0.06, help="height of the initial packed layer [m]")
    a.add_argument("--packing", type=float, default=0.55, help="solid fraction of the initial layer")
    a.add_argument("--n-particle", type=int, default=1, help="particles per parcel")
    a.add_argument("--seed", type=int, default=1, help="seed of the initial positions")
    a.add_argument("--delta-t", default="1e-4", help="OpenFOAM time step [s]")
    a.add_argument("--end-time", default="1.4")
    a.add_argument("--write-interval", default="0.005")
    a.add_argument("--format", choices=["ascii", "binary"], default="binary")
    o = a.parse_args()

    nx = cells_across(o.width, o.cell, "--width")
    ny = cells_across(o.height, o.cell, "--height")
    ni = o.inlet_cells
    if ni < 1 or ni >= nx or (nx - ni) % 2:
        raise SystemExit("--inlet-cells must leave the same whole number of cells on both sides")
    nside = (nx - ni) // 2
    depth = o.cell
    out = pathlib.Path(o.dir)
    if out.exists():
        shutil.rmtree(out)

    # --- mesh: three blocks across x (wall bottom | inlet | wall bottom), one cell deep ---------------
    xs = [-o.width / 2, -ni * o.cell / 2, ni * o.cell / 2, o.width / 2]
    verts = []
    for z in (0.0, depth):
        for y in (0.0, o.height):
            for x in xs:
                verts.append((x, y, z))

    def v(i, top, back):  # vertex index of x-line i (0..3), y bottom/top, z front/back
        return back * 8 + top * 4 + i

    blocks, inlet_faces, bottom_faces = [], [], []
    for i, n in enumerate((nside, ni, nside)):
        # hex ordering: x along v0->v1, y along v1->v2, z along v0->v4 (right-handed: x, y, z)
        hexv = (v(i, 0, 0), v(i + 1, 0, 0), v(i + 1, 1, 0), v(i, 1, 0),
                v(i, 0, 1), v(i + 1, 0, 1), v(i + 1, 1, 1), v(i, 1, 1))
        blocks.append("    hex (%s) (%d %d 1) simpleGrading (1 1 1)" % (" ".join(map(str, hexv)), n, ny))
        face = "(%d %d %d %d)" % (hexv[0], hexv[1], hexv[5], hexv[4])
        (inlet_faces if i == 1 else bottom_faces).append(face)
    tops = ["(%d %d %d %d)" % (v(i, 1, 0), v(i, 1, 1), v(i + 1, 1, 1), v(i + 1, 1, 0)) for i in range(3)]
    walls = ["(%d %d %d %d)" % (v(0, 0, 0), v(0, 0, 1), v(0, 1, 1), v(0, 1, 0)),
             "(%d %d %d %d)" % (v(3, 0, 0), v(3, 1, 0), v(3, 1, 1), v(3, 0, 1))]
    front = ["(%d %d %d %d)" % (v(i, 0, 0), v(i, 1, 0), v(i + 1, 1, 0), v(i + 1, 0, 0)) for i in range(3)]
    back = ["(%d %d %d %d)" % (v(i, 0, 1), v(i + 1, 0, 1), v(i + 1, 1, 1), v(i, 1, 1)) for i in range(3)]

    def patch(name, kind, faces):
        return "    %s\n    {\n        type %s;\n        faces\n        (\n%s\n        );\n    }\n" % (
            name, kind, "\n".join("            " + f for f in faces))

    write(out, "system/blockMeshDict", "dictionary",
          "scale 1;\n\nvertices\n(\n%s\n);\n\nblocks\n(\n%s\n);\n\nedges\n(\n);\n\nboundary\n(\n%s);\n\n"
          "mergePatchPairs\n(\n);\n"
          % ("\n".join("    (%.9g %.9g %.9g)" % p for p in verts), "\n".join(blocks),
             patch("inlet", "patch", inlet_faces) + patch("bottom", "wall", bottom_faces)
             + patch("walls", "wall", walls) + patch("outlet", "patch", tops)
             + patch("frontAndBack", "symmetry", front + back)))

    # --- fields -------------------------------------------------------------------------------------
    write(out, "0/U.air", "volVectorField", """dimensions      [0 1 -1 0 0 0 0];

internalField   uniform (0 0 0);

boundaryField
{
    inlet
    {
        type            fixedValue;
        value           uniform (0 %.9g 0);
    }
    "(bottom|walls)"
    {
        type            noSlip;
    }
    outlet
    {
        type            pressureInletOutletVelocity;
        phi             phi.air;
        inletValue      uniform (0 0 0);
        value           uniform (0 0 0);
    }
    frontAndBack
    {
        type            symmetry;
    }
}
""" % o.jet_velocity)
    write(out, "0/p", "volScalarField", """dimensions      [0 2 -2 0 0 0 0];

internalField   uniform 0;

boundaryField
{
    "(inlet|bottom|walls)"
    {
        type            fixedFluxPressure;
        value           $internalField;
    }
    outlet
    {
        type            fixedValue;
        value           $internalField;
    }
    frontAndBack
    {
        type            symmetry;
    }
}
""")

    # --- constant -----------------------------------------------------------------------------------
    write(out, "constant/g", "uniformDimensionedVectorField",
          "dimensions      [0 1 -2 0 0 0 0];\nvalue           (0 -9.81 0);\n")
    write(out, "constant/transportProperties", "dictionary",
          "continuousPhase air;\n\nrho.air         1.2;\n\ntransportModel  Newtonian;\nnu              1.5e-05;\n")
    write(out, "constant/turbulenceProperties.air", "dictionary", "simulationType  laminar;\n")

    # The packed layer: parcels drawn uniformly over the layer (a parcel's centre at least a radius from
    # the walls), as many as give --packing.
    rng = random.Random(o.seed)
    r = o.diameter / 2
    volume = o.width * o.bed_height * depth * o.packing
    n = round(volume / (o.n_particle * math.pi / 6 * o.diameter ** 3))
    lines = ["(%.7g %.7g %.7g)" % (rng.uniform(-o.width / 2 + r, o.width / 2 - r), rng.uniform(r, o.bed_height),
                                   rng.uniform(r, depth - r)) for _ in range(n)]
    write(out, "constant/kinematicCloudPositions", "vectorField", "%d\n(\n%s\n)\n" % (n, "\n".join(lines)))

    write(out, "constant/kinematicCloudProperties", "dictionary", """solution
{
    active          true;
    coupled         true;
    transient       yes;
    cellValueSourceCorrection off;
    maxCo           0.3;

    interpolationSchemes
    {
        rho.air         cell;
        U.air           cellPoint;
        mu.air          cell;
    }

    averagingMethod dual;

    integrationSchemes
    {
        U               Euler;
    }

    sourceTerms
    {
        schemes
        {
            U           semiImplicit 1;
        }
    }
}

constantProperties
{
    rho0            %(rho)s;
    alphaMax        0.9;
}

subModels
{
    particleForces
    {
        ErgunWenYuDrag
        {
            alphac alpha.air;
        }
        gravity;
    }

    injectionModels
    {
        packedLayer
        {
            type            manualInjection;
            massTotal       0;
            parcelBasisType fixed;
            nParticle       %(np)d;
            SOI             0;
            positionsFile   "kinematicCloudPositions";
            U0              (0 0 0);
            sizeDistribution
            {
                type        fixedValue;
                fixedValueDistribution
                {
                    value   %(d)s;
                }
            }
        }
    }

    dispersionModel none;

    patchInteractionModel localInteraction;

    localInteractionCoeffs
    {
        patches
        (
            "(inlet|bottom|walls|frontAndBack)"
            {
                type rebound;
                e    0.9;
                mu   0.1;
            }
            outlet
            {
                type escape;
            }
        );
    }

    heatTransferModel none;

    surfaceFilmModel none;

    packingModel implicit;

    implicitCoeffs
    {
        alphaMin 0.0001;
        rhoMin 1.0;
        applyLimiting true;
        applyGravity true;
        particleStressModel
        {
            type HarrisCrighton;
            alphaPacked 0.6;
            pSolid 10.0;
            beta 2.0;
            eps 1.0e-2;
        }
    }

    dampingModel none;

    isotropyModel stochastic;

    stochasticCoeffs
    {
        timeScaleModel
        {
            type isotropic;
            alphaPacked 0.6;
            e 0.9;
        }
    }

    stochasticCollisionModel none;

    radiation off;
}

cloudFunctions
{}
""" % {"rho": repr(o.density), "np": o.n_particle, "d": repr(o.diameter)})

    # --- system -------------------------------------------------------------------------------------
    write(out, "system/controlDict", "dictionary", """application     MPPICFoam;

startFrom       startTime;
startTime       0;
stopAt          endTime;
endTime         %s;
deltaT          %s;

writeControl    runTime;
writeInterval   %s;
purgeWrite      0;
writeFormat     %s;
writePrecision  8;
writeCompression off;
timeFormat      general;
timePrecision   6;
runTimeModifiable no;

// The import reads the legacy positions (docs/import.md); Debian's etc/controlDict sets this already.
InfoSwitches
{
    writeLagrangianPositions 1;
}
""" % (o.end_time, o.delta_t, o.write_interval, o.format))
    write(out, "system/fvSchemes", "dictionary", """ddtSchemes
{
    default Euler;
}

gradSchemes
{
    default         Gauss linear;
}

divSchemes
{
    default         none;
    div(alphaPhi.air,U.air)    Gauss linearUpwindV unlimited;
    div(((alpha.air*nuEff.air)*dev2(T(grad(U.air))))) Gauss linear;
    div(phiGByA,kinematicCloud:alpha) Gauss linear;
}

laplacianSchemes
{
    default         Gauss linear corrected;
}

interpolationSchemes
{
    default         linear;
}

snGradSchemes
{
    default         corrected;
}
""")
    write(out, "system/fvSolution", "dictionary", """solvers
{
    p
    {
        solver          GAMG;
        tolerance       1e-06;
        relTol          0.01;
        smoother        GaussSeidel;
    }

    pFinal
    {
        $p;
        relTol          0;
    }

    "U.air.*"
    {
        solver          smoothSolver;
        smoother        symGaussSeidel;
        tolerance       1e-05;
        relTol          0;
    }

    kinematicCloud:alpha
    {
        solver          GAMG;
        tolerance       1e-06;
        relTol          0;
        smoother        GaussSeidel;
    }
}

PIMPLE
{
    nOuterCorrectors 1;
    nCorrectors     2;
    momentumPredictor yes;
    nNonOrthogonalCorrectors 0;
    pRefCell        0;
    pRefValue       0;
}

relaxationFactors
{
}
""")
    print("%s: %d x %d x 1 cells of %.4g m, inlet %d cells (%.4g m) at %.4g m/s, %d parcels of %d particle(s)"
          % (out, nx, ny, o.cell, ni, ni * o.cell, o.jet_velocity, n, o.n_particle))


if __name__ == "__main__":
    main()

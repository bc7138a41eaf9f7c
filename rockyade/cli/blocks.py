"""``rockyade params`` and ``rockyade calibrate``: a block's classical and DEM parameters."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rockyade.cli.common import Commands, add_command, json_out, print_calibration
from rockyade.errors import InputError

if TYPE_CHECKING:  # the parser stays fast: blocks are imported when a command runs
    from numpy.typing import ArrayLike

    from rockyade.blocks.geometry import Block

#: A block the arguments describe: its name, the block and its classical overrides (rad, 1/s, -).
NamedBlock = tuple[str, "Block", dict[str, float]]

#: Calibration methods offered by ``rockyade calibrate``.
CALIBRATION_METHODS = ["paper", "matched"]


# ------------------------------------------------------------------ block input


def _add_block_arguments(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("block (one of: --specimen, --scene, dimensions or --vertices)")
    g.add_argument("--specimen", help="a specimen of the paper: 1-4, upper, lower")
    g.add_argument("--scene", type=Path, help="a scene file (.toml or .json)")
    g.add_argument("--block", help="block name in the scene (default: every block)")
    g.add_argument("--width", type=float, help="base width 2b, m")
    g.add_argument("--height", type=float, help="height 2h, m")
    g.add_argument("--vertices", help='convex polygon "x,y x,y ..." in m, base on y = 0')
    g.add_argument("--chamfer", type=float, help="45-degree base chamfer leg, m (with --width/--height)")
    g.add_argument("--thickness", type=float, help="thickness, m")
    g.add_argument("--mass", type=float, help="mass, kg")
    g.add_argument("--density", type=float, help="density, kg/m^3")
    g.add_argument("--inertia", type=float, help="rotational inertia about the centroid, kg m^2")


def _blocks_from_args(args: argparse.Namespace) -> list[NamedBlock]:
    """(name, Block, classical overrides) for each block the arguments describe."""
    from rockyade import paper
    from rockyade.blocks.geometry import Block, chamfered_rectangle_vertices, rectangle_vertices

    chosen = [x for x in (args.specimen, args.scene, args.width or args.vertices) if x]
    if len(chosen) != 1:
        raise InputError(
            "block", "give exactly one of --specimen, --scene, or dimensions (--width/--height or --vertices)"
        )
    if args.specimen:
        spec = paper.specimen(args.specimen)
        return [(spec.name, spec.block(), {})]
    if args.scene:
        from rockyade.scene import load_scene

        scene = load_scene(args.scene)
        specs = [b for b in scene.blocks if args.block in (None, b.name)]
        if not specs:
            raise InputError("--block", f"no block {args.block!r} in {args.scene}")
        out = []
        for b in specs:
            overrides = {k: getattr(b, k) for k in ("alpha_rad", "p_rad_s", "mu") if getattr(b, k) is not None}
            out.append((b.name, b.block(), overrides))
        return out
    if args.thickness is None:
        raise InputError("--thickness", "is required with dimensions (m)")
    verts: ArrayLike  # [[x, y], ...], m
    if args.vertices:
        try:
            verts = [[float(c) for c in pair.split(",")] for pair in args.vertices.split()]
        except ValueError:
            raise InputError("--vertices", 'must look like "x,y x,y x,y" (metres)') from None
    else:
        if args.height is None:
            raise InputError("--height", "is required with --width (m)")
        for name in ("width", "height"):
            value = getattr(args, name)
            if not value > 0:
                raise InputError(f"--{name}", f"must be > 0 m, got {value}")
    options = {**_BLOCK_OPTIONS, "vertices_m": "--vertices" if args.vertices else "--width/--height"}
    try:
        if not args.vertices:
            verts = (
                chamfered_rectangle_vertices(args.width, args.height, args.chamfer)
                if args.chamfer
                else rectangle_vertices(args.width, args.height)
            )
        block = Block.polygon(
            verts,
            args.thickness,
            mass_kg=args.mass,
            density_kg_m3=args.density,
            inertia_kgm2=args.inertia,
            name="block",
        )
    except InputError as exc:
        message = exc.message
        for field, option in options.items():
            message = message.replace(field, option)
        raise InputError(options.get(exc.field, exc.field), message) from None
    _check_scene_ranges(args)
    return [("block", block, {})]


def _check_scene_ranges(args: argparse.Namespace) -> None:
    """The dimensions, mass and density in the ranges a scene takes (:data:`rockyade.scene.bounds.BOUNDS`):
    a block given in millimetres or a density in kg/dm^3 is refused here as it is in a scene."""
    from rockyade.scene.bounds import BOUNDS

    given = (
        ("--width", args.width, "length_m"),
        ("--height", args.height, "length_m"),
        ("--thickness", args.thickness, "length_m"),
        ("--mass", args.mass, "mass_kg"),
        ("--density", args.density, "density_kg_m3"),
    )
    for option, value, field in given:
        bound = BOUNDS[field]
        if value is not None and not bound.lo <= value <= bound.hi:
            raise InputError(option, f"must be in [{bound.lo:g}, {bound.hi:g}] {bound.unit}, got {value:g}")


#: Block.polygon's field names as this command's options (its messages name the options).
_BLOCK_OPTIONS = {
    "mass_kg": "--mass",
    "density_kg_m3": "--density",
    "inertia_kgm2": "--inertia",
    "thickness_m": "--thickness",
    "chamfer_m": "--chamfer",
}


def _is_rectangle(vertices_m: ArrayLike) -> bool:
    """Four vertices on two x and two y values: the paper's Eqs 2-4 apply as printed."""
    import numpy as np

    v = np.asarray(vertices_m, dtype=float)
    scale = float(np.ptp(v)) or 1.0
    return len(v) == 4 and all(len(np.unique(np.round(v[:, k] / scale, 9))) == 2 for k in (0, 1))


# ------------------------------------------------------------------ commands


def cmd_params(args: argparse.Namespace) -> int:
    """classical parameters alpha, p, mu of a block

    Classical rocking parameters (paper Eqs 2-4, general polygon forms).

    Parameters
    ----------
    args
        The parsed command line (one block input, ``--json``).

    Returns
    -------
    int
        Exit code (0).
    """
    from rockyade.blocks.classical import classical_parameters

    out: dict[str, dict[str, Any]] = {}  # block name -> its JSON object
    rectangles: dict[str, bool] = {}
    for name, block, overrides in _blocks_from_args(args):
        cp = classical_parameters(block, **overrides)
        rectangles[name] = _is_rectangle(block.vertices_m)
        out[name] = {
            "alpha_rad": cp.alpha_rad,
            "p_rad_s": cp.p_rad_s,
            "mu": cp.mu,
            "R_m": cp.R_m,
            "I_O_kgm2": cp.I_O_kgm2,
            "I_c_kgm2": cp.I_c_kgm2,
            "mass_kg": cp.mass_kg,
            "uplift_accel_m_s2": cp.uplift_accel_m_s2,
            "centroid_height_m": cp.centroid_height_m,
            "symmetric": cp.symmetric,
            "mu_left_to_right": cp.mu_left_to_right,
            "mu_right_to_left": cp.mu_right_to_left,
            "pivots": {"left": cp.left.__dict__, "right": cp.right.__dict__},
            "source": cp.source,
        }
    if args.json:
        json_out(out[next(iter(out))] if len(out) == 1 else out)
        return 0
    for name, d in out.items():
        rect = rectangles[name]
        general = "" if rect else " generalised to polygons"
        alpha_src = f"Eq 2{general}" if d["source"]["alpha_rad"] == "geometry" else "override"
        p_src = "Eq 3 for rectangles" if rect else f"Eq 3{general}"
        mu_src = "Eq 4 for rectangles" if rect else f"Eq 4{general}"
        print(f"{name}:")
        print(f"  alpha = {d['alpha_rad']:.6g} rad ({alpha_src})")
        print(f"  p     = {d['p_rad_s']:.6g} 1/s (p^2 = M g R / I_O; {p_src})")
        print(f"  mu    = {d['mu']:.6g} (angular momentum about the new pivot; {mu_src})")
        print(f"  R     = {d['R_m']:.6g} m, I_O = {d['I_O_kgm2']:.6g} kg m^2, I_c = {d['I_c_kgm2']:.6g} kg m^2")
        print(f"  M     = {d['mass_kg']:.6g} kg")
        print(f"  uplift when |a_g| > g tan(alpha) = {d['uplift_accel_m_s2']:.6g} m/s^2")
        if not d["symmetric"]:
            print(f"  asymmetric: mu L->R = {d['mu_left_to_right']:.6g}, R->L = {d['mu_right_to_left']:.6g}")
    return 0


def cmd_calibrate(args: argparse.Namespace) -> int:
    """DEM contact parameters from classical parameters

    DEM contact parameters of a specimen: K (Eq 10), b_eq (Eq 11), beta (Eq 13 or matched to mu with the reference
    DEM), xi_min (Eq 15), f_min (Eq 14), dt (Eq 7).

    Parameters
    ----------
    args
        The parsed command line: ``--specimen`` (or a block with ``--from``),
        ``--parameters``, ``--method``, ``--stiffness-scale``, ``--friction-angle`` (degrees).

    Returns
    -------
    int
        Exit code (0).
    """
    from rockyade import paper
    from rockyade.calibration.calibrate import calibrate
    from rockyade.scene import ContactSpec

    if not 0.0 < args.friction_angle < 90.0:
        raise InputError("--friction-angle", f"must be in (0, 90) degrees, got {args.friction_angle:g}")
    if args.from_identified is not None:
        return _calibrate_identified(args, _blocks_from_args(args))
    if args.specimen is None or args.scene or args.width or args.vertices:
        raise InputError("--specimen", "is required: 1, 2, 3, 4, upper or lower (--scene, dimensions: with --from)")
    spec = paper.specimen(args.specimen)
    block = spec.block()
    if args.parameters == "experimental":
        params = spec.experimental
    else:
        from rockyade.blocks.classical import classical_parameters

        cp = classical_parameters(block)
        params = {"alpha_rad": cp.alpha_rad, "p_rad_s": cp.p_rad_s, "mu": cp.mu}
    contact = ContactSpec(
        calibration=args.method, stiffness_scale=args.stiffness_scale, friction_angle_deg=args.friction_angle
    )
    cal = calibrate(block, contact, **params)
    result: dict[str, Any] = {
        "specimen": spec.key,
        "parameters": args.parameters,
        "classical": params,
        "method": args.method,
        **cal.report(),
    }
    if args.json:
        json_out(result)
        return 0
    a, p, mu = params["alpha_rad"], params["p_rad_s"], params["mu"]
    print(f"{spec.label}, {args.parameters} parameters: alpha = {a:.4g} rad, p = {p:.4g} 1/s, mu = {mu:.4g}")
    print_calibration(result, args.method)
    return 0


def _calibrate_identified(args: argparse.Namespace, blocks: list[NamedBlock]) -> int:
    """``rockyade calibrate --from identified.json``: DEM parameters from identified values."""
    from rockyade.identification.identified import calibrate_from_identified

    if len(blocks) != 1:
        raise InputError("block", f"the scene has {len(blocks)} blocks: choose one with --block")
    name, block, _overrides = blocks[0]
    result = calibrate_from_identified(
        block,
        args.from_identified,
        method=args.method,
        stiffness_scale=args.stiffness_scale,
        friction_angle_deg=args.friction_angle,
    )
    result["block"] = name
    result["from"] = str(args.from_identified)
    if args.json:
        json_out(result)
        return 0
    c, ci = result["classical"], result["classical_ci"]

    def interval(key: str) -> str:
        return f" [{ci[key][0]:.4g}, {ci[key][1]:.4g}]" if key in ci else ""

    print(f"{name} ({block.mass_kg:.4g} kg), identified parameters from {args.from_identified}:")
    print(
        f"  alpha = {c['alpha_rad']:.5g} rad{interval('alpha_rad')}, p = {c['p_rad_s']:.5g} 1/s{interval('p_rad_s')}, "
        f"mu = {c['mu']:.5g}{interval('mu')}"
    )
    print_calibration(result, args.method)
    return 0


def register(sub: Commands) -> None:
    """Add ``params`` and ``calibrate``."""
    p = add_command(sub, cmd_params)
    _add_block_arguments(p)
    p.add_argument("--json", action="store_true", help="print JSON")

    p = add_command(sub, cmd_calibrate)
    _add_block_arguments(p)
    p.add_argument("--from", dest="from_identified", type=Path, help="identified values (rockyade identify --out)")
    p.add_argument(
        "--parameters",
        choices=["theoretical", "experimental"],
        default="experimental",
        help="classical parameters: from the geometry (theoretical) or the paper's Tables 3-4 E column",
    )
    p.add_argument(
        "--method",
        choices=CALIBRATION_METHODS,
        default="paper",
        help="damping: Eq 13 (paper) or matched so that the reference DEM's effective mu equals mu",
    )
    p.add_argument(
        "--stiffness-scale",
        default="MN/m",
        help="reading of the paper's K: N/m, kN/m, MN/m (default) or a factor",
    )
    p.add_argument("--friction-angle", type=float, default=30.0, help="joint friction angle, degrees (default 30)")
    p.add_argument("--json", action="store_true", help="print JSON")

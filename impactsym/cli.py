"""The ``impactsym`` command (also ``python -m impactsym``).

* ``impactsym --version`` -- the installed version;
* ``impactsym reproduce --out DIR [--quick] [--force]`` -- every figure, table and formula;
* ``impactsym latex NAME`` (``--list`` for the names) -- one formula, for pasting;
* ``impactsym export python FILE`` / ``impactsym export latex FILE`` -- generated files;
* ``impactsym mujoco --restitution E --speed V [--gravity G] [--contact-time T] [--mass M]
  [--timestep DT] [--integrator I] [--continuous] [--solimp ...] [--form stiffness]`` --
  MJCF ``solref``/``solimp`` for a wanted restitution, designed as the mean over touch
  phases at MuJoCo's timestep (default 0.002 s, Euler), with the range over phases and
  the predictions (SI units; ``--continuous``: the limit ``timestep -> 0``);
* ``impactsym lammps --restitution E --mass M (--contact-time T | --max-penetration X)
  [--speed V] [--gravity G] [--no-limit-damping] [--timestep DT]`` -- LAMMPS ``pair_style
  granular`` Hooke ``kn`` and ``eta_n`` for a wanted restitution, with the predictions
  (SI units; with ``--timestep`` designed for LAMMPS's velocity-Verlet at that step, the
  phase mean and range printed);
* ``impactsym engines --restitution E --contact-time T --mass M --speed V [--gravity G]`` --
  the same impact for MuJoCo, LAMMPS, Drake and PyBullet: per engine the parameters to
  paste and the predicted restitution and contact time (phase mean and range) at its
  default step, or why the engine cannot deliver it there
  (:func:`impactsym.engines.conformance.conformance_table`).
"""

from __future__ import annotations

import argparse
import math
import os
import signal
import sys
import threading
from collections.abc import Sequence
from pathlib import Path

from impactsym import __version__


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="impactsym", description="Exact symbolic-numeric impact mechanics."
    )
    parser.add_argument("--version", action="version", version=f"impactsym {__version__}")
    commands = parser.add_subparsers(dest="command", required=True)
    rep = commands.add_parser("reproduce", help="regenerate every figure, table and formula")
    rep.add_argument(
        "--out",
        required=True,
        help="output directory: new, empty, or written by a former run (it holds the "
        "marker file .impactsym-reproduce); never the current or home directory",
    )
    rep.add_argument("--quick", action="store_true", help="coarse grids (seconds, for tests)")
    rep.add_argument(
        "--force",
        action="store_true",
        help="replace the files a former run wrote into --out (nothing else is deleted)",
    )

    latex = commands.add_parser("latex", help="print one derived formula as LaTeX")
    latex.add_argument("name", nargs="?", help="formula label, e.g. sd-ridge-force-underdamped")
    latex.add_argument(
        "--list", action="store_true", help="list the formula labels with what each one is"
    )

    export = commands.add_parser("export", help="write a generated file")
    export.add_argument(
        "kind", choices=["python", "latex"], help="python: NumPy-only module; latex: formulas.tex"
    )
    export.add_argument("file", type=Path, help="output file")

    mj = commands.add_parser("mujoco", help="MuJoCo solref/solimp for a wanted restitution")
    mj.add_argument("--restitution", type=float, required=True, help="wanted e, 0 < e < 1")
    mj.add_argument("--speed", type=float, required=True, help="normal approach speed, m/s")
    mj.add_argument("--gravity", type=float, default=0.0, help="pressing acceleration, m/s^2")
    mj.add_argument("--contact-time", type=float, default=None, help="wanted contact time, s")
    mj.add_argument("--mass", type=float, default=None, help="effective mass, kg")
    mj.add_argument(
        "--timestep",
        type=float,
        default=None,
        help="MuJoCo timestep, s: design the phase mean at it (default: MuJoCo's 0.002; "
        "0: the continuous design, as --continuous)",
    )
    mj.add_argument(
        "--integrator",
        choices=["euler", "implicitfast", "rk4"],
        default=None,
        help="MuJoCo integrator (default: MuJoCo's euler)",
    )
    mj.add_argument(
        "--continuous",
        action="store_true",
        help="design for timestep -> 0 (exact only at very small timesteps)",
    )
    mj.add_argument(
        "--solimp",
        type=float,
        nargs=5,
        default=None,
        metavar="X",
        help="d_min d_max width midpoint power (default: MuJoCo's 0.9 0.95 0.001 0.5 2)",
    )
    mj.add_argument(
        "--form",
        choices=["timeconst", "stiffness"],
        default="timeconst",
        help="solref as (timeconst, dampratio) or (-stiffness, -damping)",
    )

    lmp = commands.add_parser(
        "lammps", help="LAMMPS granular Hooke kn, eta_n for a wanted restitution (units si)"
    )
    lmp.add_argument("--restitution", type=float, required=True, help="wanted e, 0 < e < 1")
    lmp.add_argument("--mass", type=float, required=True, help="effective mass m1 m2/(m1+m2), kg")
    target = lmp.add_mutually_exclusive_group(required=True)
    target.add_argument("--contact-time", type=float, help="wanted contact time, s")
    target.add_argument("--max-penetration", type=float, help="wanted largest overlap, m")
    lmp.add_argument(
        "--speed", type=float, default=None, help="normal approach speed, m/s (default 1)"
    )
    lmp.add_argument(
        "--gravity",
        type=float,
        default=0.0,
        help="pressing acceleration for the prediction, m/s^2 (the design has none)",
    )
    lmp.add_argument(
        "--limit-damping",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="LAMMPS's limit_damping keyword: contact ends when the force vanishes "
        "(default; --no-limit-damping: when the overlap does)",
    )
    lmp.add_argument(
        "--timestep",
        type=float,
        default=None,
        help="LAMMPS timestep, s: design for velocity-Verlet at it (phase mean) and print "
        "the range over touch phases (default: the continuous design, timestep -> 0)",
    )

    eng = commands.add_parser(
        "engines",
        help="one impact in MuJoCo, LAMMPS, Drake and PyBullet: parameters and predictions",
    )
    eng.add_argument("--restitution", type=_positive(), required=True, help="wanted e, 0 < e < 1")
    eng.add_argument("--contact-time", type=_positive(), required=True, help="wanted t_c, s")
    eng.add_argument(
        "--mass", type=_positive(), required=True, help="effective mass of the contact, kg"
    )
    eng.add_argument("--speed", type=_positive(), required=True, help="normal approach speed, m/s")
    eng.add_argument(
        "--gravity",
        type=_positive(zero=True),
        default=0.0,
        help="pressing acceleration, m/s^2 (default 0)",
    )
    return parser


def _positive(*, zero: bool = False):
    """An argparse ``type``: a finite real ``> 0`` (``>= 0`` with ``zero``); argparse names
    the option in its error (exit code 2)."""

    def convert(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not math.isfinite(value) or value < 0 or (value == 0 and not zero):
            bound = ">= 0" if zero else "> 0"
            raise argparse.ArgumentTypeError(f"must be a finite number {bound}, got {text!r}")
        return value

    return convert


def _engines(args: argparse.Namespace) -> None:
    from impactsym.engines.conformance import conformance_table

    table = conformance_table(
        restitution=args.restitution,
        contact_time=args.contact_time,
        mass=args.mass,
        speed=args.speed,
        gravity=args.gravity,
    )
    print(table.text())


#: MuJoCo's defaults (mjOption): the timestep and integrator the CLI designs for
_MUJOCO_TIMESTEP = 0.002
_MUJOCO_INTEGRATOR = "euler"
_INTEGRATOR_NAMES = {"euler": "Euler", "implicitfast": "implicitfast", "rk4": "RK4"}


def _mujoco_step(args: argparse.Namespace) -> tuple[float | None, str, str]:
    """The timestep (``None``: continuous) and integrator to design for, and a note."""
    continuous = args.continuous or args.timestep == 0
    if continuous and args.timestep not in (None, 0):
        raise ValueError(f"--continuous and --timestep {args.timestep:g} contradict each other")
    if continuous and args.integrator is not None:
        raise ValueError("--integrator needs a timestep (drop --continuous / --timestep 0)")
    if continuous:
        return None, "", "designed for the continuous limit (timestep -> 0)"
    step = _MUJOCO_TIMESTEP if args.timestep is None else args.timestep
    integrator = _MUJOCO_INTEGRATOR if args.integrator is None else args.integrator
    name = _INTEGRATOR_NAMES[integrator]
    default = " (MuJoCo's default; {} to change)"
    said = [
        f"timestep {step:g} s" + (default.format("--timestep") if args.timestep is None else ""),
        f"integrator {name}" + (default.format("--integrator") if args.integrator is None else ""),
    ]
    return step, integrator, "designed for " + ", ".join(said) + ": the mean over touch phases"


def _mujoco(args: argparse.Namespace) -> None:
    import warnings

    from impactsym.engines import mujoco

    solimp = mujoco.DEFAULT_SOLIMP if args.solimp is None else tuple(args.solimp)
    common = {"speed": args.speed, "gravity": args.gravity, "mass": args.mass}
    timestep, integrator, note = _mujoco_step(args)
    at = {} if timestep is None else {"timestep": timestep, "integrator": integrator}
    with warnings.catch_warnings(record=True) as caught:  # printed as notes, not raw
        warnings.simplefilter("always")
        design = mujoco.solref_for(
            restitution=args.restitution,
            contact_time=args.contact_time,
            solimp=solimp,
            form=args.form,
            **at,
            **common,
        )
        limit = mujoco.predict(solref=design.solref, solimp=solimp, **common)
        log_e = math.log(args.restitution)
        textbook = -log_e / math.sqrt(math.pi**2 + log_e**2)
        timeconst = design.solref[0] if args.form == "timeconst" else mujoco.DEFAULT_TIMECONST
        naive = mujoco.predict(solref=(timeconst, textbook), solimp=solimp, **at, **common)
    p = design.prediction
    print(design.mjcf())
    print(note)
    if timestep is None:
        print(f"predicted restitution:  {p.restitution:.6g}")
        print(f"predicted contact time: {p.contact_time:.6g} s")
    else:
        name = _INTEGRATOR_NAMES[integrator]
        e_lo, e_hi = p.restitution_range
        t_lo, t_hi = p.contact_time_range
        print(
            f"predicted restitution:  {p.restitution:.6g} (phase mean at dt = {timestep:g} s, "
            f"{name}; {e_lo:.6g} .. {e_hi:.6g} over touch phases)"
        )
        print(
            f"predicted contact time: {p.contact_time:.6g} s (phase mean; {t_lo:.6g} .. "
            f"{t_hi:.6g} s over touch phases)"
        )
        print(
            f"continuous limit:       restitution {limit.restitution:.6g}, contact time "
            f"{limit.contact_time:.6g} s (this solref as timestep -> 0)"
        )
    tag = "" if timestep is None else " (continuous limit)"
    ends = "penetration" if limit.released_by_position else "force"
    print(f"contact ends by:        {ends}{tag}")
    print(f"max penetration:        {limit.max_penetration:.6g} m{tag}")
    if args.mass is not None:
        print(f"peak force:             {limit.peak_force:.6g} N{tag}")
    where = "" if timestep is None else " (phase mean)"
    print(
        f"textbook dampratio {textbook:.6g} would give restitution {naive.restitution:.6g}"
        + ((" (sticks" + (" at some phase)" if where else ")")) if naive.sticks else where)
    )
    for w in caught:
        print(f"note: {w.message}")


def _lammps(args: argparse.Namespace) -> None:
    from impactsym.engines import lammps

    design = lammps.hooke_for(
        restitution=args.restitution,
        mass=args.mass,
        contact_time=args.contact_time,
        max_penetration=args.max_penetration,
        speed=args.speed,
        limit_damping=args.limit_damping,
        timestep=args.timestep,
    )
    speed = 1.0 if args.speed is None else args.speed
    p = lammps.predict(
        kn=design.kn,
        damping=design.damping,
        mass=args.mass,
        speed=speed,
        gravity=args.gravity,
        limit_damping=args.limit_damping,
        timestep=args.timestep,
    )
    print("pair_style granular")
    print(design.pair_coeff())
    loaded = f" (gravity {args.gravity:g} m/s^2)" if args.gravity else ""
    if p.sticks:
        print(f"predicted: the particle sticks{loaded}")
    else:
        print(f"predicted restitution:  {p.restitution:.6g}{loaded}")
        print(f"predicted contact time: {p.contact_time:.6g} s{loaded}")
        print(f"contact ends by:        {'overlap' if p.released_by_position else 'force'}")
        if args.gravity and not p.released_by_position:
            print(f"leaves the overlap at:  {p.departure_speed:.6g} m/s (coast under gravity)")
    if args.timestep is None:
        print("model:                  continuous (timestep -> 0); give --timestep for LAMMPS's")
        print("                        velocity-Verlet at your step (t_c/50: up to 4 % off)")
    else:
        e_lo, e_hi = p.restitution_range
        t_lo, t_hi = p.contact_time_range
        print(
            f"model:                  velocity-Verlet at timestep {args.timestep:g} s, "
            "mean over touch phases"
        )
        print(f"restitution over phases:  {e_lo:.6g} .. {e_hi:.6g}")
        print(f"contact time over phases: {t_lo:.6g} .. {t_hi:.6g} s")
    print(f"max overlap:            {p.max_penetration:.6g} m (at {speed:g} m/s)")
    print(f"peak force:             {p.peak_force:.6g} N (at {speed:g} m/s)")
    print(f"damping ratio:          {design.damping_ratio:.6g}")
    if args.limit_damping:
        naive = lammps.coeff_restitution_achieved(args.restitution)
        try:
            fixed = f"; {lammps.coeff_restitution_for(args.restitution):.6g} gives it"
        except ValueError:
            fixed = "; no coeff_restitution input gives it (e <= exp(-2))"
        print(
            f"'damping coeff_restitution {args.restitution:g}' would give restitution "
            f"{naive:.6g} under limit_damping{fixed}"
        )


def _reproduce(args: argparse.Namespace) -> None:
    """Run ``reproduce`` so that Ctrl-C always stops it.

    Python raises ``KeyboardInterrupt`` wherever the signal arrives; inside a finalizer
    or weakref callback it is printed and ignored. The handler therefore also sets a
    flag that the next progress message turns into ``KeyboardInterrupt`` again, and such
    an ignored interrupt is not printed. Once interrupted, any error that follows (a
    library's cleanup failing on a half-made object) is reported as the interrupt.
    """
    from impactsym.reproduce import reproduce

    interrupted: list[int] = []

    def on_sigint(signum: int, frame: object) -> None:
        interrupted.append(signum)
        raise KeyboardInterrupt

    def progress(message: str) -> None:
        if interrupted:
            raise KeyboardInterrupt
        print(message, flush=True)

    def unraisable(report: object) -> None:  # an interrupt swallowed in a finalizer
        if not issubclass(report.exc_type, KeyboardInterrupt):
            previous_hook(report)

    in_main_thread = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGINT, on_sigint) if in_main_thread else None
    previous_hook, sys.unraisablehook = sys.unraisablehook, unraisable
    try:
        reproduce(args.out, quick=args.quick, force=args.force, progress=progress)
    except Exception as exc:
        # the interrupt may surface as another error: a library's cleanup after it (e.g.
        # Matplotlib's PDF writer closing a stream it was opening raised AttributeError)
        if interrupted:
            raise KeyboardInterrupt from exc
        raise
    finally:
        sys.unraisablehook = previous_hook
        if in_main_thread:
            signal.signal(signal.SIGINT, previous)
    if interrupted:
        raise KeyboardInterrupt


def _run(args: argparse.Namespace) -> None:
    if args.command == "reproduce":
        _reproduce(args)
    elif args.command == "latex":
        from impactsym.export import formula, formula_descriptions

        if args.list or args.name is None:
            entries = formula_descriptions()
            width = max(len(label) for label, _ in entries)
            print("\n".join(f"{label:<{width}}  {text}" for label, text in entries))
        else:
            print(formula(args.name))
    elif args.command == "mujoco":
        _mujoco(args)
    elif args.command == "lammps":
        _lammps(args)
    elif args.command == "engines":
        _engines(args)
    else:
        from impactsym.export import write_latex_document, write_python_module

        writer = write_python_module if args.kind == "python" else write_latex_document
        print(f"wrote {writer(args.file)}")


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the process exit code (non-zero on any failure).

    >>> main(["latex", "sd-conditions"])
    g_\\mathrm{position} = z, \\qquad g_\\mathrm{force} = 2 D z' + z
    0
    """
    args = build_parser().parse_args(argv)
    try:
        _run(args)
    except KeyboardInterrupt:
        # every file is renamed into place only when complete: nothing partial is left
        print("impactsym: interrupted; files completed so far are kept", file=sys.stderr)
        return 130
    except (OSError, ValueError, RuntimeError) as exc:
        print(f"impactsym: error: {exc}", file=sys.stderr)
        return 2
    except Exception as exc:  # an unexpected failure: still a clear message and exit code
        print(f"impactsym: internal error: {type(exc).__name__}: {exc}", file=sys.stderr)
        return 3
    return 0


def run() -> None:
    """Entry point of the ``impactsym`` command and of ``python -m impactsym``.

    Exits with :func:`main`'s code. An interrupted run (130) ignores further Ctrl-C and
    leaves through :func:`os._exit` after flushing stdout and stderr: in full test runs
    under load the child of ``test_sigint_during_a_run...`` printed its message and
    still died by SIGINT (status -2) on CPython's normal exit path, cause not pinned
    down. Every file is complete or absent by then, so skipping the interpreter's
    finalization loses nothing.
    """
    code = main()
    if code == 130:
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # a second Ctrl-C: we are leaving
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    raise SystemExit(code)

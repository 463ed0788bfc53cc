"""Options and helpers shared by the sub-commands."""

from __future__ import annotations

import argparse
import math
import os
import sys

import numpy as np

from .. import jsondoc
from .._validate import show
from ..atomic import atomic_write_text
from ..errors import ParameterError
from ..model.config import DEFAULT_PRESET, PRESET_GUIDANCE, apply_overrides, load_config, set_parameters
from ..model.params import Model
from ..units import CM_PER_M, centimetre_slip, cm2_to_m2, radian_slip, square_metre_slip

BOTH_LORDOSIS = "is not allowed with --Lambda (both give the lordosis): give one of them"
"""The error of ``--lordosis-angle`` given with ``--Lambda`` (:func:`lordosis_option`, :func:`lordosis_grid`)."""


def add_model_options(parser: argparse.ArgumentParser) -> None:
    """``--config FILE``, ``--preset NAME`` and ``--set SECTION.FIELD=VALUE``, on every command that takes a model.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The (sub-)command's parser; the options go into a group named "model".
    """
    group = parser.add_argument_group("model")
    group.add_argument(
        "--config",
        metavar="FILE",
        help="TOML file overriding the preset's parameters ([[muscles]] merge with the preset's by name)",
    )
    group.add_argument(
        "--preset",
        metavar="NAME",
        help=f"built-in parameter preset (default: {DEFAULT_PRESET!r}): {PRESET_GUIDANCE.replace('%', '%%')}",
    )
    add_set_option(group)


def add_set_option(group) -> None:
    """``--set SECTION.FIELD=VALUE`` (repeatable) into ``args.assignments``; in :func:`add_model_options`.

    Parameters
    ----------
    group : argparse.ArgumentParser or argparse._ArgumentGroup
        Where the option goes (``spinectl study`` takes it alone: its file names the preset).
    """
    group.add_argument(
        "--set",
        dest="assignments",
        action="append",
        default=[],
        metavar="SECTION.FIELD=VALUE",
        help="set one parameter, validated as in a TOML file, e.g. --set passive.stiffness=15 "
        "or --set muscles.straight.spread=0.02 (repeatable; 'spinectl config show' lists every field)",
    )


def add_stiffness_option(parser: argparse.ArgumentParser) -> None:
    """``--K`` [N m/rad], an alias of ``--set passive.stiffness=K``, into ``args.K`` (:func:`body_aliases`).

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The sub-command's parser.
    """
    parser.add_argument(
        "--K",
        type=finite_float("--K"),
        help="passive stiffness K [N m/rad] (alias of --set passive.stiffness=K; not both)",
    )


def add_mass_option(parser: argparse.ArgumentParser) -> None:
    """``--mass`` [kg], an alias of ``--set body.mass=M``, into ``args.mass`` (:func:`body_aliases`).

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The sub-command's parser; wherever it has ``--K``.
    """
    parser.add_argument(
        "--mass",
        type=finite_float("--mass"),
        metavar="KG",
        help="upper-body mass m [kg] (alias of --set body.mass=M; not both)",
    )


def body_aliases(args: argparse.Namespace) -> dict:
    """The ``--K`` and ``--mass`` given, for :func:`load_model`'s ``aliases``.

    ``spinectl sweep``'s ``--K`` is a list (an axis of its own), not an alias: only a single value is one.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments, with ``mass`` and possibly ``K``.

    Returns
    -------
    dict
        ``(option, value)`` by dotted field.
    """
    stiffness = getattr(args, "K", None)
    aliases = {"body.mass": ("--mass", args.mass)}
    if not isinstance(stiffness, list):
        aliases["passive.stiffness"] = ("--K", stiffness)
    return aliases


def add_position_options(parser: argparse.ArgumentParser) -> None:
    """``--E`` and ``--Lambda`` in metres, or ``--lordosis-angle`` in degrees instead of ``--Lambda``.

    :func:`check_position` turns the angle into ``args.Lambda`` (docs/atlas.md, "Clinical geometry").

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The sub-command's parser.
    """
    parser.add_argument("--E", type=finite_float("--E"), default=0.0, help="eccentricity E [m] (default 0)")
    # not an argparse exclusive group: check_position's one-line error says which to give
    parser.add_argument("--Lambda", type=finite_float("--Lambda"), help="lordosis Lambda [m] (default 0)")
    parser.add_argument(
        "--lordosis-angle",
        type=finite_float("--lordosis-angle"),
        metavar="DEG",
        help="lordosis as the angle between the spine line's end tangents [deg], instead of --Lambda "
        "(theta = 2 atan(2 phi'(0) Lambda / L); docs/atlas.md)",
    )


def lordosis_option(model: Model, angle: float | None, lordosis: float | None, option: str = "--lordosis-angle"):
    """Lambda [m] from ``--Lambda`` or ``--lordosis-angle`` (exactly one or neither; neither: 0).

    Parameters
    ----------
    model : Model
        Its spine length and end conditions convert the angle (:func:`spinectl.model.clinical.lordosis_from_angle`).
    angle : float or numpy.ndarray or None
        The lordosis angle [deg] as given (an array: a grid axis), or None.
    lordosis : float or None
        Lambda [m] as given, or None.
    option : str, optional
        The angle's option, as named in errors.

    Returns
    -------
    float or numpy.ndarray
        Lambda [m], the shape of ``angle`` if given.

    Raises
    ------
    ParameterError
        Both given, or an angle not within (-180, 180) deg, or clamped ends (no angle to convert).
    """
    from ..model.clinical import lordosis_from_angle

    if angle is None:
        return 0.0 if lordosis is None else lordosis
    if lordosis is not None:
        raise ParameterError(option, BOTH_LORDOSIS)
    try:
        lordosis = lordosis_from_angle(angle, model)
    except ParameterError as exc:
        raise ParameterError(option, exc.message) from None
    slip = radian_slip(angle)
    if slip:  # a valid angle, analysed as given: said after the answer, as the --pcsa slip is
        note_after(f"{option}: {slip}")
    return float(lordosis) if np.ndim(lordosis) == 0 else lordosis


def lordosis_grid(model: Model, spec: str | None, angle_spec: str | None, default: str):
    """The Lambda axis [m] of a grid from ``--Lambda START:STOP:NUM`` [m] or ``--lordosis-angle START:STOP:NUM`` [deg].

    The angle's axis is even in degrees, so its Lambda is not (Lambda = L tan(theta / 2) / (2 phi'(0)),
    :func:`spinectl.model.clinical.lordosis_from_angle`).

    Parameters
    ----------
    model : Model
        Its geometry gives the range and converts the angle.
    spec : str or None
        ``--Lambda`` as typed, or None.
    angle_spec : str or None
        ``--lordosis-angle`` as typed, or None.
    default : str
        The ``--Lambda`` axis [m] when neither is given.

    Returns
    -------
    numpy.ndarray, shape (num,)
        Lambda [m].

    Raises
    ------
    ParameterError
        Both given, a malformed spec, or an axis beyond the modelled range (the angle's in degrees).
    """
    from ..landscape.sweep import parse_grid

    bounds = model.geometry.lordosis_range
    if angle_spec is None:
        return parse_grid(default if spec is None else spec, "--Lambda", bounds)
    if spec is not None:
        raise ParameterError("--lordosis-angle", BOTH_LORDOSIS)
    try:
        angles = parse_grid(angle_spec, "--lordosis-angle")
    except ParameterError as exc:
        message = exc.message.replace("in metres, e.g. 0:0.08:81", "in degrees, e.g. 20:80:61")
        raise ParameterError(exc.field, message) from None
    axis = lordosis_option(model, angles, None)
    low, high = bounds
    if not (np.all(axis >= low) and np.all(axis <= high)):
        from ..model.clinical import lordosis_angle

        a_low, a_high = lordosis_angle([low, high], model)
        raise ParameterError(
            "--lordosis-angle",
            f"must be within [{a_low:.6g}, {a_high:.6g}] deg, the modelled range of Lambda (got {angle_spec!r})",
        )
    return axis


def add_dpi_option(parser: argparse.ArgumentParser) -> None:
    """``--dpi``, the resolution of PNG figures, on the commands that draw (:data:`~spinectl.paper.figures.files.DPI`).

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The sub-command's parser.
    """
    from ..paper.figures import DPI

    parser.add_argument("--dpi", type=finite_float("--dpi"), default=DPI, help=f"PNG resolution (default {DPI})")


def check_position(model: Model, args: argparse.Namespace) -> None:
    """``--E`` and ``--Lambda`` (or ``--lordosis-angle``, set into ``args.Lambda``) within the model's range.

    The library refuses them too (:mod:`spinectl.model.checks`), but names its argument; the
    command line says which option, and ``--E 3`` gets "if you meant 3 cm, give 0.03".

    Parameters
    ----------
    model : Model
        Its ``geometry`` gives the ranges [m].
    args : argparse.Namespace
        With ``E`` and ``Lambda`` [m] and possibly ``lordosis_angle`` [deg] (:func:`add_position_options`);
        ``args.Lambda`` becomes the Lambda [m] to analyse.

    Raises
    ------
    ParameterError
        A value out of range, naming ``--E``, ``--Lambda`` or ``--lordosis-angle`` (its range in degrees).
    """
    angle = getattr(args, "lordosis_angle", None)
    args.Lambda = lordosis_option(model, angle, args.Lambda)
    for option, value, (low, high) in (
        ("--E", args.E, model.geometry.eccentricity_range),
        ("--Lambda", args.Lambda, model.geometry.lordosis_range),
    ):
        if angle is not None and option == "--Lambda" and not low <= value <= high:
            from ..model.clinical import lordosis_angle

            a_low, a_high = lordosis_angle([low, high], model)
            raise ParameterError(
                "--lordosis-angle",
                f"must be in [{a_low:.6g}, {a_high:.6g}] deg, the modelled range of Lambda (got {angle:g})",
            )
        if not low <= value <= high:
            hint = centimetre_slip(value, low, high, f"{value:g}", f"{value / CM_PER_M:g}")
            raise ParameterError(option, f"must be in [{low:g}, {high:g}] m, the modelled range (got {value:g}){hint}")


def pcsa_option(values: list[float] | None):
    """``--pcsa`` [cm^2] in m^2, for the library with ``slip_check=False`` (the unit is the option's).

    A value above any muscle's is analysed, as an optimum of that size is printed (a heavy body on weak
    fibres); :func:`note_pcsa_slip` says so after the answer, and warns of m^2 typed for cm^2.

    Parameters
    ----------
    values : list of float or None
        As parsed (:func:`float_list`); None: not given.

    Returns
    -------
    numpy.ndarray or None
        PCSA [m^2] (the library checks the count, signs and finiteness), or None.

    Raises
    ------
    ParameterError
        A value above :data:`spinectl.model.checks.MAX_PCSA`, named in cm^2.
    """
    if values is None:
        return None
    from ..model.checks import MAX_PCSA

    limit = MAX_PCSA / cm2_to_m2(1.0)
    if max(values, default=0.0) > limit:
        raise ParameterError(
            "--pcsa",
            f"must be at most {limit:g} cm^2 per muscle, beyond which the torques overflow (got {max(values):g})",
        )
    return cm2_to_m2(values)


def note_after(text: str) -> None:
    """Say ``text`` on stderr after the command's answer, as ``spinectl: warning: <text>``
    (:data:`spinectl.cli.NOTES`; a failed run says its error alone).

    Parameters
    ----------
    text : str
        One line, e.g. ``"--lordosis-angle: 0.7 deg is a nearly straight spine ..."``.
    """
    from . import NOTES

    NOTES.append(text)


def note_pcsa_slip(values: list[float] | None) -> None:
    """After a command's answer: one line on stderr if ``--pcsa`` looks like m^2 typed for cm^2, or exceeds any muscle.

    After the answer, not before: a run that then fails prints its one-line error alone. A PCSA above
    :data:`spinectl.model.checks.MAX_PLAUSIBLE_PCSA` is analysed (an optimum of that size is an answer,
    and can be given back), and said to be more than any muscle's.

    Parameters
    ----------
    values : list of float or None
        ``--pcsa`` as parsed [cm^2] (:func:`spinectl.units.square_metre_slip`).
    """
    if values is None:
        return
    from ..model.checks import MAX_PLAUSIBLE_PCSA

    limit = MAX_PLAUSIBLE_PCSA / cm2_to_m2(1.0)
    notes = [square_metre_slip(values)]
    if max(values, default=0.0) > limit:
        notes.append(f"{max(values):g} cm^2 is more than any muscle's PCSA (above {limit:g} cm^2); analysed as given")
    if any(notes):
        note_after(f"--pcsa: {'; '.join(n for n in notes if n)}")


def load_model(args: argparse.Namespace, aliases: dict | None = None) -> Model:
    """The model named by ``--preset``, ``--config`` and ``--set``, with a command's own options on top.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments with ``config``, ``preset`` and ``assignments`` (see :func:`add_model_options`).
    aliases : dict, optional
        A command's options that are aliases of ``--set`` (e.g. ``--K`` for ``passive.stiffness``):
        ``(option, value)`` by dotted field; None values (options not given) are skipped.

    Returns
    -------
    Model
        The validated model; its source names the preset, the file and every overridden field.

    Raises
    ------
    ParameterError
        An option given together with ``--set`` of the same field (which would win is no one's guess).
    """
    assignments = getattr(args, "assignments", None) or []
    given = {dotted: value for dotted, (_, value) in (aliases or {}).items() if value is not None}
    refuse_set_twice(
        assignments, {dotted: option for dotted, (option, _) in (aliases or {}).items() if dotted in given}
    )
    model = apply_overrides(load_config(args.config, preset=args.preset), assignments)
    return set_parameters(model, given) if given else model


def refuse_set_twice(assignments: list[str], options: dict) -> None:
    """Refuse ``--set FIELD=...`` together with an option that sets the same field.

    Parameters
    ----------
    assignments : list of str
        The ``--set`` arguments, ``SECTION.FIELD=VALUE``.
    options : dict
        Option (e.g. ``"--K"``) by the dotted field it sets, for the options given.

    Raises
    ------
    ParameterError
        Naming the option and the field.
    """
    for text in assignments:
        dotted = text.partition("=")[0].strip()
        if dotted in options:
            raise ParameterError(options[dotted], f"sets {dotted}, as does --set {dotted}: give one of them")


def refuse_set_unused(assignments: list[str], unused: dict) -> None:
    """Refuse ``--set FIELD=...`` of a field the command's mode does not use, as its own option is refused.

    Parameters
    ----------
    assignments : list of str
        The ``--set`` arguments, ``SECTION.FIELD=VALUE``.
    unused : dict
        What to refuse and why: a dotted field (``"passive.stiffness"``) or a whole section with its dot
        (``"reflex."``) -> the reason, e.g. ``"cannot go with --passive, which varies K"``.

    Raises
    ------
    ParameterError
        Naming ``--set FIELD`` and the reason (before: the value was taken and ignored without a word).
    """
    for text in assignments:
        dotted = text.partition("=")[0].strip()
        for key, why in unused.items():
            if dotted == key or (key.endswith(".") and dotted.startswith(key)):
                raise ParameterError(f"--set {dotted}", why)


def finite_float(name: str, low: float | None = None, high: float | None = None, why: str = ""):
    """An argparse ``type`` accepting finite floats only (in [low, high] where given), naming the option on error.

    Parameters
    ----------
    name : str
        The option, e.g. ``"--E"``, as named in the error message.
    low, high : float, optional
        The closed interval allowed, in the option's unit; None: no bound on that side.
    why : str
        The interval's unit and reason, said after it, e.g. ``" N m/rad, ..."``.
    """

    def convert(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be a number (got {text!r})") from None
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"{name} must be finite (got {text!r})")
        if (low is not None and value < low) or (high is not None and value > high):
            interval = f"in [{low:g}, {high:g}]" if None not in (low, high) else f"at most {high:g}"
            interval = f"at least {low:g}" if high is None else interval
            raise argparse.ArgumentTypeError(f"{name} must be {interval}{why} (got {text!r})")
        return value + 0.0  # -0 becomes 0

    convert.__name__ = name
    return convert


def float_list(name: str):
    """An argparse ``type`` for comma-separated finite floats, e.g. ``10,5,3``.

    Parameters
    ----------
    name : str
        The option, e.g. ``"--pcsa"``, as named in the error message.
    """
    one = finite_float(name)

    def convert(text: str) -> list[float]:
        return [one(part) for part in text.split(",") if part.strip()]

    convert.__name__ = name
    return convert


def emit_json(payload: dict, out: str | None = None) -> None:
    """Print ``payload`` as JSON, or write it atomically to ``out``.

    Parameters
    ----------
    payload : dict
        JSON-ready document; a NaN or infinite number is written ``null`` with a ``<key>_reason``
        beside it (:func:`spinectl.jsondoc.dumps`, docs/cli.md "JSON output").
    out : str, optional
        Output file; default standard output.
    """
    text = jsondoc.dumps(payload)
    if out:
        atomic_write_text(out, text)
    else:
        sys.stdout.write(text)


def require(condition: bool, field: str, message: str) -> None:
    """Raise :class:`ParameterError` for ``field`` unless ``condition``.

    Parameters
    ----------
    condition : bool
        What must hold.
    field : str
        The option or parameter named in the error, e.g. ``"--pcsa"``.
    message : str
        What is allowed, e.g. ``"must be >= 0"``.
    """
    if not condition:
        raise ParameterError(field, message)


def input_name(text: str) -> str:
    """An argparse type: a file or folder name that the system can look up (it need not exist).

    A name too long for the file system (``ENAMETOOLONG``), a loop of symbolic links, a folder
    that cannot be searched or a NUL byte end as argparse's one line naming the argument
    (``argument RESULTS: cannot read '...': File name too long``); a missing file is left to the
    library, which says so in its own words.

    Parameters
    ----------
    text : str
        The name as given.

    Returns
    -------
    str
        ``text``, unchanged.

    Raises
    ------
    argparse.ArgumentTypeError
        The name cannot be looked up.
    """
    try:
        os.stat(text)
    except (FileNotFoundError, NotADirectoryError):
        pass
    except (OSError, ValueError) as exc:  # ValueError: a NUL byte in the name
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise argparse.ArgumentTypeError(f"cannot read {show(text)}: {reason}") from None
    return text


def add_scheduler_options(
    parser: argparse.ArgumentParser,
    default: str = "a local cluster on 127.0.0.1, started and closed by the command",
    workers: str = "one per core, at most one per chunk",
) -> None:
    """``--scheduler``, ``--workers`` and ``--worker-timeout``: where the chunks run (``study``, ``atlas``).

    Read back by :func:`scheduler_options`; the library checks them
    (:func:`spinectl.landscape.study.executor.check_options`).

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The sub-command's parser.
    default : str
        Where the chunks run without ``--scheduler``, for the help.
    workers : str
        What runs without ``--workers``, for the help (the atlas: no cluster at all).
    """
    parser.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="an existing dask.distributed scheduler, e.g. tcp://host:8786, or 'synchronous' for "
        f"in-process (default: {default})",
    )
    parser.add_argument(
        "--worker-timeout",
        type=finite_float("--worker-timeout"),
        metavar="SECONDS",
        help="how long to wait for a first worker of --scheduler if it has none, and for a worker again "
        "once every worker has gone mid-run (default: spinectl.landscape.study.executor.WORKER_TIMEOUT)",
    )
    parser.add_argument("--workers", type=_workers, metavar="N", help=f"local worker processes (default: {workers})")


def _workers(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"--workers must be an integer (got {text!r})") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"--workers must be >= 1 (got {text!r})")
    return value


def scheduler_options(args: argparse.Namespace) -> dict:
    """The options of :func:`add_scheduler_options` as keywords of the library, and a ``notify`` to stderr.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments.

    Returns
    -------
    dict
        ``scheduler``, ``workers``, ``worker_timeout`` (only if given) and ``notify`` (prints a line on stderr).
    """
    options = {"scheduler": args.scheduler, "workers": args.workers}
    options["notify"] = lambda line: print(line, file=sys.stderr)
    if args.worker_timeout is not None:
        options["worker_timeout"] = args.worker_timeout
    return options


def sagittal_load(text: str) -> tuple:
    """--load of the paper's model: ``FX,FY``, a force [N] at the point mass (x ventral, y up), fixed in the ground.

    Each component finite and within +-:data:`spinectl.model.loads.MAX_LOAD` N (docs/chain.md, "External loads").

    Parameters
    ----------
    text : str
        The option's value.

    Returns
    -------
    tuple of float
        (F_x, F_y) [N].
    """
    from ..model.loads import MAX_LOAD

    parts = text.split(",")
    if len(parts) != 2:
        raise argparse.ArgumentTypeError(f"--load must be FX,FY: two forces [N], e.g. 0,-200 (got {text!r})")
    one = finite_float("--load", -MAX_LOAD, MAX_LOAD, " N, per component")
    return tuple(one(part) for part in parts)


def anatomy_load(text: str) -> dict:
    """--load of ``spinectl anatomy``: ``BODY:FX,FY,FZ[@X,Y,Z][:ground|:body]`` (docs/anatomy.md, "Loads").

    A force [N] at a point of BODY in its own frame [m] (default its origin), the force fixed in the ground
    (default) or in the body. Forces within +-:data:`spinectl.model.loads.MAX_LOAD` N, the point within
    +-:data:`spinectl.anatomy.loads.MAX_LOAD_OFFSET` m; the body is checked against the model when it is loaded.

    Parameters
    ----------
    text : str
        The option's value.

    Returns
    -------
    dict
        ``body``, ``force`` [N], ``point`` [m], ``frame``: the keywords of
        :class:`spinectl.anatomy.loads.BodyLoad`.
    """
    from ..anatomy.loads import MAX_LOAD_OFFSET, SYNTAX
    from ..model.loads import FRAMES, MAX_LOAD

    body, sep, rest = text.partition(":")
    frame = "ground"
    head, colon, tail = rest.rpartition(":")
    if colon and tail in FRAMES:
        rest, frame = head, tail
    force, at, point = rest.partition("@")
    force, point = force.split(","), point.split(",") if at else ["0", "0", "0"]
    if not (sep and body.strip() and len(force) == 3 and len(point) == 3):
        raise argparse.ArgumentTypeError(f"--load must be {SYNTAX} (got {text!r})")
    forces = finite_float("--load", -MAX_LOAD, MAX_LOAD, " N, per force component")
    offsets = finite_float("--load", -MAX_LOAD_OFFSET, MAX_LOAD_OFFSET, " m, per point coordinate")
    return {
        "body": body,
        "force": tuple(forces(f) for f in force),
        "point": tuple(offsets(p) for p in point),
        "frame": frame,
    }


def bounded_int(name: str, low: int, high: int):
    """An argparse ``type`` accepting an integer in [low, high], naming the option on error.

    Parameters
    ----------
    name : str
        The option, e.g. ``"--contributions"``.
    low, high : int
        The closed interval allowed.
    """

    def convert(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be an integer (got {text!r})") from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{name} must be in [{low}, {high}] (got {text!r})")
        return value

    convert.__name__ = name
    return convert


def named_pattern(name: str):
    """An argparse ``type`` for ``NAME=REGEX``: a name and a pattern, both non-empty, as a pair.

    Parameters
    ----------
    name : str
        The option, e.g. ``"--group"``.
    """

    def convert(text: str) -> tuple[str, str]:
        label, sep, pattern = text.partition("=")
        if not sep or not label.strip() or not pattern:
            raise argparse.ArgumentTypeError(f"{name} must be NAME=REGEX, e.g. erector=IL|LTp (got {text!r})")
        return label.strip(), pattern  # the expression is the library's to check (model.contributions.resolve_groups)

    convert.__name__ = name
    return convert

"""``spinectl stability``: self-stability and counter torque of every segment."""

from __future__ import annotations

from ..errors import ModelError
from ..model.config import set_parameter
from ..model.stability import StabilityResult, segment_stability
from ..optimise.reference import solve_point
from ..units import cm2_to_m2, m2_to_cm2
from ._common import add_model_options, emit_json, finite_float, float_list, load_model


def register(sub) -> None:
    """Add the ``stability`` sub-command to the ``spinectl`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command action of :func:`spinectl.cli.build_parser`.
    """
    parser = sub.add_parser(
        "stability",
        help="eigenvalues, self-stability and counter torque of each segment",
        description="Linearise every lumbar segment about the upright posture and report its "
        "stiffness, damping, eigenvalues (paper, eq. 1), self-stability and local counter torque.",
    )
    add_position_options(parser)
    parser.add_argument(
        "--pcsa",
        type=float_list("--pcsa"),
        metavar="CM2,...",
        help="PCSA [cm^2]: one value per pair (each muscle of the pair) or one per muscle "
        "(default: the minimum stabilising PCSA, the optimiser's chosen activation)",
    )
    parser.add_argument("--K", type=finite_float("--K"), help="passive stiffness K [N m/rad] (overrides the model)")
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    add_model_options(parser)
    parser.set_defaults(func=run)


def add_position_options(parser) -> None:
    """``--E`` and ``--Lambda`` in metres.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The sub-command's parser.
    """
    parser.add_argument("--E", type=finite_float("--E"), default=0.0, help="eccentricity E [m] (default 0)")
    parser.add_argument("--Lambda", type=finite_float("--Lambda"), default=0.0, help="lordosis Lambda [m] (default 0)")


def model_with_overrides(args):
    """The model of ``--preset``/``--config`` with ``--K`` applied.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments; ``K`` [N m/rad] is optional.
    """
    model = load_model(args)
    if getattr(args, "K", None) is not None:
        model = set_parameter(model, "passive.stiffness", args.K)
    return model


def run(args) -> int:
    """Run ``spinectl stability``: print the table, or JSON with ``--json``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments: ``E``, ``Lambda`` [m], ``pcsa`` [cm^2], ``K``, ``json`` and the model options.

    Returns
    -------
    int
        Exit code 0.
    """
    model = model_with_overrides(args)
    pcsa = cm2_to_m2(args.pcsa) if args.pcsa is not None else minimum_stabilising_pcsa(model, args.E, args.Lambda)
    result = segment_stability(model, args.E, args.Lambda, pcsa)
    if args.json:
        emit_json(result_to_json(model, result, given=args.pcsa is not None))
    else:
        print(format_table(model, result, given=args.pcsa is not None))
    return 0


def minimum_stabilising_pcsa(model, eccentricity: float, lordosis: float):
    """The chosen activation of :func:`spinectl.optimise.reference.solve_point` [m^2]; an error if there is none.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].

    Raises
    ------
    ModelError
        No activation within the bounds stabilises every segment (or the solver failed).
    """
    optimum = solve_point(model, eccentricity, lordosis)
    if not optimum.ok:
        raise ModelError(
            f"pcsa: no activation stabilises every segment at E = {eccentricity:g} m, Lambda = {lordosis:g} m "
            f"(optimiser status {optimum.status}); give --pcsa"
        )
    return optimum.pcsa


def result_to_json(model, result: StabilityResult, given: bool = True) -> dict:
    """The JSON document of ``spinectl stability --json`` (units in the key names).

    Parameters
    ----------
    model : Model
        The model the result was computed with (muscle names, K).
    result : StabilityResult
        Output of :func:`~spinectl.model.stability.segment_stability`.
    given : bool
        Whether the PCSA was given (``--pcsa``); ``pcsa_source`` is then 'given',
        else 'min_pcsa' (the optimiser's chosen activation).
    """
    pcsa = m2_to_cm2(result.pcsa)
    return {
        "E_m": result.eccentricity,
        "Lambda_m": result.lordosis,
        "K_Nm_per_rad": model.passive.stiffness,
        "K_convention": model.passive.convention,
        "pcsa_source": "given" if given else "min_pcsa",
        "pcsa_cm2": dict(zip(model.muscle_names, pcsa.tolist(), strict=False)),
        "total_pcsa_cm2": float(pcsa.sum()),
        "segments": [
            {
                "name": name,
                "stiffness_Nm_per_rad": float(result.stiffness[k]),
                "damping_Nms_per_rad": float(result.damping[k]),
                "inertia_kgm2": float(result.inertia[k]),
                "eigenvalues": [[float(z.real), float(z.imag)] for z in result.eigenvalues[k]],
                "self_stable": bool(result.self_stable[k]),
                "counter_torque_Nm": float(result.counter_torque[k]),
            }
            for k, name in enumerate(result.segment_names)
        ],
        "all_self_stable": result.all_self_stable,
        "counter_torque_norm_Nm": result.counter_torque_norm,
    }


def _complex(z: complex) -> str:
    return f"{z.real:9.3f}{z.imag:+9.3f}j"


def format_table(model, result: StabilityResult, given: bool = True) -> str:
    """A readable per-segment table.

    Parameters
    ----------
    model : Model
        The model the result was computed with (muscle names, K).
    result : StabilityResult
        Output of :func:`~spinectl.model.stability.segment_stability`.
    given : bool
        Whether the PCSA was given (``--pcsa``) or is the minimum stabilising one.
    """
    pcsa = m2_to_cm2(result.pcsa)
    lines = [
        f"E = {result.eccentricity * 100:.2f} cm, Lambda = {result.lordosis * 100:.2f} cm, "
        f"K = {model.passive.stiffness:g} N m/rad ({model.passive.convention})",
        ("PCSA [cm^2]: " if given else "PCSA [cm^2] (minimum stabilising, chosen activation): ")
        + ", ".join(f"{n} {p:.2f}" for n, p in zip(model.muscle_names, pcsa, strict=False))
        + f"  (total {pcsa.sum():.2f})",
        "",
        f"{'segment':8} {'S [N m/rad]':>12} {'D [N m s/rad]':>14} {'theta [kg m2]':>14} "
        f"{'lambda_1 [1/s]':>20} {'lambda_2 [1/s]':>20} {'stable':>7} {'CT [N m]':>10}",
    ]
    for k, name in enumerate(result.segment_names):
        eig = result.eigenvalues[k]
        lines.append(
            f"{name:8} {result.stiffness[k]:12.3f} {result.damping[k]:14.4f} {result.inertia[k]:14.4f} "
            f"{_complex(eig[0]):>20} {_complex(eig[1]):>20} {'yes' if result.self_stable[k] else 'NO':>7} "
            f"{result.counter_torque[k]:10.3f}"
        )
    lines += [
        "",
        f"||CT|| = {result.counter_torque_norm:.3f} N m; "
        f"self-stable: {'all segments' if result.all_self_stable else 'NOT all segments'}",
    ]
    return "\n".join(lines)


__all__ = ["register", "run", "result_to_json", "format_table", "add_position_options"]

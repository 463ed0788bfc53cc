"""The JSON documents spinectl prints: strict JSON, a value without a finite number as ``null`` and a reason.

JSON has no NaN or infinity; Python's ``json`` writes them as the bare words ``NaN`` and
``Infinity``, which strict parsers (JavaScript's ``JSON.parse``, jq, Go, Rust's serde) reject.
Every ``--json`` document goes through :func:`dumps`, the one place of the convention
(docs/cli.md, "JSON output"):

- a float that is NaN or infinite is written ``null``;
- the dict that holds it gains the key ``<key>_reason``, which says what the missing number
  means: a word of :data:`REASONS`. For a list (eigenvalue pairs, matrices, per-joint values)
  ``<key>_reason`` is a list of the same shape, ``null`` where the number is finite.

The reason keeps the meaning the tables print as words: an infinite delay margin is
``"unbounded"`` (any delay), an infinite slowest time constant ``"never_returns"`` (the segment
is not asymptotically stable), a NaN disk margin ``"none"`` (the loop is unstable at the delay,
so it has no margin), a NaN where nothing was computed ``"not_computed"``.
"""

from __future__ import annotations

import json
import math

REASONS = {
    "unbounded": "+inf: no limit (a margin, a gain factor or a kp bound that any value satisfies)",
    "-unbounded": "-inf: no lower limit",
    "never_returns": "+inf time constant: the segment is not asymptotically stable, a push never dies out",
    "none": "the quantity does not exist here: no crossover, no stabilising kp range, no disk margin "
    "(the loop is unstable at the delay)",
    "not_computed": "NaN: not computed (no optimum at the point, no LP minimum for a given PCSA, "
    "a reading python-control could not make)",
}
"""Every word a ``<key>_reason`` can hold, with its meaning (docs/cli.md, "JSON output")."""

_BY_KEY = {
    "slowest_time_constant_s": {"inf": "never_returns"},
    "phase_margin_deg": {"inf": "none", "nan": "none"},
    "crossover_rad_s": {"nan": "none"},
    "phase_crossover_rad_s": {"nan": "none"},
    "frequency_rad_s": {"nan": "none"},
    "delay_margin_frequency_rad_s": {"nan": "none"},
    "kp_min_Nm_per_rad": {"nan": "none"},
    "kp_max_Nm_per_rad": {"nan": "none"},
    "disk_margin": {"nan": "none"},
    "disk_gain_margin": {"nan": "none"},
    "disk_phase_margin_deg": {"nan": "none"},
}
"""Keys whose missing number means something other than the default of :func:`reason`."""


def reason(key: str, value: float) -> str:
    """The word of :data:`REASONS` for the non-finite ``value`` of ``key``.

    Parameters
    ----------
    key : str
        The key in the document, e.g. ``"delay_margin_s"``.
    value : float
        NaN or ±inf.

    Returns
    -------
    str
        ``"unbounded"`` for +inf, ``"-unbounded"`` for -inf, ``"not_computed"`` for NaN, unless
        the key's quantity gives the value another meaning (e.g. ``"never_returns"``).
    """
    kind = "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    default = {"nan": "not_computed", "inf": "unbounded", "-inf": "-unbounded"}[kind]
    return _BY_KEY.get(key, {}).get(kind, default)


def strict(document, key: str = ""):
    """``document`` with every NaN or infinite float ``null`` and its ``<key>_reason`` beside it.

    Parameters
    ----------
    document : dict, list or scalar
        JSON-ready data (dicts with str keys, lists, str, bool, int, float, None).
    key : str
        The key ``document`` stands under (its reasons' words depend on it).

    Returns
    -------
    object
        The same structure with finite numbers only; dicts gain ``<key>_reason`` entries.
    """
    if isinstance(document, dict):
        out = {}
        for name, value in document.items():
            out[name] = strict(value, name)
            reasons = _reasons(value, name)
            if reasons is not None:
                out[f"{name}_reason"] = reasons
        return out
    if isinstance(document, (list, tuple)):
        return [strict(item, key) for item in document]
    if isinstance(document, float) and not math.isfinite(document):
        return None
    return document


def _reasons(value, key: str):
    """The ``<key>_reason`` entry of ``value``: a word, a list shaped like it, or None if all is finite."""
    if isinstance(value, float):
        return None if math.isfinite(value) else reason(key, value)
    if isinstance(value, (list, tuple)):
        inner = [_reasons(item, key) if not isinstance(item, dict) else None for item in value]
        return inner if any(r is not None for r in inner) else None
    return None


def dumps(document) -> str:
    """``document`` as strict JSON text (indent 2, final newline), the convention of :func:`strict`.

    Parameters
    ----------
    document : dict
        JSON-ready data; numpy floats are not accepted (``to_dict`` methods give Python floats).

    Returns
    -------
    str
        Text that any strict JSON parser reads: no ``NaN``, ``Infinity`` or ``-Infinity``.
    """
    return json.dumps(strict(document), indent=2, allow_nan=False) + "\n"

"""Muscle laws by name: the registry that ``fibre.law`` selects from (docs/model.md, "The muscle-law seam").

The way pvlib selects a model by name or callable: :func:`get_law` takes a registered name
(``"wagner2012"``, the paper's law and the only one built in) or a :class:`MuscleLaw` itself.
A new law is one module that builds a :class:`MuscleLaw` and one :func:`register_law` call
(CONTRIBUTING.md, "Extension points"); the model (:mod:`spinectl.model.mechanics`), the chain
(:mod:`spinectl.model.chain`) and the exports (:mod:`spinectl.anatomy.export_mjcf`,
:mod:`spinectl.anatomy.export_osim`) then use it through :func:`tension` and :func:`at_rest`.

An ``.osim`` model's muscles bring their own law (Millard 2012, Thelen 2003, De Groote-Fregly
2016), which OpenSim evaluates: the OpenSim engine's law is that evaluation,
``spinectl.anatomy.opensim_muscles``, not an entry of this registry (docs/model.md).
"""

from __future__ import annotations

from ... import _validate as v
from ...errors import ParameterError
from . import wagner2012
from .law import FibreRest, MuscleLaw, OpenSimCurves, at_rest, tension

__all__ = [
    "DEFAULT_LAW",
    "LAWS",
    "FibreRest",
    "MuscleLaw",
    "OpenSimCurves",
    "at_rest",
    "get_law",
    "opensim_curves",
    "register_law",
    "tension",
]

DEFAULT_LAW = wagner2012.LAW.name
"""The law of ``fibre.law`` unless a model names another: the paper's."""

LAWS: dict[str, MuscleLaw] = {DEFAULT_LAW: wagner2012.LAW}
"""The registered laws by name; extended by :func:`register_law` only."""


def register_law(law: MuscleLaw) -> MuscleLaw:
    """Register ``law`` under its name, so that ``fibre.law = "<name>"`` selects it.

    Register at the import of the module that defines the law: a process that evaluates a model
    (a Dask worker of ``spinectl study``) knows the laws its imports registered.

    Parameters
    ----------
    law : MuscleLaw

    Returns
    -------
    MuscleLaw
        ``law`` itself.

    Raises
    ------
    ValueError
        ``law`` is no :class:`MuscleLaw`, or its name is registered to another law (a law is not
        replaced under a model that names it).
    """
    if not isinstance(law, MuscleLaw):
        raise ValueError(f"register_law takes a MuscleLaw (got {type(law).__name__})")
    if LAWS.get(law.name, law) is not law:
        raise ValueError(f"the muscle law {law.name!r} is registered already")
    LAWS[law.name] = law
    return law


def get_law(law, field: str = "fibre.law") -> MuscleLaw:
    """The :class:`MuscleLaw` named ``law``, or ``law`` itself if it is one.

    Parameters
    ----------
    law : str or MuscleLaw
        A registered name (:data:`LAWS`) or a law.
    field : str
        The field named by the error.

    Returns
    -------
    MuscleLaw

    Raises
    ------
    ParameterError
        An unknown name, with the registered ones and the closest ("did you mean").
    """
    if isinstance(law, MuscleLaw):
        return law
    return LAWS[v.choice(field, law, tuple(LAWS), suggest=True)]


def opensim_curves(fibre, errata) -> OpenSimCurves:
    """The OpenSim expressions of the fibre's law (``fibre.law``).

    Parameters
    ----------
    fibre : Fibre
    errata : Errata

    Returns
    -------
    OpenSimCurves

    Raises
    ------
    ParameterError
        The law has no OpenSim form (``MuscleLaw.opensim`` is None).
    """
    law = get_law(fibre.law)
    if law.opensim is None:
        raise ParameterError(
            "fibre.law", f"the muscle law {law.name!r} has no OpenSim expressions: export its fibres as Millard muscles"
        )
    return law.opensim(fibre, errata)

"""The whole parameter set of one model: every section together, validated as a whole."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

from ... import _validate as v
from ...errors import ParameterError
from .body import Body, Geometry
from .bounds import MAX_CORS, MAX_FIBRE_TERMS, MAX_MUSCLE_PAIRS, SIDES, _store
from .muscles import Fibre, MusclePair, _default_muscles
from .reflex import Reflex
from .segments import Levels, Local, Passive
from .solving import Errata, Optimisation


@dataclass(frozen=True)
class Model:
    """The whole parameter set of one spinectl model."""

    body: Body = field(default_factory=Body, metadata={"doc": "Upper-body mass and inertia."})
    geometry: Geometry = field(default_factory=Geometry, metadata={"doc": "Spine line and CoRs."})
    fibre: Fibre = field(default_factory=Fibre, metadata={"doc": "Muscle fibre properties."})
    muscles: tuple[MusclePair, ...] = field(
        default_factory=_default_muscles, metadata={"doc": "The antagonistic pairs of global muscles."}
    )
    passive: Passive = field(default_factory=Passive, metadata={"doc": "Passive stiffness K."})
    local: Local = field(default_factory=Local, metadata={"doc": "Local muscles of the coupled chain."})
    levels: Levels = field(default_factory=Levels, metadata={"doc": "Lumbar levels of the coupled chain."})
    errata: Errata = field(default_factory=Errata, metadata={"doc": "Printed formula or correction."})
    optimisation: Optimisation = field(default_factory=Optimisation, metadata={"doc": "Optimiser settings."})
    reflex: Reflex = field(default_factory=Reflex, metadata={"doc": "Delayed reflex and its simulation."})

    def __post_init__(self):
        for f in dataclasses.fields(self):  # each section's default factory is its class
            section = getattr(self, f.name)
            if f.name != "muscles" and not isinstance(section, f.default_factory):
                raise ParameterError(f.name, f"must be a {f.default_factory.__name__} (got {v.show(section)})")
        muscles = self.muscles
        if isinstance(muscles, MusclePair) or not isinstance(muscles, (tuple, list)):
            raise ParameterError("muscles", f"must be a list of MusclePair (got {v.show(muscles)})")
        if not muscles:
            raise ParameterError("muscles", "must list at least one muscle pair")
        n_cors = len(self.geometry.cor_heights)  # the model's bound: a bare Geometry may sample a line finely
        if n_cors > MAX_CORS:
            raise ParameterError(
                "geometry.cor_heights",
                f"must have at most {MAX_CORS} centres of rotation, the joints of the whole spine (got {n_cors})",
            )
        if len(muscles) > MAX_MUSCLE_PAIRS:  # before the pairwise checks: their cost grows with the square
            raise ParameterError(
                "muscles",
                f"must list at most {MAX_MUSCLE_PAIRS} pairs: the optimisation's cost grows combinatorially "
                f"with the muscles (got {len(muscles)})",
            )
        for i, pair in enumerate(muscles):
            if not isinstance(pair, MusclePair):
                raise ParameterError(f"muscles.{i}", f"must be a MusclePair (got {v.show(pair)})")
            if pair.name in [m.name for m in muscles[:i]]:
                raise ParameterError(f"muscles.{i}.name", f"must be unique among the pairs (repeated: {pair.name!r})")
        _store(self, muscles=tuple(muscles))
        terms = len(SIDES) * sum(pair.fibres for pair in muscles) * n_cors
        if terms > MAX_FIBRE_TERMS:
            raise ParameterError(
                "muscles",
                f"must have at most {MAX_FIBRE_TERMS:,} fibre-CoR terms (fibres of every muscle x the "
                f"{n_cors} CoRs; got {terms:,}): use fewer fibres",
            )
        top = self.geometry.cor_heights[0]
        if self.body.mass_height <= top:
            # every segment is an inverted pendulum: the mass above the joint (docs/model.md, Gravity)
            raise ParameterError(
                "body.mass_height",
                f"must lie above the top centre of rotation {self.geometry.cor_names[0]} at {top:g} m "
                f"(got {self.body.mass_height:g})",
            )

    @property
    def muscle_names(self) -> tuple[str, ...]:
        """Names of the individual muscles, ``<pair>_<side>`` (``geometry.side_names``), in column order."""
        return tuple(f"{m.name}_{side}" for m in self.muscles for side in self.geometry.side_names)

    @property
    def pair_names(self) -> tuple[str, ...]:
        """Names of the antagonistic pairs."""
        return tuple(m.name for m in self.muscles)

    def replace(self, **changes) -> Model:
        """Return a copy with top-level sections replaced (see :func:`dataclasses.replace`).

        The copy keeps where ``self`` came from (:mod:`spinectl.model.source`: its preset, its
        file) and lists the fields that differ as overridden, as ``--set`` does: its outputs say
        e.g. ``preset wagner2012; overridden: body.mass``.

        Parameters
        ----------
        **changes
            New sections by name, e.g. ``body=Body(mass=60.0)``.

        Returns
        -------
        Model
            A new, validated model; ``self`` is unchanged.
        """
        new = dataclasses.replace(self, **changes)  # a new instance: the source, no field, is carried below
        source = getattr(self, SOURCE_ATTRIBUTE, None)
        if source is not None:
            object.__setattr__(new, SOURCE_ATTRIBUTE, source.with_overridden(changed_fields(self, new)))
        return new


SOURCE_ATTRIBUTE = "_spinectl_source"
"""The private attribute of a :class:`Model` that holds its :class:`~spinectl.model.source.ModelSource`."""


def changed_fields(old: Model, new: Model) -> list[str]:
    """The dotted fields whose values differ between two models, e.g. ``["body.mass"]``.

    Parameters
    ----------
    old, new : Model

    Returns
    -------
    list of str
        In the order of the sections and fields; a muscle pair's fields by the pair's name
        (``muscles.straight.spread``), or ``muscles`` where the pairs themselves differ.
    """
    out = []
    for section in dataclasses.fields(old):
        before, after = getattr(old, section.name), getattr(new, section.name)
        if before == after:
            continue
        if section.name != "muscles":
            out += _differing(section.name, before, after)
        elif [m.name for m in before] == [m.name for m in after]:
            for a, b in zip(before, after, strict=True):
                out += _differing(f"muscles.{a.name}", a, b)
        else:
            out.append("muscles")
    return out


def _differing(prefix: str, a, b) -> list[str]:
    return [f"{prefix}.{f.name}" for f in dataclasses.fields(a) if getattr(a, f.name) != getattr(b, f.name)]

"""Where a model came from: its preset, its configuration file (path and SHA-256), its overridden fields.

Every output names the model it used (docs/model.md, "The default model"): a table's header line
(:func:`header`), a JSON document's keys (:func:`provenance`), a dataset's attributes and the
reproduction report. The source rides on the :class:`~spinectl.model.params.Model` instance as a
private attribute, outside its fields, so two equal parameter sets still compare equal however they
were made; :mod:`spinectl.model.config` attaches it when it loads or changes a model.
"""

from __future__ import annotations

import copy
import dataclasses
from dataclasses import dataclass

import numpy as np

from .params import Model
from .params.model import SOURCE_ATTRIBUTE as _ATTRIBUTE


@dataclass(frozen=True)
class ModelSource:
    """How a model was assembled.

    Attributes
    ----------
    preset : str or None
        The built-in preset it starts from; None for a model built in Python (``Model()``).
    config : str or None
        The configuration file laid over the preset, as given.
    config_sha256 : str or None
        SHA-256 of that file's bytes (hex).
    overridden : tuple of str
        Dotted fields changed after loading (``--set``, ``--K``, :func:`~spinectl.model.config.set_parameters`).
    """

    preset: str | None = None
    config: str | None = None
    config_sha256: str | None = None
    overridden: tuple[str, ...] = ()

    def with_overridden(self, names) -> ModelSource:
        """This source with ``names`` added to :attr:`overridden` (each once, in order).

        Parameters
        ----------
        names : iterable of str
            Dotted fields, e.g. ``"passive.stiffness"``.

        Returns
        -------
        ModelSource
            A new source.
        """
        added = tuple(n for n in dict.fromkeys(names) if n not in self.overridden)
        return dataclasses.replace(self, overridden=self.overridden + added)


def source_of(model: Model) -> ModelSource:
    """The :class:`ModelSource` of ``model`` (an empty one for a model built in Python).

    Parameters
    ----------
    model : Model

    Returns
    -------
    ModelSource
    """
    return getattr(model, _ATTRIBUTE, ModelSource())


def with_source(model: Model, source: ModelSource) -> Model:
    """A shallow copy of ``model`` that carries ``source``; ``model`` is unchanged.

    Parameters
    ----------
    model : Model
    source : ModelSource

    Returns
    -------
    Model
        Equal to ``model`` (the source is no field).
    """
    out = copy.copy(model)
    object.__setattr__(out, _ATTRIBUTE, source)  # frozen: the fields stay as validated
    return out


STIFFNESS_UNITS = {"physical": "N m/rad", "paper": "1/s^2"}
"""The unit of ``passive.stiffness`` K under each convention (docs/model.md, "Passive stiffness: two
conventions"): a torque per radian added as -K, or, under eq. 2 as printed, an angular acceleration per
radian, which adds -K theta_k [N m/rad] at CoR k."""


def stiffness_unit(convention: str) -> str:
    """The unit of ``passive.stiffness`` under ``convention``, as text (``"N m/rad"`` or ``"1/s^2"``).

    Parameters
    ----------
    convention : str
        ``passive.convention``: ``"physical"`` or ``"paper"``.

    Returns
    -------
    str
        The unit; ``"?"`` for a convention spinectl does not know (an edited file).
    """
    return STIFFNESS_UNITS.get(convention, "?")


def stiffness_text(stiffness, convention: str, inertia=None) -> str:
    """K with the unit it has under its convention, and what it adds where that is not K itself.

    Parameters
    ----------
    stiffness : float or sequence of float
        ``passive.stiffness`` K, one value or the several of a dataset stacked along ``K``.
    convention : str
        ``passive.convention``.
    inertia : sequence of float, optional
        theta_k of each CoR [kg m^2] at the posture of a table: under ``"paper"`` the stiffness added,
        K theta_k [N m/rad], is printed CoR by CoR.

    Returns
    -------
    str
        ``K = 15 N m/rad, convention physical``; ``K = 15 1/s^2, convention paper (K theta_k [N m/rad] at
        each CoR)``; with ``inertia``, ``K = 15 1/s^2, convention paper: K theta_k = 5.02, 7.40 ... N m/rad``.
    """
    values = [float(k) for k in np.atleast_1d(stiffness)]
    text = f"K = {', '.join(f'{k:g}' for k in values)} {stiffness_unit(convention)}, convention {convention}"
    if convention != "paper" or not any(values):
        return text
    if inertia is None or len(values) != 1:
        return f"{text} (K theta_k [N m/rad] at each CoR)"
    return f"{text}: K theta_k = {', '.join(f'{values[0] * th:.4g}' for th in inertia)} N m/rad"


def header(model: Model, inertia=None, stiffness: str | None = None) -> str:
    """One line naming the model: ``preset wagner2012, K = 15 N m/rad, convention physical``, then file and overrides.

    Parameters
    ----------
    model : Model
    inertia : sequence of float, optional
        theta_k [kg m^2] of each CoR at the table's posture: under the ``"paper"`` convention the
        stiffness K theta_k [N m/rad] that K adds there is named (:func:`stiffness_text`).
    stiffness : str, optional
        What to say of K instead of its value, where the model's K is not the one used (an atlas draws it).

    Returns
    -------
    str
        E.g. ``preset wagner2012, K = 0 N m/rad, convention physical; config my.toml (sha256 1a2b3c4d5e6f);
        overridden: passive.stiffness``.
    """
    first, *rest = _origin_parts(model)
    passive = (
        stiffness
        if stiffness is not None
        else stiffness_text(model.passive.stiffness, model.passive.convention, inertia)
    )
    return "; ".join([f"{first}, {passive}", *rest])


def origin(model: Model) -> str:
    """Where a model came from, without its K: for a run over several K (``spinectl reproduce``).

    Parameters
    ----------
    model : Model

    Returns
    -------
    str
        :func:`header` without ``K = ..., convention ...``, e.g. ``preset wagner2012; overridden: body.mass``.
    """
    return "; ".join(_origin_parts(model))


def _origin_parts(model: Model) -> list[str]:
    """The preset, the file with its SHA-256 and the overridden fields, each a part of :func:`header`."""
    src = source_of(model)
    parts = [f"preset {src.preset or 'none (a Model built in Python)'}"]
    if src.config:
        parts.append(f"config {src.config} (sha256 {src.config_sha256[:12]})")
    if src.overridden:
        parts.append(f"overridden: {', '.join(src.overridden)}")
    return parts


def provenance(model: Model) -> dict:
    """The model's source as JSON-ready keys (also the attributes of datasets and stores).

    Parameters
    ----------
    model : Model

    Returns
    -------
    dict
        ``preset`` (str or None), ``config`` (path or None), ``config_sha256`` (hex or None),
        ``overridden`` (list of dotted fields), K in its unit (``K_Nm_per_rad`` under the ``"physical"``
        convention, ``K_per_s2`` under ``"paper"``, :data:`STIFFNESS_UNITS`) and ``K_convention``.
    """
    src = source_of(model)
    key = "K_per_s2" if model.passive.convention == "paper" else "K_Nm_per_rad"
    return {
        "preset": src.preset,
        "config": src.config,
        "config_sha256": src.config_sha256,
        "overridden": list(src.overridden),
        key: model.passive.stiffness,
        "K_convention": model.passive.convention,
    }


def attributes(model: Model, stiffnesses=None) -> dict:
    """The model's source as NetCDF/Zarr attributes: strings only (netCDF has no null).

    Parameters
    ----------
    model : Model
    stiffnesses : sequence of float, optional
        The K (:func:`stiffness_unit`) of a dataset stacked along ``K``: the ``model`` line names them all, and
        ``passive.stiffness`` is not counted as overridden (each K is a coordinate).

    Returns
    -------
    dict of str to str
        ``model`` (the :func:`header` line), ``preset``, ``config``, ``config_sha256`` and
        ``overridden`` (comma-separated); empty strings where there is none.
    """
    src = source_of(model)
    line = header(model)
    if stiffnesses is not None:  # K is a coordinate: no override, and the line names every K
        src = dataclasses.replace(src, overridden=tuple(n for n in src.overridden if n != "passive.stiffness"))
        first, *rest = _origin_parts(with_source(model, src))
        line = "; ".join([f"{first}, {stiffness_text(list(stiffnesses), model.passive.convention)}", *rest])
    return {
        "model": line,
        "preset": src.preset or "",
        "config": src.config or "",
        "config_sha256": src.config_sha256 or "",
        "overridden": ", ".join(src.overridden),
    }

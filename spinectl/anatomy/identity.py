"""What every output says of an anatomical model: its name, source, file hash, engine and versions.

Two public versions of one model (MyoTorso from pip and from its repository) can differ by a factor in
stiffness, so the table's first line and the JSON's ``model`` name exactly which file each analysed
(docs/anatomy.md, "JSON").
"""

from __future__ import annotations

SHORT_HASH = 12
"""Hex digits of the model file's SHA-256 that the table's first line shows (the JSON has all 64)."""


def model_identity(anatomy) -> dict:
    """What every output says of the model: its name, source, file hash, engine and package versions.

    Two public versions of a model (MyoTorso from pip and from its repository) can differ by a factor in
    stiffness: the table's first line and the JSON name exactly which file each analysed.

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model.

    Returns
    -------
    dict
        ``name``, ``source``, ``sha256``, ``sha256_short`` (its first :data:`SHORT_HASH` digits), ``engine``
        and ``versions`` (package -> version: the engine's, myo-sim's for MyoTorso, spinectl's).
    """
    from .._version import __version__

    versions = dict(getattr(anatomy, "engine_versions", dict)())
    versions["spinectl"] = __version__
    return {
        "name": anatomy.name,
        "source": anatomy.source,
        "sha256": anatomy.sha256,
        "sha256_short": str(anatomy.sha256)[:SHORT_HASH],
        "engine": getattr(anatomy, "engine_kind", "unnamed engine"),
        "versions": versions,
    }


def identity_text(model: dict) -> str:
    """The model's identity as the table's first line gives it.

    Parameters
    ----------
    model : dict
        :func:`model_identity`.

    Returns
    -------
    str
        E.g. ``"myotorso (sha256 4e1f0c2a9b3d; MuJoCo; mujoco 3.3.0, myo-sim 0.2.4, spinectl 0.1.0)"``.
    """
    versions = ", ".join(f"{k} {v}" for k, v in model["versions"].items())
    return f"{model['name']} (sha256 {model['sha256_short']}; {model['engine']}; {versions})"

"""Anatomical models (MuJoCo musculoskeletal models such as MyoTorso) as chains (docs/anatomy.md).

``load("myotorso")`` compiles the model with MuJoCo, maps its lumbar joints onto the chain
and classifies its muscles; :meth:`Anatomy.chain` gives the chain linearised at a posture
as a :class:`~spinectl.model.linear_chain.LinearChain`, and :func:`analyse` the joint-by-joint
and chain verdicts at an activation. Needs the extra ``spinectl[anatomy]`` (mujoco, myo-sim);
an ``.osim`` file loads with OpenSim instead (``spinectl[opensim]``, docs/interchange.md).
"""

from pathlib import Path

from . import model as _model
from .model import Anatomy


def load(model="myotorso", mapping=None, cache: bool = True) -> Anatomy:
    """Load an anatomical model and map it onto the chain: MuJoCo's, or OpenSim's for an ``.osim`` file.

    Parameters
    ----------
    model : str or pathlib.Path
        ``"myotorso"``, an MJCF file (:func:`spinectl.anatomy.model.load`) or an ``.osim`` file
        (:func:`spinectl.anatomy.opensim_engine.load_osim`).
    mapping : str, pathlib.Path or Mapping, optional
        A mapping TOML file; default the built-in one of the model's name.
    cache : bool
        For MuJoCo's models: read the compiled model from the cache of compiled models, and write
        it there (:mod:`spinectl.anatomy.cache`); False compiles it anew. An ``.osim`` file is not cached.

    Returns
    -------
    Anatomy
    """
    if Path(str(model)).suffix.lower() == ".osim":
        from .opensim_engine import load_osim

        return load_osim(model, mapping)
    return _model.load(model, mapping, cache=cache)


__all__ = ["Anatomy", "load"]

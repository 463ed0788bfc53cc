"""Anatomical models (MuJoCo musculoskeletal models such as MyoTorso, OpenSim models) as chains (docs/anatomy.md).

``load("myotorso")`` compiles the model with MuJoCo, maps its lumbar joints onto the chain
and classifies its muscles; :meth:`Anatomy.chain` gives the chain linearised at a posture
as a :class:`~spinectl.model.linear_chain.LinearChain`, and :func:`analyse` the joint-by-joint
and chain verdicts at an activation. Needs the extra ``spinectl[anatomy]`` (mujoco, myo-sim);
an ``.osim`` file loads with OpenSim instead (``spinectl[opensim]``, docs/interchange.md).
Every engine's model is an :class:`~spinectl.anatomy.contract.AnatomyEngine`; the engine is chosen
by the model's name or suffix in :data:`~spinectl.anatomy.contract.ENGINES`
(:func:`~spinectl.anatomy.contract.register_engine` adds one).
"""

from .contract import ENGINES, AnatomyEngine, register_engine
from .model import Anatomy


def load(model="myotorso", mapping=None, cache: bool = True) -> AnatomyEngine:
    """Load an anatomical model with its engine and map it onto the chain: MuJoCo's, or OpenSim's for ``.osim``.

    Parameters
    ----------
    model : str or pathlib.Path
        ``"myotorso"``, an MJCF file (:func:`spinectl.anatomy.model.load`), an ``.osim`` file
        (:func:`spinectl.anatomy.opensim_engine.load_osim`) or a model of a registered engine
        (:data:`~spinectl.anatomy.contract.ENGINES`); any other name or suffix is refused in one line.
    mapping : str, pathlib.Path or Mapping, optional
        A mapping TOML file; default the built-in one of the model's name.
    cache : bool
        For MuJoCo's models: read the compiled model from the cache of compiled models, and write
        it there (:mod:`spinectl.anatomy.cache`); for an ``.osim`` file, its linearisations
        (:mod:`spinectl.anatomy.osim_cache`). False compiles and linearises anew.

    Returns
    -------
    AnatomyEngine
    """
    from .contract import load as load_model

    return load_model(model, mapping, cache=cache)


__all__ = ["ENGINES", "Anatomy", "AnatomyEngine", "load", "register_engine"]

"""Anatomical models (MuJoCo musculoskeletal models such as MyoTorso) as chains (docs/anatomy.md).

``load("myotorso")`` compiles the model with MuJoCo, maps its lumbar joints onto the chain
and classifies its muscles; :meth:`Anatomy.chain` gives the chain linearised at a posture
as a :class:`~spinectl.model.linear_chain.LinearChain`, and :func:`analyse` the joint-by-joint
and chain verdicts at an activation. Needs the extra ``spinectl[anatomy]`` (mujoco, myo-sim).
"""

from .model import Anatomy, load

__all__ = ["Anatomy", "load"]

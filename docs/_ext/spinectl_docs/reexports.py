"""Links for re-exported names: ``spinectl.Model`` points to ``spinectl.model.params.Model``.

A package's page lists the names of its ``__all__`` (autosummary), but each is
documented once, in the module that defines it; this ``missing-reference``
handler sends a reference to a re-exported name there.
"""

from __future__ import annotations

import importlib


def canonical(target: str) -> str | None:
    """Where ``target`` (``package.name``) is defined, ``module.qualname``, if spinectl re-exports it."""
    module, _, name = target.rpartition(".")
    if not module.startswith("spinectl"):
        return None
    try:
        obj = getattr(importlib.import_module(module), name)
    except (ImportError, AttributeError):
        return None
    home, qualname = getattr(obj, "__module__", None), getattr(obj, "__qualname__", None)
    if not (home and qualname) or f"{home}.{qualname}" == target:
        return None
    return f"{home}.{qualname}"


def resolve(app, env, node, contnode):
    """``missing-reference`` handler: a Python reference to a re-exported name, resolved at its home."""
    if node.get("refdomain") != "py" or not (home := canonical(node["reftarget"])):
        return None
    domain = env.get_domain("py")
    return domain.resolve_xref(env, node["refdoc"], app.builder, node["reftype"], home, node, contnode)

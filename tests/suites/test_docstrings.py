"""Every public parameter of spinectl is documented in a numpydoc "Parameters" section (issue 6).

Walks every module of the package with :mod:`pkgutil` and checks every public
function, every public class (its constructor) and every public method defined
there. A dataclass field also counts as documented when it is listed under
"Attributes" or carries ``doc`` metadata (the convention of
:mod:`spinectl.model.params`; the docs render that metadata, see ``docs/_ext``).
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import pkgutil

import pytest
from numpydoc.docscrape import NumpyDocString

import spinectl

NOT_IMPORTED = {"spinectl.__main__"}  # importing it runs the CLI and exits
IMPLICIT = {"self", "cls"}


def module_names() -> list[str]:
    walked = pkgutil.walk_packages(spinectl.__path__, prefix="spinectl.")
    return ["spinectl", *sorted(m.name for m in walked if m.name not in NOT_IMPORTED)]


def documented(obj, section: str = "Parameters") -> set[str]:
    """Names listed in one numpydoc section of ``obj``'s docstring ("a, b : float" lists two)."""
    doc = NumpyDocString(inspect.getdoc(obj) or "")
    return {name.strip().lstrip("*") for entry in doc[section] for name in entry.name.split(",")}


def signature_names(obj) -> list[str]:
    """Parameters of ``obj``'s signature, without self, cls, *args and **kwargs."""
    try:
        params = inspect.signature(obj).parameters.values()
    except (TypeError, ValueError):  # a builtin without a signature: nothing to document
        return []
    skip = (inspect.Parameter.VAR_POSITIONAL, inspect.Parameter.VAR_KEYWORD)
    return [p.name for p in params if p.kind not in skip and p.name not in IMPLICIT]


def missing_in_function(func) -> list[str]:
    have = documented(func)
    return [name for name in signature_names(func) if name not in have]


def missing_in_class(cls) -> list[str]:
    """Constructor parameters documented nowhere (only for classes that define their constructor)."""
    if "__init__" not in vars(cls) and "__new__" not in vars(cls):
        return []  # inherited: checked where the constructor is defined
    have = documented(cls)
    if "__init__" in vars(cls):
        have |= documented(cls.__init__)
    if dataclasses.is_dataclass(cls):
        have |= documented(cls, "Attributes")
        have |= {f.name for f in dataclasses.fields(cls) if f.metadata.get("doc")}
    return [name for name in signature_names(cls) if name not in have]


def public_methods(cls):
    for name, member in vars(cls).items():
        if name.startswith("_"):
            continue
        if isinstance(member, (staticmethod, classmethod)):
            member = member.__func__
        if inspect.isfunction(member):
            yield f"{cls.__name__}.{name}", member


def undocumented(module) -> list[str]:
    """``"qualname: param, ..."`` for every public object of ``module`` with undocumented parameters."""
    problems = []
    for name, obj in vars(module).items():
        if name.startswith("_") or getattr(obj, "__module__", None) != module.__name__:
            continue  # private, or imported from elsewhere (checked in its own module)
        if inspect.isclass(obj):
            found = [(name, missing_in_class(obj))]
            found += [(qual, missing_in_function(m)) for qual, m in public_methods(obj)]
        elif callable(obj):
            found = [(name, missing_in_function(obj))]
        else:
            continue
        problems += [f"{qual}: {', '.join(miss)}" for qual, miss in found if miss]
    return problems


@pytest.mark.parametrize("name", module_names())
def test_every_public_parameter_is_documented(name):
    problems = undocumented(importlib.import_module(name))
    assert not problems, f"{name}: parameters missing from the numpydoc 'Parameters' section:\n" + "\n".join(problems)


def test_walk_finds_every_layer():
    # a walk that finds nothing would pass trivially; these modules exist since issue 1
    names = set(module_names())
    expected = {"spinectl.model.params", "spinectl.model.mechanics", "spinectl.model.stability"}
    expected.add("spinectl.cli.stability_cmd")
    assert expected <= names


def _half_documented(pcsa, margin, *args, **kwargs):
    """A function documenting only one of its two parameters.

    Parameters
    ----------
    pcsa : float
        PCSA [m^2].
    """


class _Undocumented:
    """A class whose constructor documents nothing."""

    def __init__(self, eccentricity):
        self.eccentricity = eccentricity


@dataclasses.dataclass
class _Fields:
    """A dataclass documenting one field under Attributes and one by metadata, not the third.

    Attributes
    ----------
    lordosis : float
        Lambda [m].
    """

    lordosis: float
    mass: float = dataclasses.field(default=1.0, metadata={"doc": "m [kg]"})
    gravity: float = 9.81


def test_checker_flags_undocumented_parameters():
    # fixtures above, built to fail in known ways: the check itself can fail
    assert missing_in_function(_half_documented) == ["margin"]
    assert missing_in_class(_Undocumented) == ["eccentricity"]
    assert missing_in_class(_Fields) == ["gravity"]

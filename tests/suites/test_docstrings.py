"""Every public parameter of spinectl is documented, and so is every value a public function returns.

Walks every module of the package with :mod:`pkgutil` and checks every public
function, every public class (its constructor) and every public method defined
there:

- every parameter is listed in the numpydoc "Parameters" section. A dataclass
  field also counts as documented when it is listed under "Attributes" or
  carries ``doc`` metadata (the convention of :mod:`spinectl.model.params`; the
  docs render that metadata, see ``docs/_ext``);
- every function or method that returns a value has a numpydoc "Returns"
  section ("Yields" for a generator). Properties, dunder methods and private
  names (a leading underscore on the function, its class or its module) are
  exempt.
"""

from __future__ import annotations

import ast
import dataclasses
import importlib
import inspect
import pkgutil
import re
import textwrap
import types
from pathlib import Path

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
    # a walk that finds nothing would pass trivially; the model's modules and the CLI must be among those walked
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


# --- Returns ------------------------------------------------------------------------------------------


def _body_nodes(node):
    """The nodes of a function's own body: not those of functions, lambdas or classes nested in it."""
    for child in ast.iter_child_nodes(node):
        if not isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda, ast.ClassDef)):
            yield child
            yield from _body_nodes(child)


def returns_value(func) -> bool:
    """Whether ``func`` gives back a value.

    True if its source has a ``return <expr>`` whose value is not ``None`` or a
    ``yield``, or if its return annotation is anything but ``None`` (written out
    or, under ``from __future__ import annotations``, the string ``"None"``).
    """
    func = inspect.unwrap(func)
    annotation = func.__annotations__.get("return", inspect.Signature.empty)
    if annotation not in (inspect.Signature.empty, None, "None", type(None)):
        return True
    tree = ast.parse(textwrap.dedent(inspect.getsource(func)))
    for node in _body_nodes(tree.body[0]):
        if isinstance(node, (ast.Yield, ast.YieldFrom)):
            return True
        if isinstance(node, ast.Return) and node.value is not None:
            if not (isinstance(node.value, ast.Constant) and node.value.value is None):
                return True
    return False


def documents_return(func) -> bool:
    """Whether ``func``'s docstring has a non-empty numpydoc "Returns" or "Yields" section."""
    doc = NumpyDocString(inspect.getdoc(func) or "")
    return bool(doc["Returns"] or doc["Yields"])


def private_module(name: str) -> bool:
    """A module with a leading underscore in any part of its dotted name (``spinectl._validate``)."""
    return any(part.startswith("_") for part in name.split("."))


def public_functions(module):
    """``(qualname, function)`` of every public function of ``module`` and public method of its public classes.

    Only objects defined in ``module`` (imported ones are checked in their own module). Properties are
    not functions here, so they are left out, as are dunder methods (they start with an underscore).
    """
    for name, obj in vars(module).items():
        if name.startswith("_") or getattr(obj, "__module__", None) != module.__name__:
            continue
        if inspect.isclass(obj):
            yield from public_methods(obj)
        elif inspect.isfunction(obj):
            yield name, obj


def undocumented_returns(module) -> list[str]:
    """Qualified names of the public value-returning functions of ``module`` without a "Returns" section."""
    if private_module(module.__name__):
        return []
    return [qual for qual, func in public_functions(module) if returns_value(func) and not documents_return(func)]


@pytest.mark.parametrize("name", module_names())
def test_every_returned_value_is_documented(name):
    problems = undocumented_returns(importlib.import_module(name))
    assert not problems, f"{name}: value-returning functions without a numpydoc 'Returns' section:\n" + "\n".join(
        problems
    )


def _returns_documented(pcsa):
    """Total PCSA.

    Parameters
    ----------
    pcsa : array_like
        PCSA [m^2].

    Returns
    -------
    float
        Sum [m^2].
    """
    return sum(pcsa)


def _returns_undocumented(pcsa):
    """Total PCSA, its Returns section missing.

    Parameters
    ----------
    pcsa : array_like
        PCSA [m^2].
    """
    return sum(pcsa)


def _returns_nothing(path) -> None:
    """Writes a file and returns nothing: no Returns section needed.

    Parameters
    ----------
    path : str
        Where.
    """
    if not path:
        return
    return None


def _annotated_only(x) -> float:  # type: ignore[empty-body]
    """Declares a float but its body is only a docstring: the annotation alone makes it value-returning.

    Parameters
    ----------
    x : float
        Anything.
    """


def _generator(n):
    """Counts, documented under Yields.

    Parameters
    ----------
    n : int
        How far.

    Yields
    ------
    int
        0 to n - 1.
    """
    yield from range(n)


def _nested_return_only(x):
    """Only a nested function returns a value; the function itself returns nothing.

    Parameters
    ----------
    x : float
        Anything.
    """

    def inner():
        return x

    inner()


class _Holder:
    """Fixtures as methods: a property and a dunder method are exempt, a plain method is not."""

    @property
    def value(self):
        """A property: exempt."""
        return 1

    def __len__(self):
        return 1

    def total(self):
        """Returns a value but does not say so."""
        return 2


def test_returns_checker_tells_value_returning_functions_apart():
    # fixtures above, built to fail in known ways: the check itself can fail
    assert returns_value(_returns_documented) and documents_return(_returns_documented)
    assert returns_value(_returns_undocumented) and not documents_return(_returns_undocumented)
    assert not returns_value(_returns_nothing)
    assert returns_value(_annotated_only) and not documents_return(_annotated_only)
    assert returns_value(_generator) and documents_return(_generator)
    assert not returns_value(_nested_return_only)
    assert [qual for qual, _ in public_methods(_Holder)] == ["_Holder.total"]


def _without_section(doc: str, section: str) -> str:
    """``doc`` (cleaned) without one numpydoc section: its header, underline and body up to the next header."""
    lines = inspect.cleandoc(doc).splitlines()
    start = lines.index(section)
    headers = [i for i in range(start + 2, len(lines) - 1) if set(lines[i + 1]) == {"-"} and lines[i].strip()]
    end = headers[0] if headers else len(lines)
    return "\n".join(lines[:start] + lines[end:])


def test_returns_checker_fails_when_a_returns_section_is_removed():
    """A real function in a stand-in module: passes as written, fails once its Returns section is cut out."""
    from spinectl.model import stability

    def module_with(doc):
        module = types.ModuleType("spinectl.model.stand_in")
        func = stability.eigenvalues
        copy = types.FunctionType(func.__code__, func.__globals__, func.__name__, func.__defaults__, func.__closure__)
        copy.__doc__, copy.__module__ = doc, module.__name__
        module.eigenvalues = copy
        return module

    doc = stability.eigenvalues.__doc__
    stripped = _without_section(doc, "Returns")
    assert "Parameters" in stripped and "Returns" not in stripped and "References" in stripped
    assert undocumented_returns(module_with(doc)) == []
    assert undocumented_returns(module_with(stripped)) == ["eigenvalues"]


def test_private_modules_are_exempt_from_the_returns_check():
    assert private_module("spinectl._validate") and private_module("spinectl.model._toml")
    assert not private_module("spinectl.model.stability")


SUBSTITUTION = re.compile(r"(?<![|\w])\|[A-Za-z_]\w*\|(?![|\w])")
"""``|name|``: a reST substitution reference, which Sphinx refuses as undefined (the docs build fails)."""


def test_no_docstring_holds_a_rest_substitution_reference():
    """A docstring with ``|tau_ij|`` (an absolute value written as in maths) failed the docs build with 'Undefined
    substitution referenced': write abs(x) or ``|x|`` in double backquotes. Every string statement of the package
    is read by ast (module, class, function and attribute docstrings), so the build's failure is caught here."""
    found = []
    for path in sorted(Path(spinectl.__file__).parent.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if (
                isinstance(node, ast.Expr)
                and isinstance(node.value, ast.Constant)
                and isinstance(node.value.value, str)
            ):
                text = node.value.value
                plain = re.sub(r"``.*?``", "", text, flags=re.S)  # inline literals are not substitutions
                found += [f"{path.name}: {m.group(0)}" for m in SUBSTITUTION.finditer(plain)]
    assert not found, found

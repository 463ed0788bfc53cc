"""The architecture of spinectl, read from its source: layers depend only downward, and no import cycle.

The layers and their order are those of CONTRIBUTING.md ("Architecture", "Layers"; a test
checks that its table and :data:`LAYERS` agree, and that its tree names every module):

    _version _threads errors _optional units _validate _oscalls quoting _folder_swap atomic jsondoc canvas presets
    <  model  <  optimise  <  reflex  <  anatomy  <  landscape  <  paper  <  explore  <  cli

A module may import modules of its own layer and of the layers before it, never
of a later one (:data:`LAYERS`). ``spinectl/__init__.py`` is exempt as an
importer: it re-exports the most used names. Imported, it counts at the layer
of the highest module it imports itself (the model), since importing it runs
those imports. ``spinectl/__main__.py`` (``python -m spinectl``) is the command
line's entry point and belongs to its layer.

Every module is parsed with :mod:`ast`, nothing is imported: relative and
absolute imports are resolved to modules of spinectl, those inside functions
included for the layers. Imports by :func:`importlib.import_module` are not
seen; the package has two, both by design: its subpackages imported on first
use (``spinectl/__init__.py``) and the CLI's sub-commands. The cycle check uses
every import, those inside functions too: a cycle at import time means a module
can be half-initialised when another reads it, and one closed inside a function (deferred to break the first kind) still
means two modules that each need the other, so neither is the lower part.
"""

from __future__ import annotations

import ast
import graphlib
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "spinectl"

LAYERS = (
    (
        "_version",
        "_threads",
        "errors",
        "_optional",
        "units",
        "_validate",
        "_oscalls",
        "quoting",
        "_folder_swap",
        "atomic",
        "jsondoc",
        "canvas",
        "presets",
    ),
    ("model",),
    ("optimise",),
    ("reflex",),
    ("anatomy",),
    ("landscape",),
    ("paper",),
    ("explore",),
    ("cli", "__main__"),
)
"""The layers, lowest first, by the name below ``spinectl.`` (a module or a subpackage)."""


@dataclass(frozen=True)
class Import:
    """One import of a module of the package, resolved.

    Attributes
    ----------
    importer : str
        Dotted name of the importing module.
    target : str
        Dotted name of the imported module of the package (a module, or the package whose
        ``__init__`` defines the imported name).
    line : int
        Line of the import statement.
    deferred : bool
        Inside a function: runs when it is called, not when the module is imported.
    """

    importer: str
    target: str
    line: int
    deferred: bool


def module_files(package: Path) -> dict[str, Path]:
    """Every module of ``package`` by dotted name (a package by its own name, for its ``__init__.py``)."""
    out = {}
    for path in sorted(package.rglob("*.py")):
        parts = path.relative_to(package.parent).with_suffix("").parts
        out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return out


def imports(package: Path) -> list[Import]:
    """Every import of a module of ``package`` by a module of ``package``, resolved."""
    modules = module_files(package)
    found = []
    for name, path in modules.items():
        is_package = path.name == "__init__.py"
        visitor = _ImportVisitor(name, is_package, set(modules), package.name)
        visitor.visit(ast.parse(path.read_text(), filename=str(path)))
        found += visitor.found
    return found


class _ImportVisitor(ast.NodeVisitor):
    """Collects the imports of one module, noting whether each is inside a function."""

    def __init__(self, name: str, is_package: bool, modules: set[str], root: str):
        self.name, self.modules, self.root = name, modules, root
        self.package = name if is_package else name.rpartition(".")[0]
        self.depth = 0
        self.found: list[Import] = []

    def _function(self, node) -> None:
        self.depth += 1
        self.generic_visit(node)
        self.depth -= 1

    visit_FunctionDef = visit_AsyncFunctionDef = visit_Lambda = _function

    def _add(self, target: str, node: ast.stmt) -> None:
        if target == self.root or target.startswith(self.root + "."):
            found = Import(self.name, self._module(target), node.lineno, self.depth > 0)
            if found not in self.found:  # from x import a, b: one import of x
                self.found.append(found)

    def _module(self, dotted: str) -> str:
        """``dotted`` itself if it is a module of the package, else the nearest package above it."""
        while dotted not in self.modules and "." in dotted:
            dotted = dotted.rpartition(".")[0]
        return dotted

    def visit_Import(self, node: ast.Import) -> None:
        for alias in node.names:
            self._add(alias.name, node)

    def visit_ImportFrom(self, node: ast.ImportFrom) -> None:
        if node.level:
            parts = self.package.split(".")
            assert node.level <= len(parts), f"{self.name} (line {node.lineno}) imports beyond the package"
            parts = parts[: len(parts) - (node.level - 1)]
            base = ".".join([*parts, node.module] if node.module else parts)
        else:
            base = node.module or ""
        for alias in node.names:
            submodule = f"{base}.{alias.name}"
            self._add(submodule if submodule in self.modules else base, node)


def layer_of(module: str, root_layer: int) -> int:
    """Index in :data:`LAYERS` of a module of spinectl; ``root_layer`` for the package itself."""
    parts = module.split(".")
    if len(parts) == 1:
        return root_layer
    for index, names in enumerate(LAYERS):
        if parts[1] in names:
            return index
    raise AssertionError(f"{module} is in no layer: add spinectl.{parts[1]} to LAYERS and CONTRIBUTING.md")


def upward_imports(found: list[Import], root: str) -> list[str]:
    """Each import of a later layer, as ``importer (line N) imports target: layer a < layer b``."""
    root_layer = max((layer_of(i.target, 0) for i in found if i.importer == root), default=0)
    out = []
    for i in found:
        if i.importer == root:
            continue  # the package's __init__ re-exports: exempt
        low, high = layer_of(i.importer, root_layer), layer_of(i.target, root_layer)
        if high > low:
            out.append(f"{i.importer} (line {i.line}) imports {i.target}: {LAYERS[low]} < {LAYERS[high]}")
    return out


def import_cycle(found: list[Import]) -> list[str] | None:
    """One cycle of imports, at module level or inside functions, as a list of modules, or None."""
    graph: dict[str, set[str]] = {}
    for i in found:
        graph.setdefault(i.importer, set())
        if i.target != i.importer:
            graph[i.importer].add(i.target)
    try:
        tuple(graphlib.TopologicalSorter(graph).static_order())
    except graphlib.CycleError as exc:
        return list(exc.args[1])
    return None


@pytest.fixture(scope="module")
def spinectl_imports() -> list[Import]:
    return imports(PACKAGE)


def test_every_module_is_in_a_layer():
    """Every module of spinectl belongs to a layer of LAYERS (a new top-level name fails here first)."""
    for module in module_files(PACKAGE):
        layer_of(module, 0)


def test_no_module_imports_a_higher_layer(spinectl_imports):
    """No module imports a module of a later layer, at module level or inside a function."""
    assert len(spinectl_imports) > 100  # the walk found the package's imports
    assert upward_imports(spinectl_imports, "spinectl") == []


def test_no_import_cycle(spinectl_imports):
    """The imports form no cycle, counting those inside functions (before: the reference imported the fast
    path inside a function, the fast path the reference at module level)."""
    cycle = import_cycle(spinectl_imports)
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


MAX_LINES = 800
"""The most lines a module may have (CONTRIBUTING.md, "The tree": one idea per module)."""


def long_modules(package: Path) -> dict[str, int]:
    """Every module of ``package`` over :data:`MAX_LINES` lines: path -> lines."""
    counts = {
        path.relative_to(package).as_posix(): len(path.read_text().splitlines()) for path in package.rglob("*.py")
    }
    return {name: n for name, n in sorted(counts.items()) if n > MAX_LINES}


def test_no_module_is_over_800_lines():
    """No module of spinectl is over 800 lines (before the splits: atlas.py 852, atomic.py 858, model/chain.py
    809, anatomy/opensim_engine.py 1000, anatomy/contract.py 892, anatomy/optimum.py 840)."""
    assert long_modules(PACKAGE) == {}


def test_the_length_check_finds_a_long_module(tmp_path):
    """The check itself, on a made-up package: a module of 801 lines is named (in a subpackage too), one of 800
    is not."""
    package = _package(
        tmp_path,
        {
            "long.py": "x = 1\n" * 801,
            "fine.py": "x = 1\n" * 800,
            "anatomy/engine.py": "x = 1\n" * 900,
        },
    )
    assert long_modules(package) == {"anatomy/engine.py": 900, "long.py": 801}


def contributing_section(title: str) -> str:
    """The text of one "###" section of CONTRIBUTING.md."""
    return (ROOT / "CONTRIBUTING.md").read_text().split(f"### {title}\n")[1].split("\n##")[0]


def test_the_layers_are_those_of_contributing():
    """CONTRIBUTING.md's layer table lists the layers of LAYERS, in the same order."""
    cells = [line.split("|")[1] for line in contributing_section("Layers").splitlines() if line.startswith("|")]
    rows = [cell for cell in cells if "`" in cell]  # the table's first column, without header and rule
    assert [tuple(re.findall(r"`(\w+)`", row)) for row in rows] == list(LAYERS)


def test_the_map_in_contributing_names_every_module():
    """CONTRIBUTING.md's tree has a line for every file and folder of the package."""
    tree = contributing_section("The tree")
    names = {path.name for path in PACKAGE.rglob("*.py")} | {f"{p.name}/" for p in PACKAGE.rglob("*") if p.is_dir()}
    missing = [n for n in names - {"__pycache__/"} if not re.search(rf"(^|\s){re.escape(n)}(\s|$)", tree, re.M)]
    assert [n for n in missing if not n.endswith("_cmd.py")] == []  # cli's commands: one line, <name>_cmd.py
    assert "<name>_cmd.py" in tree


def _package(tmp_path: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        path = tmp_path / "spinectl" / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return tmp_path / "spinectl"


def test_the_checks_find_upward_imports_of_every_form(tmp_path):
    """The checks themselves, on a made-up package: each kind of upward import, and one that is fine."""
    package = _package(
        tmp_path,
        {
            "__init__.py": "from .model import params\n",
            "errors.py": "def f():\n    from spinectl.cli import main\n",  # absolute, inside a function
            "model/__init__.py": "",
            "model/params.py": "from .. import errors\nfrom ..reflex import delay\n",  # relative, module level
            "reflex/__init__.py": "",
            "reflex/delay.py": "import spinectl.landscape.sweep as s\nfrom ..model.params import X\n",
            "landscape/__init__.py": "",
            "landscape/sweep.py": "from .. import __version__\n",  # the package: at the model's layer, fine
            "cli/__init__.py": "",
        },
    )
    found = imports(package)
    assert upward_imports(found, "spinectl") == [
        "spinectl.errors (line 2) imports spinectl.cli: " + f"{LAYERS[0]} < {LAYERS[-1]}",
        "spinectl.model.params (line 2) imports spinectl.reflex.delay: " + f"{LAYERS[1]} < {LAYERS[3]}",
        "spinectl.reflex.delay (line 1) imports spinectl.landscape.sweep: "
        + f"{LAYERS[3]} < {LAYERS[LAYERS.index(('landscape',))]}",
    ]
    assert import_cycle(found) is not None  # model.params -> reflex.delay -> model.params


def test_the_cycle_check_finds_a_cycle_closed_inside_a_function(tmp_path):
    """A made-up package: a imports b at module level, b imports a inside a function (the form the
    reference and the fast path had); the check names both. Without b's import there is no cycle,
    and a cycle at module level is found as before."""
    package = _package(
        tmp_path,
        {
            "__init__.py": "",
            "model/__init__.py": "",
            "model/a.py": "from . import b\n",
            "model/b.py": "def f():\n    from .a import g\n",
        },
    )
    assert set(import_cycle(imports(package))) == {"spinectl.model.a", "spinectl.model.b"}
    (package / "model" / "b.py").write_text("def f():\n    return 1\n")
    assert import_cycle(imports(package)) is None
    (package / "model" / "b.py").write_text("from .a import g\n")
    assert set(import_cycle(imports(package))) == {"spinectl.model.a", "spinectl.model.b"}


def test_the_version_is_that_of_pyproject():
    """spinectl/_version.py (the basics layer, re-exported by the root) states pyproject.toml's version."""
    from spinectl import __version__
    from spinectl._version import __version__ as basics

    stated = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    assert basics == __version__ == stated

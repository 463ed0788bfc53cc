"""The schema: every output name with one entry (units, description) and one function that computes it.

Before, the atlas computed its outputs with its own functions, and ``local_stiffness_total_Nm_per_rad`` meant
the whole minimum PCSA's local stiffness in the sweep and ``reflex.activation`` times it in the atlas. These
tests walk the schema: each name is defined once, computed once (in landscape/columns.py) and written by the
sweep, the study and the atlas only as defined.
"""

from __future__ import annotations

import ast
from pathlib import Path

import spinectl
from spinectl.landscape import atlas, schema
from spinectl.landscape.columns import point_columns
from spinectl.landscape.priors import parse_atlas
from spinectl.model.config import load_preset

PACKAGE = Path(spinectl.__file__).parent
LANDSCAPE = PACKAGE / "landscape"
NAMES = schema.VARIABLES.keys() | schema.DRAW_VARIABLES.keys()

SHIPPED = Path(__file__).parents[2] / "examples" / "atlas.toml"
"""The shipped priors (every field of the atlas's fast path but two), drawn at N = 2 with the chain."""


def test_each_output_name_has_one_schema_entry_with_units_and_a_description():
    """The landscape's and the draws' names are disjoint, each with a unit string and a description."""
    assert not schema.VARIABLES.keys() & schema.DRAW_VARIABLES.keys()
    for name in NAMES:
        units, description = {**schema.VARIABLES, **schema.DRAW_VARIABLES}[name]
        assert isinstance(units, str) and isinstance(description, str) and description, name
    assert set(schema.ON_REQUEST) <= schema.VARIABLES.keys()
    assert set(atlas.OUTPUTS) <= NAMES


def test_the_sweep_writes_every_landscape_variable_and_no_other():
    """point_columns with the coupled chain at one point: exactly the keys of VARIABLES (no name outside the schema)."""
    found, _ = point_columns(load_preset("wagner2012"), [0.03], [0.04], coupled=True)
    assert found.keys() == schema.VARIABLES.keys()


def test_the_atlas_writes_only_names_of_the_schema_and_every_draw_variable():
    """A draw's outputs (its parameters aside) are schema names; with the chain, every name of DRAW_VARIABLES."""
    text = SHIPPED.read_text().replace("[atlas]\n", "[atlas]\nchain = true\n")
    spec = parse_atlas(text.replace("samples = 1024", "samples = 2", 1))
    assert spec.samples == 2 and spec.chain
    values = atlas.draw(spec, atlas.saltelli_unit(spec))
    outputs = atlas.evaluate(spec, values)
    assert set(outputs) <= NAMES
    assert schema.DRAW_VARIABLES.keys() <= set(outputs)
    assert not set(outputs) & set(values)


def _computing_sites(path: Path) -> list[tuple[str, str]]:
    """(name, module:function) wherever a schema name is given a value in ``path``: a dict literal's key or a
    subscript assigned, unless the value only forwards the same name (``out["status"] = out["status"].astype(str)``)."""
    tree = ast.parse(path.read_text())
    sites = []

    def forwards(value, name) -> bool:
        return any(
            isinstance(node, ast.Subscript) and isinstance(node.slice, ast.Constant) and node.slice.value == name
            for node in ast.walk(value)
        )

    def visit(node, where):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            where = f"{path.relative_to(PACKAGE)}:{node.name}"
        pairs = []
        if isinstance(node, ast.Dict):
            pairs = [(k.value, v) for k, v in zip(node.keys, node.values, strict=True) if isinstance(k, ast.Constant)]
        elif isinstance(node, ast.Assign):
            pairs = [
                (t.slice.value, node.value)
                for t in node.targets
                if isinstance(t, ast.Subscript) and isinstance(t.slice, ast.Constant)
            ]
        sites.extend((name, where) for name, value in pairs if name in NAMES and not forwards(value, name))
        for child in ast.iter_child_nodes(node):
            visit(child, where)

    visit(tree, f"{path.relative_to(PACKAGE)}:<module>")
    return sites


def test_each_output_name_is_computed_by_one_function_in_columns():
    """Walk the schema: every name gets its value in exactly one function of the landscape layer, in columns.py.

    Before the fix the atlas's _segment_outputs and _chain_outputs computed min_pcsa_cm2, counter_torque_norm_Nm,
    spine_delay_margin_s and local_stiffness_total_Nm_per_rad beside columns.py's functions.
    """
    sites: dict[str, set[str]] = {name: set() for name in NAMES}
    for path in sorted(set(LANDSCAPE.rglob("*.py")) - {LANDSCAPE / "schema.py"}):  # schema.py defines them
        for name, where in _computing_sites(path):
            sites[name].add(where)
    for name, where in sorted(sites.items()):
        assert len(where) == 1, f"{name} is computed in {sorted(where) or 'no function'}"
        assert next(iter(where)).startswith("landscape/columns.py:"), (name, where)


def _defined(name: str) -> list[str]:
    """The modules of spinectl that define ``name`` at their top level (a function or a class)."""
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        for node in ast.parse(path.read_text()).body:
            if isinstance(node, ast.FunctionDef | ast.ClassDef) and node.name == name:
                found.append(str(path.relative_to(PACKAGE)))
    return found


def test_each_renamed_name_means_one_thing():
    """ParetoFront and pareto_front: the chain's alone; the counter-torque front of the reference is its own name;
    the atlas's summary is not anatomy's analyse."""
    assert _defined("ParetoFront") == ["optimise/coupled/joint.py"]
    assert _defined("pareto_front") == ["optimise/coupled/joint.py"]
    assert _defined("CounterTorqueFront") == _defined("counter_torque_front") == ["optimise/reference.py"]
    assert _defined("analyse") == ["anatomy/analyses.py"]
    assert _defined("summarise") == ["landscape/atlas.py"]
    assert spinectl.optimise.counter_torque_front is spinectl.optimise.reference.counter_torque_front
    assert not hasattr(spinectl.optimise, "pareto_front") and not hasattr(atlas, "analyse")

"""The ``published-model`` directive: a published model's row of verdicts, analysed at the build.

In ``docs/anatomy.md``::

    ```{published-model} shared:pose2sim-beaucage-gauvreau/Model_Pose2Sim_muscles_flex.osim
    :name: Pose2Sim (Beaucage-Gauvreau et al. 2019)
    :source: perfanalytics/pose2sim, Pose2Sim/OpenSim_Setup/Model_Pose2Sim_muscles_flex.osim
    :licence: BSD-3-Clause

    [bodies]
    pelvis = ["pelvis"]
    ...
    ```

The argument is the model (a path relative to the docs folder, or absolute, ``$VARIABLES`` expanded;
``shared:<folder>/<file>`` in the published models' folder, :func:`shared_models`; or a built-in name such as
``myotorso``); the mapping is ``:mapping:`` (a file relative to the docs folder) or the
directive's content (the mapping TOML inline); neither: the model's built-in mapping. ``:activation:``
(default: the model's own controls, as ``spinectl anatomy`` without ``--activation``) and
``:joint-stiffness:`` (default none) are ``spinectl anatomy``'s options. It renders one table: the model, its
source and licence, the muscles by class, the global muscles' rank, and the verdicts joint by joint and of the
chain, free and constrained, as :func:`spinectl.anatomy.analyses.analyse` gives them now. A model file absent
at the build (the published models are not in the repository; CI has them) or an engine not installed gives
a sentence saying so instead of the numbers; a mapping the model refuses fails the build.
"""

from __future__ import annotations

import os
import tempfile
from functools import cache
from pathlib import Path

import numpy as np
from docutils import nodes
from docutils.parsers.rst import Directive, directives
from docutils.statemachine import StringList

from spinectl.errors import SpinectlError

from .markup import md_escape
from .values import missing_extra

HEADER = (
    "| model | source | licence | muscles: global, local, between, non-lumbar | global muscles' rank "
    "| joint by joint: self-stable joints ($-K_{jj}$ > 0) | the chain, free: eigenvalues of $-K$ "
    "| the chain, constrained by the rhythm |"
)


SHARED_PREFIX = "shared:"
"""An argument ``shared:<folder>/<file>`` is a file of a copy of the published models (docs/anatomy.md, "Published
models"), found where the tests find it (tests/anatomy/shared_models.py, ``$SPINECTL_SHARED_MODELS``)."""


def shared_models() -> Path:
    """The published models' folder (not in the repository)."""
    beside = Path(__file__).resolve().parents[4] / "shared" / "models"  # docs/_ext/spinectl_docs/ in the checkout
    return Path(os.environ.get("SPINECTL_SHARED_MODELS") or beside)


def resolve(model: str, docs: Path) -> str:
    """The model as ``spinectl.anatomy.load`` takes it: a built-in name, or the file's absolute path."""
    if model.startswith(SHARED_PREFIX):
        return str(shared_models() / model[len(SHARED_PREFIX) :])
    expanded = os.path.expandvars(model)
    if "/" not in expanded and "." not in expanded:
        return expanded  # a built-in name (myotorso)
    return str((docs / expanded).resolve())


@cache
def analysed(model: str, mapping_text: str | None, activation: float | None, stiffness: float):
    """``spinectl anatomy MODEL --mapping M [--activation A] [--joint-stiffness K]``'s analysis, once per build."""
    from spinectl import anatomy
    from spinectl.anatomy.analyses import analyse

    if mapping_text is None:
        return analyse(anatomy.load(model), activation=activation, joint_stiffness=stiffness)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "mapping.toml"
        path.write_text(mapping_text)
        loaded = anatomy.load(model, mapping=path)
        return analyse(loaded, activation=activation, joint_stiffness=stiffness)


def _minus(v: float, fmt: str = ".4g") -> str:
    return f"{v:{fmt}}".replace("-", "\u2212")


def _range(values) -> str:
    return _minus(values[0]) if len(values) == 1 else f"{_minus(values[0])} … {_minus(values[-1])}"


def row(result, name: str, source: str, licence: str) -> str:
    """The model's row of the table."""
    free, con, cert = result.free, result.constrained, result.certificate
    word = {True: "stable", False: "unstable"}
    counts = ", ".join(str(len(result.muscles[c])) for c in ("global", "local", "between", "non-lumbar"))
    joints = f"{sum(free.joint_self_stable)} of {free.joint_stiffness.size} ({_range(free.joint_stiffness)} N m/rad)"
    unstable = int(np.sum(free.eigenvalues <= 0))
    chain = (
        f"{word[free.chain_stable]}, {unstable} of {free.eigenvalues.size} modes unstable ({_range(free.eigenvalues)})"
    )
    if result.rhythm_size:
        constrained = f"{word[con.chain_stable]} ({_range(con.eigenvalues)} N m/rad, {len(con.joints)} coordinate(s))"
    else:
        constrained = "no rhythm: the free chain's verdict"
    rank = f"{cert.rank} of {free.eigenvalues.size}"
    cells = (md_escape(name), md_escape(source), md_escape(licence), counts, rank, joints, chain, constrained)
    return "| " + " | ".join(cells) + " |"


def caption(result, activation, stiffness: float) -> str:
    """What the row was measured at, as the page says it."""
    import spinectl

    at = (
        f"every muscle at activation {activation:g}"
        if activation is not None
        else f"the model's own controls ({md_escape(result.activation_source)}, mean {result.activation_mean:.3g})"
    )
    return (
        f"Measured at this build by spinectl {spinectl.__version__} (`spinectl anatomy`): "
        f"{md_escape(result.model['source'])}, "
        f"the sagittal chain, the reference posture, {at}, {stiffness:g} N m/rad added per joint."
    )


class PublishedModel(Directive):
    """``{published-model} MODEL``: the model's verdicts as ``spinectl anatomy`` gives them now (module docstring)."""

    required_arguments = 1
    final_argument_whitespace = False
    has_content = True
    option_spec = {
        "name": directives.unchanged,
        "source": directives.unchanged,
        "licence": directives.unchanged,
        "mapping": directives.path,
        "activation": float,
        "joint-stiffness": float,
    }

    def run(self):
        env = self.state.document.settings.env
        docs = Path(env.srcdir)
        model = resolve(self.arguments[0], docs)
        mapping_text = self._mapping(docs)
        activation = self.options.get("activation")
        stiffness = self.options.get("joint-stiffness", 0.0)
        name = self.options.get("name", Path(model).name)
        if os.path.isabs(model) and Path(model).is_file():
            env.note_dependency(model)  # a changed model file rebuilds the page
        text = self._markdown(model, mapping_text, activation, stiffness, name)
        node = nodes.container(classes=["published-model"])
        self.state.nested_parse(StringList(text.splitlines(), source=self.arguments[0]), self.content_offset, node)
        return [node]

    def _mapping(self, docs: Path) -> str | None:
        """The mapping's text: the ``:mapping:`` file, the content, or None (the model's built-in one)."""
        if "mapping" in self.options:
            path = docs / self.options["mapping"]
            self.state.document.settings.env.note_dependency(str(path))
            return path.read_text()
        return "\n".join(self.content) + "\n" if self.content else None

    def _markdown(self, model, mapping_text, activation, stiffness, name) -> str:
        source = self.options.get("source", "")
        licence = self.options.get("licence", "")
        if os.path.isabs(model) and not Path(model).is_file():
            return (
                f"*{md_escape(name)} ({md_escape(source)}, {md_escape(licence)}): not analysed at this build, "
                f"its file is not here ({md_escape(model)}); the published models are not in the repository "
                "(CI builds the docs with them).*"
            )
        try:
            result = analysed(model, mapping_text, activation, stiffness)
        except ImportError as error:
            return f"*{md_escape(name)}: {missing_extra(error)}*"
        except SpinectlError as error:  # a mapping the model refuses: the page is wrong, the build fails
            raise self.error(f"published-model {self.arguments[0]}: {error}") from None
        separator = "| " + " | ".join("---" for _ in range(HEADER.count("|") - 1)) + " |"
        return "\n".join(
            [HEADER, separator, row(result, name, source, licence), "", caption(result, activation, stiffness)]
        )

"""Numbers quoted in a sentence, computed at the build: the ``{measured}`` role.

A page writes ``{measured}`anatomy.remedy``` where a sentence quotes what a command prints; the role
looks the name up in :data:`VALUES` and puts the number the code gives now in its place, so that the
prose cannot go stale. Each generator module registers its names with :func:`value`; the computations
behind them are cached within the build (one anatomy run feeds many numbers).

A value whose extra is not installed at the build (``ImportError``) is replaced by a short note saying
what is missing, so that the build does not fail on a machine without it (CI installs every extra).
"""

from __future__ import annotations

from collections.abc import Callable

from docutils import nodes

VALUES: dict[str, tuple[Callable[[], str], bool]] = {}
"""name -> (a function giving the text, whether it is shown as code)."""


def value(name: str, code: bool = False):
    """Register ``function`` (no arguments, returns the text) as the value of ``{measured}`name```.

    Parameters
    ----------
    name : str
        The role's argument, ``<page>.<what>``.
    code : bool
        Show it as inline code (a command line, a line the command prints).
    """

    def register(function):
        VALUES[name] = (function, code)
        return function

    return register


class NotAtBuild(Exception):
    """What a value needs is not at this build (a published model's file): the page says so."""


def missing_extra(error: ImportError) -> str:
    """The page's note where an extra is not installed at the build."""
    return f"(not computed: {getattr(error, 'name', None) or error} is not installed at this build)"


def is_missing_extra(error: ImportError) -> bool:
    """Whether ``error`` is an extra's package absent (``No module named 'mujoco'``), not a name of spinectl's own
    that a generator still imports after it moved (``cannot import name ... from 'spinectl...'``)."""
    return isinstance(error, ModuleNotFoundError) and not (error.name or "spinectl").startswith("spinectl")


def text_of(name: str) -> str:
    """The text of a registered value, or the note on the extra that is missing.

    Raises
    ------
    KeyError
        For a name no generator registered.
    ImportError
        Where a generator imports a name that spinectl no longer has (the build fails rather than print a note
        that an extra is missing).
    """
    function, _ = VALUES[name]
    try:
        return function()
    except ImportError as error:
        if not is_missing_extra(error):  # spinectl's own name gone (moved or renamed): the generator is stale
            raise
        return missing_extra(error)
    except NotAtBuild as error:
        return f"(not computed: {error})"


def measured_role(name, rawtext, text, lineno, inliner, options=None, content=None):
    """The ``{measured}`` role: the registered value's text, computed now (an unknown name is an error)."""
    key = text.strip()
    env = inliner.document.settings.env
    if not hasattr(env, "spinectl_measured"):
        env.spinectl_measured = set()
    env.spinectl_measured.add(env.docname)  # read again at the next build: the code may have changed
    if key not in VALUES:
        known = ", ".join(sorted({name.split(".")[0] + ".*" for name in VALUES}))
        message = inliner.reporter.error(f"measured: unknown value {key!r} (known: {known})", line=lineno)
        return [inliner.problematic(rawtext, rawtext, message)], [message]
    shown = text_of(key)
    node = nodes.literal(shown, shown) if VALUES[key][1] else nodes.Text(shown)
    return [node], []


def outdated(app, env, added, changed, removed):
    """The pages that quote a measured value (the ``env-get-outdated`` handler): read at every build."""
    return sorted(getattr(env, "spinectl_measured", set()) - set(removed))


def purge(app, env, docname):
    """Forget a page that is read again (``env-purge-doc``); it registers itself anew if it still quotes."""
    getattr(env, "spinectl_measured", set()).discard(docname)


def merge(app, env, docnames, other):
    """Parallel reads: the pages that another process found quoting (``env-merge-info``)."""
    if not hasattr(env, "spinectl_measured"):
        env.spinectl_measured = set()
    env.spinectl_measured |= getattr(other, "spinectl_measured", set()) & set(docnames)

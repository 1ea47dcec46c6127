"""Sphinx configuration of the trajgen documentation: MyST Markdown pages and an autodoc API reference.

Build as CI does (``tests/test_docs.py``)::

    python -m sphinx -W --keep-going -n -b html docs docs/_build

``-n`` (nitpicky) makes every reference that names no documented object a warning and ``-W`` makes
warnings errors. Two rules of this file decide what a reference in a docstring may name (see
:func:`resolve_elsewhere`): an object of trajgen that the API reference documents under another
name (a re-export, e.g. ``trajgen.verification.certify`` is documented as ``trajgen.certify``) links
there; an object that exists but has no page here (the standard library, numpy, a private helper of
trajgen) is shown as code without a link. A name that does not exist still fails the build.
"""

from __future__ import annotations

import functools
import importlib
import os
import re
import sys
from pathlib import Path
from unittest import mock

from docutils import nodes
from sphinx import addnodes
from sphinx.util.docutils import SphinxDirective

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # the packages of this checkout, installed or not

project = "trajgen"
author = "trajgen developers"
project_copyright = "trajgen developers"

extensions = ["myst_parser", "sphinx.ext.autodoc", "sphinx.ext.napoleon"]
source_suffix = {".md": "markdown"}
exclude_patterns = ["_build"]
root_doc = "index"

myst_heading_anchors = 3  # [text](page.md#a-heading) links to headings down to ###

nitpicky = True

autodoc_member_order = "bysource"
autodoc_typehints = "signature"
napoleon_google_docstring = False
napoleon_numpy_docstring = True

html_theme = "alabaster"
html_title = "trajgen"
html_theme_options = {"nosidebar": False, "fixed_sidebar": False}

#: Words of numpydoc type descriptions that are no Python names ("float, optional", "array_like,
#: shape (n,)", "iterable of Configuration", "path"): napoleon passes them on as class references.
NUMPYDOC_WORDS = frozenset(
    {"optional", "default", "array_like", "shape", "n", "k", "iterable", "sequence", "path", "callable"}
)
_DOTTED_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*")


@functools.cache  # the build asks for the same names thousands of times; a failed import is slow
def _import(dotted: str) -> tuple[bool, object]:
    """``(True, object)`` for an importable dotted name (module, then attributes), else ``(False, None)``."""
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            value = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        try:
            for attribute in parts[cut:]:
                value = getattr(value, attribute)
        except AttributeError:
            return False, None
        return True, value
    return False, None


@functools.cache
def _defining_contexts(dotted: str) -> tuple[str, ...]:
    """The module (and class) that define the object ``dotted``, or its nearest parent that has one."""
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        found, value = _import(".".join(parts[:cut]))
        module = getattr(value, "__module__", None) if found else None
        if isinstance(module, str):
            return (f"{module}.{value.__qualname__}", module) if isinstance(value, type) else (module,)
    return ()


def _contexts(node: nodes.Element) -> list[str]:
    """Where names in ``node`` are looked up: the modules and classes of the docstrings it sits in.

    autodoc sets ``py:module`` to the package that documents the object (``trajgen`` for
    ``trajgen.Schedule``), while the docstring's short names are those of the module that defines
    it (``trajgen.model.schedule``): that comes from the node's source (``docstring of NAME``) or from the
    signatures of the descriptions that hold the node.
    """
    contexts = []
    parent = node
    while parent is not None:
        match = re.search(r"docstring of ([\w.]+)", getattr(parent, "source", None) or "")
        if match:
            contexts += _defining_contexts(match.group(1))
        if isinstance(parent, addnodes.desc):
            for signature in parent.findall(addnodes.desc_signature):
                if signature.get("fullname"):
                    contexts += _defining_contexts(f"{signature.get('module')}.{signature['fullname']}")
        parent = parent.parent
    module, cls = node.get("py:module"), node.get("py:class")
    if module and cls:
        contexts.append(f"{module}.{cls}")
    if module:
        contexts.append(module)
    return list(dict.fromkeys(contexts))


def _candidates(target: str, node: nodes.Element) -> list[str]:
    """``target`` relative to each context of ``node`` and the context's parent modules, then as written."""
    target = target.lstrip(".~")
    names = []
    for context in _contexts(node):
        parts = context.split(".")
        names += [".".join([*parts[:cut], target]) for cut in range(len(parts), 0, -1)]
    names.append(target)
    return list(dict.fromkeys(names))


def _documented(app, env) -> dict[int, str]:
    """Identity of every object the API reference documents -> its documented name (once per build)."""
    cache = getattr(app, "_trajgen_documented", None)  # on the application: the environment is pickled
    if cache is None:
        cache, keep = {}, []
        for name, entry in sorted(env.get_domain("py").objects.items()):
            if entry.aliased:
                continue
            found, value = _import(name)
            if found and not isinstance(value, (int, float, str, bytes, bool, type(None))):
                keep.append(value)  # ids stay unique while the objects live
                cache.setdefault(id(value), name)
        app._trajgen_documented, app._trajgen_documented_objects = cache, keep
    return cache


def resolve_elsewhere(app, env, node, contnode):
    """``missing-reference``: resolve what the Python domain could not, by the rules of this file.

    1. The words of numpydoc type descriptions and prose read as a type (text with spaces) are
       shown as text.
    2. A name that imports (as written, or relative to the module and class it appears in) and is
       the object that the API reference documents under another name links there.
    3. A name that imports but is documented nowhere here is shown as code, without a link.

    Anything else stays unresolved, and the nitpicky build fails on it.
    """
    if node.get("refdomain") != "py":
        return None
    target = node["reftarget"]
    if target in NUMPYDOC_WORDS or not _DOTTED_NAME.fullmatch(target.lstrip(".~")):
        return contnode if (" " in target or target in NUMPYDOC_WORDS) else None
    documented = _documented(app, env)
    for name in _candidates(target, node):
        found, value = _import(name)
        if not found:
            continue
        documented_name = documented.get(id(value))
        if documented_name is not None:  # a re-export, or a role of another kind (func for a class)
            domain = env.get_domain("py")
            return domain.resolve_xref(
                env, node["refdoc"], app.builder, "obj", documented_name, node, contnode
            )
        return contnode
    return None


class CommandHelp(SphinxDirective):
    """``{trajgen-help}``: the ``--help`` of every ``trajgen`` command, one section each, from the parser.

    The text is what ``trajgen COMMAND --help`` prints at 100 columns, so the page cannot fall behind
    the command line. Sections get the ids ``command-NAME`` (link as ``cli.md#command-schedule``).
    """

    has_content = False

    def run(self) -> list[nodes.Node]:
        """One section per sub-command: its summary line and its help text."""
        from trajgen.cli import command_parsers

        with mock.patch.dict(os.environ, {"COLUMNS": "100"}):
            sections: list[nodes.Node] = []
            for name, (summary, subparser) in command_parsers().items():
                section = nodes.section(ids=[f"command-{name}"], names=[f"trajgen {name}"])
                section += nodes.title(text=f"trajgen {name}")
                if summary:
                    section += nodes.paragraph(text=summary[0].upper() + summary[1:] + ".")
                help_text = subparser.format_help()
                section += nodes.literal_block(help_text, help_text, language="text")
                self.state.document.note_implicit_target(section, section)
                sections.append(section)
        return sections


def _napoleon_without_inline_types(app) -> None:
    """Keep napoleon from reading "text: more" at the start of a property's docstring as "type: text".

    Napoleon takes the first line of an attribute's, property's or module constant's docstring as
    ``type: description`` when it has a colon; here such lines are prose ("Makespan: ...", "paper
    Instruction 2: ..."), and the types come from the annotations. Those docstrings are parsed
    like a function's (sections included) instead.
    """
    from sphinx.ext import napoleon

    replaced = False
    for listener in list(app.events.listeners.get("autodoc-process-docstring", ())):
        if listener.handler is napoleon._process_docstring:
            app.disconnect(listener.id)
            replaced = True
    if not replaced:  # napoleon registers its handler differently: leave it as it is
        return

    def process(app, what, name, obj, options, lines) -> None:
        inline = what in {"attribute", "property", "data"}
        napoleon._process_docstring(app, "function" if inline else what, name, obj, options, lines)

    app.connect("autodoc-process-docstring", process)


def skip_named_tuple_fields(app, what, name, obj, skip, options):
    """``autodoc-skip-member``: a NamedTuple's fields are documented by its ``Attributes`` section."""
    if isinstance(obj, property) or type(obj).__name__ == "_tuplegetter":
        doc = getattr(obj, "__doc__", "") or ""
        if doc.startswith("Alias for field number"):
            return True
    return None


def setup(app) -> dict:
    """Register the ``trajgen-help`` directive and the reference rules."""
    app.add_directive("trajgen-help", CommandHelp)
    app.connect("missing-reference", resolve_elsewhere)
    app.connect("autodoc-skip-member", skip_named_tuple_fields)
    _napoleon_without_inline_types(app)
    return {"parallel_read_safe": True}

"""A fast start: the command line and the package load no solver, plot or spline library until used.

The heavy dependencies (SciPy, CasADi, TOPPRA, matplotlib, Ruckig) are imported only by the modules
that use them, when they are used; ``import trajgen`` and ``import trajgen.cli`` load not even NumPy.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

import trajgen
from tests.conftest import REPO

pytestmark = pytest.mark.slow

HEAVY = ("scipy", "casadi", "toppra", "matplotlib", "ruckig")


def _modules_after(code: str, *, full: bool = False) -> set[str]:
    """Top-level names (``full``: full names) of the modules loaded once ``code`` has run afresh."""
    script = code + "\nimport json, sys\nprint(json.dumps(sorted(sys.modules)))"
    done = subprocess.run(
        [sys.executable, "-c", script], cwd=REPO, capture_output=True, text=True, check=True, timeout=120
    )
    names = json.loads(done.stdout.splitlines()[-1])
    return set(names) if full else {name.split(".")[0] for name in names}


@pytest.mark.parametrize(
    "code",
    ["import trajgen", "import trajgen.cli", "import trajgen.cli; import sys; print(sorted(sys.modules))"],
    ids=["trajgen", "trajgen.cli", "the-issue's-line"],
)
def test_importing_the_package_or_its_command_line_loads_no_heavy_library(code):
    loaded = _modules_after(code)
    assert not loaded & {*HEAVY, "numpy"}, sorted(loaded & {*HEAVY, "numpy"})


def test_an_exact_schedule_on_the_command_line_loads_no_solver_spline_plot_or_ruckig():
    code = (
        "import contextlib, io\n"
        "from trajgen.cli.entry import main\n"
        "with contextlib.redirect_stdout(io.StringIO()) as out:\n"
        "    status = main(['schedule', 'examples/swap.toml', '--method', 'exact', '--json'])\n"
        "assert status == 0 and '\"duration_s\": 67.5' in out.getvalue(), out.getvalue()[:300]\n"
    )
    modules = _modules_after(code, full=True)
    loaded = {name.split(".")[0] for name in modules}
    assert "numpy" in loaded  # the run really happened: the schedule is computed with NumPy
    assert not loaded & set(HEAVY), sorted(loaded & set(HEAVY))
    # nor NumPy's masked arrays (numpy.unique pulls them in on its first call)
    assert "numpy.ma" not in modules
    # nor the methods it does not use: the optimal method's NLP code and TOPPRA's wrapper
    unused = sorted(
        name
        for name in modules
        if name.startswith(("trajgen.methods.optimal.", "trajgen.methods.toppra"))
        and name != "trajgen.methods.optimal.choice"
    )
    assert not unused, unused
    # nor the other commands' code: plots, VDA 5050, the closed loop, profile checking
    others = sorted(
        name
        for name in modules
        if name.startswith(
            ("trajgen.plots", "trajgen.execution", "trajgen.simulation_pipeline", "trajgen.export.vda5050")
        )
        or name in ("trajgen.cli.animate", "trajgen.cli.check", "trajgen.cli.simulate", "trajgen.cli.vda5050")
    )
    assert not others, others


def test_the_help_lists_every_command_with_its_summary():
    from trajgen.cli.entry import COMMANDS, build_parser

    text = build_parser().format_help()
    assert all(
        name in text and " ".join(summary.split()[:4]) in text for name, (summary, _) in COMMANDS.items()
    )


def test_a_method_is_imported_when_it_is_first_created_not_when_it_is_named():
    code = (
        "from trajgen.methods import METHODS\n"
        "assert METHODS.names == ('exact', 'toppra', 'optimal') and 'optimal:' in METHODS.help()\n"
        "import sys\n"
        "assert 'trajgen.methods.optimal.method' not in sys.modules\n"
        "METHODS.create('optimal')\n"
    )
    modules = _modules_after(code, full=True)
    assert "trajgen.methods.optimal.method" in modules
    assert "trajgen.methods.toppra" not in modules


def test_the_check_sees_a_heavy_import():
    assert "scipy" in _modules_after(
        "import trajgen.export.plc.tables as t; t.ProfileTable  # noqa\nimport scipy"
    )


@pytest.mark.parametrize("name", sorted(trajgen.__all__), ids=sorted(trajgen.__all__))
def test_every_public_name_imports_from_trajgen(name):
    namespace: dict = {}
    exec(f"from trajgen import {name}", namespace)  # the statement a user writes
    assert namespace[name] is getattr(trajgen, name)
    assert name in dir(trajgen)
    # a class or function is the one of that name, not a module or another object that shadows it
    assert getattr(namespace[name], "__name__", name) == name


def test_the_public_verify_is_the_function_also_once_the_verification_package_is_loaded():
    import trajgen.verification

    assert callable(trajgen.verify)
    assert trajgen.verify is trajgen.verification.verify


def test_an_unknown_name_is_an_attribute_error_naming_it():
    with pytest.raises(AttributeError, match="module 'trajgen' has no attribute 'plan_everything'"):
        trajgen.plan_everything  # noqa: B018

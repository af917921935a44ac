"""The README's example scripts run as a user runs them, and the package's set-up installs
what they (and the docs' examples) import: the set-up command's extras hold every
third-party module the scripts import, each extra the docs name holds what their examples
import."""

import ast
import importlib.metadata
import importlib.util
import re
import sys
import sysconfig

from conftest import ROOT, run_python

PYPROJECT = ROOT / "crates" / "xbandsim-py" / "pyproject.toml"
EXAMPLES = sorted((ROOT / "examples").glob("*.py"))
DOCS = [ROOT / "docs" / "python.md", ROOT / "docs" / "rl.md"]


def test_plotting_examples_run_as_the_readme_shows(repo_root):
    """`python examples/render_frame.py` and `python examples/dataset_boxes.py`, with their
    defaults, from the repository root, with no display and no MPLBACKEND set: each writes
    its figure into out/."""
    out = run_python(["examples/render_frame.py"], repo_root).stdout
    png = repo_root / "out" / "render_frame.png"
    assert png.stat().st_size > 10_000 and "5 objects" in out
    out = run_python(["examples/dataset_boxes.py"], repo_root).stdout
    sheet = repo_root / "out" / "example-dataset" / "boxes.png"
    assert sheet.stat().st_size > 10_000 and "8 samples" in out


def _load_toml(path):
    try:
        import tomllib
    except ImportError:  # Python < 3.11: pip's own copy of the same parser
        from pip._vendor import tomli as tomllib
    with open(path, "rb") as f:
        return tomllib.load(f)


def _name(requirement):
    """A requirement's distribution name, normalised (PEP 503)."""
    name = re.match(r"\s*([A-Za-z0-9][A-Za-z0-9._-]*)", requirement).group(1)
    return re.sub(r"[-_.]+", "-", name).lower()


def _extras():
    project = _load_toml(PYPROJECT)["project"]
    base = {_name(r) for r in project["dependencies"]}
    extras = {
        extra: {_name(r) for r in reqs}
        for extra, reqs in project["optional-dependencies"].items()
    }
    return base, extras


def _is_stdlib(module):
    if hasattr(sys, "stdlib_module_names"):
        return module in sys.stdlib_module_names
    spec = importlib.util.find_spec(module)  # pragma: no cover - Python < 3.10
    origin = getattr(spec, "origin", None) or ""
    return origin in ("built-in", "frozen") or origin.startswith(sysconfig.get_paths()["stdlib"])


def _third_party_imports(source):
    modules = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            modules.update(a.name.split(".")[0] for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0:
            modules.add(node.module.split(".")[0])
    return {m for m in modules if m != "xbandsim" and not _is_stdlib(m)}


def _distributions(module):
    """The distributions (normalised names) installing ``module`` in this environment."""
    found = importlib.metadata.packages_distributions().get(module, [])
    assert found, f"{module} is imported but installed by no distribution in the test venv"
    return {_name(d) for d in found}


def python_blocks(doc):
    """The ```python blocks of a Markdown file, in order."""
    return re.findall(r"^```python\n(.*?)^```", doc.read_text(), re.S | re.M)


def test_setup_installs_what_the_examples_import():
    """scripts/setup.sh installs the package with extras; together with the package's own
    dependencies they must hold every third-party module examples/*.py import (matplotlib
    was missing, so two of the three README examples failed in .venv)."""
    base, extras = _extras()
    commands = [
        line
        for line in (ROOT / "scripts" / "setup.sh").read_text().splitlines()
        if "pip install" in line and not line.lstrip().startswith("#")
    ]
    installs = re.findall(r'"\./crates/xbandsim-py\[([a-z0-9,]+)\]"', "\n".join(commands))
    assert installs, "scripts/setup.sh installs no ./crates/xbandsim-py[extras]"
    have = set(base)
    for extra in installs[0].split(","):
        have |= extras[extra]
    for script in EXAMPLES:
        for module in _third_party_imports(script.read_text()):
            assert _distributions(module) & have, (
                f"{script.name} imports {module}, which scripts/setup.sh's extras "
                f"({installs[0]}) do not install"
            )


def test_the_docs_name_an_extra_for_what_their_examples_import():
    """Each third-party module the docs' python examples import is installed by the
    package's dependencies or one of its extras (data for webdataset and Pillow, ray, gym,
    sb3), so that the install line the docs give for it works."""
    base, extras = _extras()
    everything = set(base).union(*extras.values())
    for doc in DOCS:
        for block in python_blocks(doc):
            for module in _third_party_imports(block):
                assert _distributions(module) & everything, (doc.name, module)

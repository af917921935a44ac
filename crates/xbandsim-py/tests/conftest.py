"""Shared fixtures: the repository root, and a stand-in for it where scripts may write."""

import importlib
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture
def repo_root(tmp_path):
    """A folder that looks like the repository root to a script run from it: every top-level
    entry of the repository linked in, but ``out/``, which is the folder's own (empty). The
    README's commands and the docs' examples run here as written, relative paths and all,
    without writing into the working tree's ``out/``."""
    root = tmp_path / "repo"
    root.mkdir()
    for entry in ROOT.iterdir():
        if entry.name not in ("out", "target"):
            (root / entry.name).symlink_to(entry)
    (root / "out").mkdir()
    return root


def run_python(args, cwd, timeout=600, env=None):
    """Runs this interpreter (the test venv's, where the package is installed as a user's
    would be) with ``args`` in ``cwd``, headless (no display, matplotlib left to choose its
    backend as it does for a user); fails with its stderr on a non-zero exit."""
    env = dict(os.environ if env is None else env)
    for name in ("MPLBACKEND", "DISPLAY", "WAYLAND_DISPLAY"):
        env.pop(name, None)
    out = subprocess.run(
        [sys.executable, *args],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    assert out.returncode == 0, f"{args} failed:\n{out.stdout}\n{out.stderr}"
    return out


def optional_import(module, extra):
    """``module`` from an optional set of packages that scripts/test.sh installs from
    ``scripts/requirements-<extra>.txt`` (``ray``, ``sb3``): where it installed them
    (``XBANDSIM_<EXTRA>_REQUIRED=1``) failing to import is a failure; elsewhere the test is
    skipped with the reason test.sh gave (``XBANDSIM_<EXTRA>_UNAVAILABLE``) or how to
    install them."""
    upper = extra.upper()
    if os.environ.get(f"XBANDSIM_{upper}_REQUIRED") == "1":
        return importlib.import_module(module)
    return pytest.importorskip(
        module,
        reason=f"{module} is not installed: "
        + os.environ.get(
            f"XBANDSIM_{upper}_UNAVAILABLE", f"pip install -r scripts/requirements-{extra}.txt"
        ),
    )


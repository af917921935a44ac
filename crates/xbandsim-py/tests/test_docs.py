"""Every ```python example of docs/python.md and docs/rl.md runs as written: a page's blocks
in order, as one script, from the repository root (a stand-in for it whose out/ is the
test's own), in the test venv. A block may use what a block above it made (docs/python.md's
RadarDataset example reads the dataset its Datasets example generates)."""

import subprocess

import pytest

from conftest import ROOT, optional_import, run_python
from test_examples import python_blocks

DOCS = ["python.md", "rl.md"]


def _needs_sb3(blocks):
    if any("stable_baselines3" in b for b in blocks):
        optional_import("stable_baselines3", "sb3")


@pytest.mark.parametrize("doc", DOCS)
def test_the_python_examples_of_the_docs_run_as_written(doc, repo_root):
    blocks = python_blocks(ROOT / "docs" / doc)
    assert blocks, f"docs/{doc} has no python example"
    _needs_sb3(blocks)
    script = repo_root / f"docs-{doc}.py"
    script.write_text(
        "".join(f"# --- docs/{doc}, example {k + 1}\n{block}\n" for k, block in enumerate(blocks))
    )
    run_python([str(script)], repo_root)


def test_the_readme_python_examples_run_as_written(repo_root):
    """The README's ```python blocks, in order, after what its first command leaves in out/
    (scripts/setup.sh renders the paper scene there with the CLI, which scripts/test.sh has
    built: the same command, run here into the stand-in's own out/)."""
    blocks = python_blocks(ROOT / "README.md")
    assert len(blocks) >= 2, "README.md has fewer python examples than expected"
    cli = ROOT / "target" / "release" / "xbandsim"
    if not cli.exists():
        pytest.skip("the CLI is not built (cargo build --release -p xbandsim-cli)")
    subprocess.run(
        [str(cli), "render", "scenes/paper.toml", "--out", "out/"],
        cwd=repo_root,
        check=True,
        capture_output=True,
    )
    script = repo_root / "readme.py"
    script.write_text(
        "".join(f"# --- README.md, example {k + 1}\n{block}\n" for k, block in enumerate(blocks))
    )
    run_python([str(script)], repo_root)

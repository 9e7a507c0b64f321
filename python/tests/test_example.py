"""The notebook-shaped example and the README's Python examples run as they are written."""

from __future__ import annotations

import re
import subprocess
import sys

from conftest import REPO


def test_line_layout_example_runs(tmp_path):
    out = subprocess.run(
        [sys.executable, str(REPO / "examples" / "line_layout.py"), str(tmp_path / "out")],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert out.returncode == 0, out.stdout + out.stderr
    assert "spacing   450 mm" in out.stdout
    for name in ("line450.dct", "quilt.png", "render.png", "protective.png", "closed_loop.png"):
        assert (tmp_path / "out" / name).stat().st_size > 1000, name


def test_the_readme_examples_run(tmp_path):
    """Each python block of README.md's "From Python", run in a fresh interpreter in a
    scratch folder."""
    text = (REPO / "README.md").read_text().split("\n## From Python\n")[1].split("\n## ")[0]
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) == 3
    for i, code in enumerate(blocks):
        out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=300)
        assert out.returncode == 0, f"block {i}:\n{code}\n{out.stdout}{out.stderr}"
    for name in ("quilt.png", "run.png"):
        assert (tmp_path / name).stat().st_size > 1000, name

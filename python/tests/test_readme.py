"""The Python in the docs runs as written: docs/PYTHON.md's first session and its quantize
example (each printing what its comments say), the package's docstring and the README's
block."""

import contextlib
import io
import os
import pathlib
import re

import pytest

import rmapgen

ROOT = pathlib.Path(__file__).resolve().parents[2]


def run(code, name):
    """Runs `code` from the repository's root; returns what it printed and its namespace."""
    out, scope = io.StringIO(), {}
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        with contextlib.redirect_stdout(out):
            exec(compile(code, name, "exec"), scope)
    finally:
        os.chdir(cwd)
    return out.getvalue().splitlines(), scope


def test_the_first_session_runs_as_written():
    text = (ROOT / "docs" / "PYTHON.md").read_text()
    block = re.search(r"<!-- python -->\n```python\n(.*?)```\n<!-- end python -->", text, re.S)
    assert block, "docs/PYTHON.md has its python block"
    code = block.group(1)
    said = re.search(r"print\(m\[\"max_abs_error\"\].*# (.*)\n", code).group(1)
    lines, _ = run(code, "docs/PYTHON.md")
    assert lines[0] == said, f"the doc says {said!r}, the code printed {lines[0]!r}"
    assert [line.split()[0] for line in lines[1:]] == [
        "u_sort_shift.m_o", "u_normalise.u_o", "u_atan_rom.pu_o", "i_o"]


def test_the_readmes_python_block_runs_as_written():
    text = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) == 1, "the README has one python block"
    lines, _ = run(blocks[0], "README.md")
    assert int(lines[0]) > 0, "the grazing highlight's largest error"


def test_the_quantize_example_runs_as_written():
    text = (ROOT / "docs" / "PYTHON.md").read_text()
    block = re.search(r"<!-- python quantize -->\n```python\n(.*?)```\n<!-- end python -->", text,
                      re.S)
    assert block, "docs/PYTHON.md has its quantize block"
    code = block.group(1)
    said = re.findall(r"^print\(.*# (.*)$", code, re.M)
    lines, scope = run(code, "docs/PYTHON.md")
    assert lines == said, f"the doc says {said}, the code printed {lines}"
    # What its comments claim.
    with pytest.raises(TypeError, match="dtype float64 is not an integer dtype"):
        scope["d"].shade(scope["normals"])
    g = scope["g"]
    assert g.dtype.name == "int32" and (abs(g).max(axis=1) == 2047).all()


def test_the_packages_docstring_runs_as_written():
    doc = rmapgen.__doc__
    block = re.search(r"::\n\n((?:    .*\n|\n)+)", doc)
    assert block, "the docstring has its example"
    code = "\n".join(line[4:] for line in block.group(1).splitlines())
    said = re.findall(r"^print\(.*# .*: (.*)$", code, re.M)
    lines, _ = run(code, "rmapgen.__doc__")
    assert lines[-len(said):] == said

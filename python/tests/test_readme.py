"""The Python in the docs runs as written: docs/PYTHON.md's first session (and prints what its
comment says) and the README's block."""

import contextlib
import io
import os
import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_the_first_session_runs_as_written():
    text = (ROOT / "docs" / "PYTHON.md").read_text()
    block = re.search(r"<!-- python -->\n```python\n(.*?)```\n<!-- end python -->", text, re.S)
    assert block, "docs/PYTHON.md has its python block"
    code = block.group(1)
    said = re.search(r"print\(m\[\"max_abs_error\"\].*# (.*)\n", code).group(1)
    out = io.StringIO()
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        with contextlib.redirect_stdout(out):
            exec(compile(code, "docs/PYTHON.md", "exec"), {})
    finally:
        os.chdir(cwd)
    lines = out.getvalue().splitlines()
    assert lines[0] == said, f"the doc says {said!r}, the code printed {lines[0]!r}"
    assert [line.split()[0] for line in lines[1:]] == [
        "u_sort_shift.m_o", "u_normalise.u_o", "u_atan_rom.pu_o", "i_o"]


def test_the_readmes_python_block_runs_as_written():
    text = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) == 1, "the README has one python block"
    out = io.StringIO()
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        with contextlib.redirect_stdout(out):
            exec(compile(blocks[0], "README.md", "exec"), {})
    finally:
        os.chdir(cwd)
    assert int(out.getvalue()) > 0, "the grazing highlight's largest error"

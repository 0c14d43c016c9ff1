"""The checked-in type stubs of the compiled module are what nanobind's
stubgen writes for the module as built: regenerate them with

    python -m nanobind.stubgen -m bireg._bireg -o python/bireg/_bireg.pyi
"""

import pathlib
import subprocess
import sys

import pytest

STUB = pathlib.Path(__file__).resolve().parents[1] / "bireg" / "_bireg.pyi"


def test_stubs_match_the_module(tmp_path):
    pytest.importorskip("nanobind.stubgen")
    out = tmp_path / "_bireg.pyi"
    subprocess.run([sys.executable, "-m", "nanobind.stubgen", "-q", "-m", "bireg._bireg", "-o",
                    str(out)], check=True, cwd=tmp_path)
    assert out.read_text() == STUB.read_text(), (
        "python/bireg/_bireg.pyi is stale: regenerate it (see this file's docstring)")

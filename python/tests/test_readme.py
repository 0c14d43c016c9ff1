"""The README's Python examples run as written, from the repository's root
(where their relative paths point). A block that needs an optional package
this environment lacks is skipped, naming it."""

import pathlib
import re

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
BLOCKS = re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), re.DOTALL)


def test_the_readme_has_python_examples():
    assert len(BLOCKS) >= 3


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_python_block_runs(index, monkeypatch):
    code = BLOCKS[index]
    if "distributed" in code:
        pytest.importorskip("distributed")
    monkeypatch.chdir(ROOT)
    namespace = {"__name__": "__main__"}  # as `python block.py` runs it
    try:
        exec(compile(code, f"README.md python block {index}", "exec"), namespace)
    finally:
        client = namespace.get("client")
        if client is not None:
            cluster = client.cluster
            client.close()
            if cluster is not None:
                cluster.close()

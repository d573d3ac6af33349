"""docs/python.md's example, run as written: its code blocks under
"## Example" in one interpreter, from a directory that holds the source
tree's configs/, as a notebook run from the source tree would."""
import os
import re
import subprocess
import sys

import mechopt

from common import SOURCE


def example_code():
    with open(os.path.join(SOURCE, "docs", "python.md")) as f:
        text = f.read()
    section = text[text.index("\n## Example"):]
    blocks = re.findall(r"```python\n(.*?)```", section, re.S)
    assert blocks
    return "\n".join(blocks)


def test_the_documented_example_runs(tmp_path):
    os.symlink(os.path.join(os.path.abspath(SOURCE), "configs"), tmp_path / "configs")
    env = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.dirname(os.path.abspath(mechopt.__file__))))
    run = subprocess.run([sys.executable, "-c", example_code()], cwd=tmp_path, env=env, capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert (tmp_path / "results" / "doe_phase" / "k1.png").stat().st_size > 10000
    assert "cannot_assemble" in run.stdout and "converged" in run.stdout

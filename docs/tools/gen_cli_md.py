"""Run the documented commands and paste their real output into docs/cli.md.

Run it with the python whose clpc is documented: ``python docs/tools/gen_cli_md.py``.
"""

import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import clpc.datasets as d

DATA = os.path.dirname(str(d.path("dryer")))
WORK = Path(tempfile.mkdtemp(prefix="clpc-cli-doc-"))
shutil.rmtree(WORK, ignore_errors=True)
WORK.mkdir(parents=True)
env = dict(os.environ, DATA=DATA, PATH=f"{Path(sys.executable).parent}:{os.environ['PATH']}")


def sh(cmd: str) -> str:
    """Run one documented shell command; its output as it would appear in a terminal."""
    p = subprocess.run(
        ["bash", "-c", "{ " + cmd + " ; } 2>&1"], cwd=WORK, env=env, capture_output=True, text=True
    )
    out = p.stdout.rstrip("\n").replace(DATA, "$DATA")
    code = f"\n[exit code {p.returncode}]" if p.returncode else ""
    return f"$ {cmd}\n{out}{code}"


template = Path(__file__).with_name("cli.md.in").read_text()
doc = re.sub(r"@@(.+?)@@", lambda m: sh(m.group(1)), template)
(Path(__file__).parents[1] / "cli.md").write_text(doc)
print(doc)
